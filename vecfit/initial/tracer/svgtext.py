"""The traced shapes as elements of a new SvgDocument."""
from __future__ import annotations

import numpy as np

from vecfit.svg.document import NewDocument, SvgDocument
from vecfit.svg.numbers import fmt_many
from vecfit.svg.pathdata import format_relative_path_data
from vecfit.svg.write import BACKGROUND_ID

from .primitives import cubic_outline

DECIMALS = 2  # a trace is placed to a hundredth of a pixel, its refinement finer


def path_data(subpaths) -> str:
    """'M x y c ... z' for each closed subpath of cubic segments [S, 4, 2] (each closed by
    a Z after its last cubic, as the reader closes it: a line of zero length)."""
    return outline_path_data([cubic_outline(segs) for segs in subpaths if len(segs)])


def outline_path_data(outlines) -> str:
    """'M x y C ... L ... Z' for closed outlines (primitives.Outline: lines and cubics, each
    closed by a Z)."""
    if not outlines:
        return ""
    points = np.concatenate([o.points for o in outlines])
    degrees, spans = [], []
    for o in outlines:
        spans.append((len(degrees), len(o.degrees), True))
        degrees += o.degrees
    return format_relative_path_data(points, degrees, spans, decimals=DECIMALS)


def add_primitive(document: NewDocument, tag: str, geometry: dict, fill: str) -> None:
    """A rect, circle or ellipse (primitives.Primitive's geometry, in pixels)."""
    numbers = dict(zip(geometry, fmt_many(list(geometry.values()), DECIMALS)))
    document.add(tag, {**numbers, "fill": fill})


def new_document(width: int, height: int) -> NewDocument:
    return SvgDocument.new(width, height)


# The background rect reaches this far past the canvas: its edges then touch no pixel,
# get no gradient, and refinement cannot pull them in and uncover the canvas's rim.
BACKGROUND_MARGIN = 4


def add_rect(document: NewDocument, width: int, height: int, fill: str) -> None:
    m = BACKGROUND_MARGIN
    document.add("rect", {"id": BACKGROUND_ID, "x": f"-{m}", "y": f"-{m}", "width": f"{width + 2 * m}",
                          "height": f"{height + 2 * m}", "fill": fill})


def add_path(document: NewDocument, d: str, fill: str, evenodd: bool = False) -> None:
    """A traced shape (no id: like an unnamed path in a designer's file, and 8 bytes less
    a shape)."""
    attributes = {"d": d, "fill": fill}
    if evenodd:
        attributes["fill-rule"] = "evenodd"
    document.add("path", attributes)
