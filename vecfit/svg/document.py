"""The SVG document: a file parsed once and kept, so that what was read can be written back.

An SvgDocument holds the element tree with its comments and processing instructions, the
prolog (DOCTYPE, comments before the root), the namespace prefixes, the handle of every
element (how a Shape or Group names its element: ``source``), the style sheet and the
DOM cascade. The reader walks it to build a Scene; the writer writes a Scene's values
into a copy of it. Generated SVGs (a trace, random strokes) are built as documents
directly (``SvgDocument.new``), never as text to be parsed again.
"""
from __future__ import annotations

import copy
import gzip
import re
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

from vecfit.errors import SvgError

from .dom import SVG_NS, is_svg, local_name
from .style import Cascade, StyleSheet

__all__ = ["SvgDocument"]


class _TreeBuilder(ET.TreeBuilder):
    """Keeps comments and processing instructions, and records namespace prefixes, so
    that one parse gives everything the writer needs."""

    def __init__(self):
        super().__init__(insert_comments=True, insert_pis=True)
        self.prefixes: list[tuple[str, str]] = []

    def start_ns(self, prefix, uri):
        self.prefixes.append((prefix, uri))


_PROLOG_ITEM = re.compile(
    rb"\s+|<\?.*?\?>|<!--.*?-->|<!DOCTYPE(?:[^\[>]|\[.*?\])*>", re.DOTALL | re.IGNORECASE)


def _has_declaration(data: bytes) -> bool:
    """Whether the source opens with an XML declaration (after a byte-order mark)."""
    return data.lstrip(b"\xef\xbb\xbf").startswith(b"<?xml")


def _prolog(data: bytes) -> str:
    """What comes before the root element (comments, DOCTYPE), without the XML declaration,
    which ElementTree does not keep."""
    i, parts = 0, []
    if data.startswith(b"\xef\xbb\xbf"):
        i = 3
    while True:
        m = _PROLOG_ITEM.match(data, i)
        if not m:
            break
        item = m.group(0)
        if not item.startswith(b"<?xml ") and not item.startswith(b"<?xml?"):
            parts.append(item)
        i = m.end()
    try:
        text = b"".join(parts).decode("utf-8").strip()
    except UnicodeDecodeError:
        return ""
    return text + "\n" if text else ""


def element_children(element) -> list:
    """Child elements, without comments and processing instructions."""
    return [c for c in element if isinstance(c.tag, str)]


def _handles(root) -> dict[str, ET.Element]:
    """handle -> element: an element's id when that is unique in the document, else its
    position "/i/j/k" (indices among element children, from the root; "/" is the root)."""
    counts = Counter(e.get("id") for e in root.iter() if isinstance(e.tag, str) and e.get("id") is not None)
    out, todo = {}, [(root, "")]
    while todo:
        element, position = todo.pop()
        i = element.get("id")
        out[i if i is not None and counts[i] == 1 else (position or "/")] = element
        todo += [(c, f"{position}/{k}") for k, c in enumerate(element_children(element))]
    return out


def _read_bytes(path) -> bytes:
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
    return data


class SvgDocument:
    """A parsed (or generated) SVG document; see the module's docstring.

    ``name`` is how messages name it (the file's path). ``original`` and ``viewport`` are
    set by the reader: the Scene as read (a detached copy, what the writer compares
    against to write only what changed) and the root viewport's size in user units.
    """

    def __init__(self, root: ET.Element, name, prolog: str = "", prefixes=(), declaration: bool = False):
        self.root = root
        self.name = name
        self.prolog = prolog
        # An XML declaration is written where the source had one; a generated document
        # (a trace, a painting) has none: UTF-8 is XML's default, and the line is a tenth
        # of a small icon's compressed bytes.
        self.declaration = declaration
        self.prefixes = list(prefixes)
        self.handles = _handles(root)
        self._handle_of = {id(e): h for h, e in self.handles.items()}
        self.ids: dict[str, ET.Element] = {}
        self.parents: dict[int, ET.Element] = {}
        for element in root.iter():
            i = element.get("id") if isinstance(element.tag, str) else None
            if i is not None:
                self.ids.setdefault(i, element)  # the first of duplicated ids wins
            for child in element:
                self.parents[id(child)] = element
        self.sheet = _style_sheet(root)
        self.cascade = Cascade(self.sheet)
        self._computed: dict[int, dict] = {}
        self.original = None
        self.viewport = None

    # ------------------------------------------------------------ construction

    @classmethod
    def read(cls, path) -> "SvgDocument":
        """The SVG file at ``path``; SvgError for anything that is not a readable SVG."""
        return cls.parse(_read_bytes(path), path)

    @classmethod
    def parse(cls, data: bytes | str, name="<svg>") -> "SvgDocument":
        if isinstance(data, str):
            data = data.encode("utf-8")
        if not data.strip():
            raise SvgError(name, "the file is empty")
        builder = _TreeBuilder()
        try:
            parser = ET.XMLParser(target=builder)
            parser.feed(data)
            root = parser.close()
        except ET.ParseError as e:
            raise SvgError(name, f"not valid XML ({e})") from None
        except Exception as e:  # expat's other complaints: encodings, entity limits, ...
            raise SvgError(name, f"cannot parse the XML ({e})") from None
        if local_name(root.tag) == "svg" and not is_svg(root):
            namespace = root.tag[1:].split("}", 1)[0]
            raise SvgError(name, f"the root element <svg> is in the namespace {namespace!r}, not SVG's ({SVG_NS})")
        if local_name(root.tag) != "svg":
            raise SvgError(name, f"the root element is <{local_name(root.tag) or root.tag}>, not <svg>")
        return cls(root, name, _prolog(data), builder.prefixes, _has_declaration(data))

    @classmethod
    def new(cls, width, height, name="<generated>") -> "NewDocument":
        """An empty document of ``width`` x ``height`` px (viewBox 0 0 width height), for
        SVGs that vecfit makes itself; add elements with ``NewDocument.add``."""
        return NewDocument(width, height, name)

    def copy(self) -> "SvgDocument":
        """An independent copy of the tree (for writing into), with its own handles and
        cascade; ``original`` and ``viewport`` are shared (they are never changed)."""
        twin = SvgDocument(copy.deepcopy(self.root), self.name, self.prolog, self.prefixes, self.declaration)
        twin.original, twin.viewport = self.original, self.viewport
        return twin

    # --------------------------------------------------------------- queries

    def handle_of(self, element) -> str:
        return self._handle_of[id(element)]

    def computed(self, element) -> dict[str, str]:
        """Computed properties of any element, inherited along the DOM (memoised)."""
        key = id(element)
        if key not in self._computed:
            parent = self.parents.get(key)
            self._computed[key] = self.cascade.computed(
                element, self.computed(parent) if parent is not None else None)
        return self._computed[key]

    def element_by_id(self, i):
        return None if i is None else self.ids.get(i)

    # ---------------------------------------------------------------- output

    def serialize(self) -> bytes:
        """The document as UTF-8 SVG text: XML declaration (where the source had one),
        prolog, tree."""
        for prefix, uri in self.prefixes:
            try:
                ET.register_namespace(prefix, uri)
            except ValueError:
                pass  # ns0-style prefixes: ElementTree makes its own
        text = ET.tostring(self.root, encoding="unicode")
        head = '<?xml version="1.0" encoding="UTF-8"?>\n' if self.declaration else ""
        return (head + self.prolog + text + "\n").encode("utf-8")

    def text(self) -> str:
        return self.serialize().decode("utf-8")


class NewDocument(SvgDocument):
    """A document vecfit builds element by element (one per line, as a person would
    write it). Handles are kept up to date as elements are added."""

    def __init__(self, width, height, name="<generated>"):
        root = ET.Element(f"{{{SVG_NS}}}svg", {"width": str(width), "height": str(height),
                                               "viewBox": f"0 0 {width} {height}"})
        root.text = "\n"
        super().__init__(root, name, prefixes=[("", SVG_NS)])

    def add(self, tag: str, attributes: dict[str, str]) -> ET.Element:
        """A new child of the root, after the others."""
        element = ET.SubElement(self.root, f"{{{SVG_NS}}}{tag}", attributes)
        element.tail = "\n"
        i = element.get("id")
        if i is not None and i in self.ids:
            raise ValueError(f"duplicate id {i!r} in a generated SVG")
        handle = f"/{len(self.root) - 1}" if i is None else i
        if i is not None:
            self.ids[i] = element
        self.handles[handle] = element
        self._handle_of[id(element)] = handle
        self.parents[id(element)] = self.root
        return element


def _style_sheet(root) -> StyleSheet:
    sheet = StyleSheet()
    for element in root.iter():
        if local_name(element.tag) == "style" and is_svg(element):
            if (element.get("type") or "text/css").strip().lower() in ("text/css", ""):
                sheet.add("".join(element.itertext()))
    return sheet
