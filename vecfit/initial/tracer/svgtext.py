"""The traced shapes as elements of a new SvgDocument."""
from __future__ import annotations

import operator

import numpy as np

from vecfit.svg.document import NewDocument, SvgDocument
from vecfit.svg.numbers import fmt_many

DECIMALS = 2  # a trace is placed to a hundredth of a pixel, its refinement finer
_HUNDREDTHS = [""] + [f".{f:02d}".rstrip("0") for f in range(1, 100)]  # ".01" ... ".5" ... ".99"


def format_hundredths(values) -> list[str]:
    """fmt_many(values, 2), the same text, 1.4x as fast: numbers well away from a half
    hundredth are rounded to whole hundredths in NumPy (a float's error in v * 100 is far
    below the margin, so printf would round them the same way) and written as integer
    part and a looked-up fraction; the others, and any non-finite value (which fmt_many
    refuses), go through fmt_many."""
    v = np.asarray(values, float).ravel()
    if not np.isfinite(v).all():
        return fmt_many(v, 2)
    scaled = v * 100
    k = np.rint(scaled)
    large = np.abs(v) >= 1e9  # (left to fmt_many, before they overflow an int64)
    whole = np.abs(np.where(large, 0, k)).astype(np.int64)
    out = list(map(operator.add, map(str, (whole // 100).tolist()),
                   map(_HUNDREDTHS.__getitem__, (whole % 100).tolist())))
    for i in np.flatnonzero(k < 0).tolist():
        out[i] = "-" + out[i]
    unsure = np.flatnonzero(~(np.abs(scaled - k) < 0.499) | large)
    for i, text in zip(unsure.tolist(), fmt_many(v[unsure], 2)):
        out[i] = text
    return out


def path_data_many(shapes) -> list[str]:
    """The path data of each shape, a list of closed subpaths of cubic segments [S, 4, 2]:
    'M x y C x y x y x y ... Z' for each subpath (closed by a Z after its last cubic, as
    the reader closes it: a line of zero length), as format_path_data writes it (compact,
    two decimals: DECIMALS, which format_hundredths writes). All shapes' numbers are formatted in one pass, and each segment's
    text made by one call: a trace writes 50,000 numbers, and a call per path or per
    number is what costs."""
    subpaths = [segs for shape in shapes for segs in shape if len(segs)]
    if not subpaths:
        return ["" for _ in shapes]
    segs = np.concatenate(subpaths).reshape(-1, 4, 2)
    counts = np.array([len(sp) for sp in subpaths])
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    # the numbers of every segment's three points, then of every subpath's start
    numbers = format_hundredths(np.concatenate([segs[:, 1:].reshape(-1), segs[first, 0].reshape(-1)]))
    cubic = numbers[:6 * len(segs)]
    cubics = list(map("C{} {} {} {} {} {}".format, *(cubic[k::6] for k in range(6))))
    start = numbers[6 * len(segs):]
    texts = [f"M{x} {y}" + "".join(cubics[a:a + n]) + "Z"
             for x, y, a, n in zip(start[0::2], start[1::2], first.tolist(), counts.tolist())]
    out, k = [], 0
    for shape in shapes:
        n = sum(1 for segs in shape if len(segs))
        out.append("".join(texts[k:k + n]))
        k += n
    return out


def new_document(width: int, height: int) -> NewDocument:
    return SvgDocument.new(width, height)


# The background rect reaches this far past the canvas: its edges then touch no pixel,
# get no gradient, and refinement cannot pull them in and uncover the canvas's rim.
BACKGROUND_MARGIN = 4


def add_rect(document: NewDocument, ident: str, width: int, height: int, fill: str) -> None:
    m = BACKGROUND_MARGIN
    document.add("rect", {"id": ident, "x": f"-{m}", "y": f"-{m}", "width": f"{width + 2 * m}",
                          "height": f"{height + 2 * m}", "fill": fill})


def add_path(document: NewDocument, ident: str, d: str, fill: str, evenodd: bool = False) -> None:
    attributes = {"id": ident, "d": d, "fill": fill}
    if evenodd:
        attributes["fill-rule"] = "evenodd"
    document.add("path", attributes)
