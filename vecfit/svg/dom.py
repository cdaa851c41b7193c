"""Reading the XML: the file to an element tree, with every failure as an SvgError."""
from __future__ import annotations

import gzip
import xml.etree.ElementTree as ET
from pathlib import Path

from vecfit.errors import SvgError

SVG_NS = "http://www.w3.org/2000/svg"
XLINK_HREF = "{http://www.w3.org/1999/xlink}href"


def local_name(tag) -> str:
    """Tag without its namespace ("{http://www.w3.org/2000/svg}rect" -> "rect"); "" for
    comments and processing instructions."""
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def is_svg(element) -> bool:
    """In the SVG namespace, or in none (hand-written files often omit xmlns)."""
    tag = element.tag
    return isinstance(tag, str) and (tag.startswith("{" + SVG_NS + "}") or not tag.startswith("{"))


def href_id(element) -> str | None:
    """The local id that href (or, without it, xlink:href) points to: "#a" -> "a"."""
    ref = element.get("href")
    if ref is None:
        ref = element.get(XLINK_HREF)
    ref = (ref or "").strip()
    return ref[1:] if ref.startswith("#") and len(ref) > 1 else None


def read_root(path) -> ET.Element:
    """The root <svg> element of the file at ``path``."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise SvgError(path, "no such file") from None
    except IsADirectoryError:
        raise SvgError(path, "is a directory, not an SVG file") from None
    except OSError as e:
        raise SvgError(path, f"cannot read the file ({e.strerror or e})") from None
    if data[:2] == b"\x1f\x8b":  # .svgz
        try:
            data = gzip.decompress(data)
        except (OSError, EOFError) as e:
            raise SvgError(path, f"not a valid gzip-compressed SVG ({e})") from None
    if not data.strip():
        raise SvgError(path, "the file is empty")
    try:
        root = ET.fromstring(data)
    except ET.ParseError as e:
        raise SvgError(path, f"not valid XML ({e})") from None
    except Exception as e:  # expat's other complaints: encodings, entity limits, ...
        raise SvgError(path, f"cannot parse the XML ({e})") from None
    if local_name(root.tag) == "svg" and not is_svg(root):
        namespace = root.tag[1:].split("}", 1)[0]
        raise SvgError(path, f"the root element <svg> is in the namespace {namespace!r}, not SVG's ({SVG_NS})")
    if local_name(root.tag) != "svg":
        raise SvgError(path, f"the root element is <{local_name(root.tag) or root.tag}>, not <svg>")
    return root
