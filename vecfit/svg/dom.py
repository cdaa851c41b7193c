"""XML names: namespaces, local tag names, and local references (href)."""
from __future__ import annotations

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
