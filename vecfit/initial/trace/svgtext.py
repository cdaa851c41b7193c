"""SVG text of the traced shapes."""
from __future__ import annotations

from vecfit.svg.numbers import fmt


def number(v: float) -> str:
    """Compact decimal with at most 2 decimals: 12.5, 3, -0.25 (never -0)."""
    return fmt(v, 2)


def path_data(subpaths) -> str:
    """'M x y C ... Z' for each closed subpath of cubic segments [S, 4, 2]."""
    parts = []
    for segs in subpaths:
        if len(segs) == 0:
            continue
        parts.append(f"M{number(segs[0, 0, 0])} {number(segs[0, 0, 1])}")
        for seg in segs:
            parts.append("C" + " ".join(f"{number(x)} {number(y)}" for x, y in seg[1:]))
        parts.append("Z")
    return "".join(parts)


def svg_document(width: int, height: int, elements: list[str]) -> str:
    head = (f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
            f'viewBox="0 0 {width} {height}">')
    return "\n".join([head, *elements, "</svg>"]) + "\n"


# The background rect reaches this far past the canvas: its edges then touch no pixel,
# get no gradient, and refinement cannot pull them in and uncover the canvas's rim.
BACKGROUND_MARGIN = 4


def rect_element(ident: str, width: int, height: int, fill: str) -> str:
    m = BACKGROUND_MARGIN
    return (f'<rect id="{ident}" x="-{m}" y="-{m}" width="{width + 2 * m}" height="{height + 2 * m}" '
            f'fill="{fill}"/>')


def path_element(ident: str, d: str, fill: str, evenodd: bool = False) -> str:
    rule = ' fill-rule="evenodd"' if evenodd else ""
    return f'<path id="{ident}" d="{d}" fill="{fill}"{rule}/>'
