"""Edited copies of SVGs for `vecfit edit`'s tests and benchmarks/edit.py: the fills of a
few drawn elements changed and one element moved, as a user would in a vector or raster
editor; and an SVG's structure (elements, ids, classes, nesting) to check it is kept."""
from __future__ import annotations

import xml.etree.ElementTree as ET

DRAWN = {"path", "rect", "circle", "ellipse", "polygon", "polyline", "line"}


def _local(tag) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def drawn_elements(root) -> list:
    return [e for e in root.iter() if _local(e.tag) in DRAWN]


def edited_svg(text: str, recolour, moved: int, dx: float, dy: float) -> str:
    """``text`` with the fill of each (index, colour) in ``recolour`` changed (the index
    counts the drawn elements in document order; set in ``style``, which beats CSS classes)
    and the drawn element ``moved`` translated by (dx, dy) user units."""
    ET.register_namespace("", "http://www.w3.org/2000/svg")
    ET.register_namespace("xlink", "http://www.w3.org/1999/xlink")
    root = ET.fromstring(text)
    drawn = drawn_elements(root)
    for index, colour in recolour:
        e = drawn[index]
        style = e.get("style", "").rstrip("; ")
        e.set("style", (style + ";" if style else "") + f"fill:{colour}")
    e = drawn[moved]
    e.set("transform", f"translate({dx} {dy}) " + e.get("transform", ""))
    return ET.tostring(root, encoding="unicode")


def structure(path) -> list:
    """(depth, tag, id, class) of every element, in document order."""
    out = []

    def walk(e, depth):
        if isinstance(e.tag, str):
            out.append((depth, _local(e.tag), e.get("id"), e.get("class")))
        for c in e:
            walk(c, depth + 1)

    walk(ET.parse(path).getroot(), 0)
    return out
