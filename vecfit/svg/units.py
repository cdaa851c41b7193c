"""Numbers, lengths, transforms and viewBox mapping: the small parsers of SVG attribute values.

Every parser here returns None for a value it cannot read, so that callers apply SVG's
rule for that attribute (usually: use the default) instead of failing the whole file.
"""
from __future__ import annotations

import math
import re

import numpy as np

# Larger magnitudes overflow float32 or make the renderer's arithmetic lose all precision.
LIMIT = 1e7

# Quantifiers are possessive (``++``, ``*+``, ``?+``: what they take is never given back),
# so that a match fails in one pass: backtracking into a number (is "123" also "1", "23"?)
# or into whitespace beside whitespace made matching quadratic, cubic or exponential in
# the value's length (issue 41). A number's parts cannot start one another, so taking the
# longest accepts the same texts.
NUMBER = r"[-+]?+(?:\d++(?:\.\d*+)?+|\.\d++)(?:[eE][-+]?+\d++)?+"
_NUMBER_RE = re.compile(NUMBER)
_LENGTH_RE = re.compile(rf"\s*+({NUMBER})\s*+(px|pt|pc|mm|cm|in|em|ex|%)?+\s*+$", re.IGNORECASE)
_LIST_SPLIT = re.compile(r"[\s,]+")

# Absolute units in px at CSS's 96 dpi; em and ex assume the default 16 px font.
_UNIT_PX = {None: 1.0, "px": 1.0, "pt": 96 / 72, "pc": 16.0, "mm": 96 / 25.4,
            "cm": 96 / 2.54, "in": 96.0, "em": 16.0, "ex": 8.0}


def parse_number(text) -> float | None:
    """A plain number (no unit), or None."""
    if text is None:
        return None
    m = _NUMBER_RE.fullmatch(text.strip())
    return float(m.group(0)) if m else None


def parse_length(text, reference: float | None = None) -> float | None:
    """A length in px. Percentages are relative to ``reference`` (None: not allowed)."""
    if text is None:
        return None
    m = _LENGTH_RE.match(text)
    if not m:
        return None
    value, unit = float(m.group(1)), m.group(2)
    if unit == "%":
        return None if reference is None else value / 100.0 * reference
    return value * _UNIT_PX[unit.lower() if unit else None]


def parse_fraction(text) -> float | None:
    """A number or a percentage, as a fraction (``50%`` -> 0.5); not clamped."""
    if text is None:
        return None
    text = text.strip()
    if text.endswith("%"):
        value = parse_number(text[:-1])
        return None if value is None else value / 100.0
    return parse_number(text)


def parse_numbers(text) -> list[float] | None:
    """A whitespace/comma separated list of numbers, or None if any item is not one."""
    if text is None:
        return None
    items = [t for t in _LIST_SPLIT.split(text.strip()) if t]
    values = [parse_number(t) for t in items]
    return None if any(v is None for v in values) else values


def clamp(value: float) -> float:
    """Keep a parsed number finite and within what float32 geometry can carry."""
    if math.isnan(value):
        return 0.0
    return min(max(value, -LIMIT), LIMIT)


def clamp_array(values) -> tuple[np.ndarray, bool]:
    """float64 array with NaN set to 0 and magnitudes limited; and whether any changed."""
    if type(values) is float and -LIMIT <= values <= LIMIT:  # (a shape's stroke width: no min, max)
        return np.array(values), False
    a = np.asarray(values, dtype=np.float64)
    if a.size == 0 or (-LIMIT <= a.min() and a.max() <= LIMIT):  # False for NaN too
        return a, False
    return np.clip(np.nan_to_num(a, nan=0.0), -LIMIT, LIMIT), True


def parse_transform(text) -> np.ndarray | None:
    """A transform attribute as a 3x3 float64 matrix; None for an empty or invalid one.

    Lists of matrix, translate and scale are multiplied here as svgelements multiplies
    them; svgelements reads the others (rotations, skews); we only check the result is
    finite.
    """
    if text is None or not text.strip():
        return None
    items = _transform_items(text)
    if items is None:
        return None  # as resvg: a list with any error is no transform at all
    m = _product(items)
    if m is None:
        import svgelements  # (rotations and skews; imported here: a tenth of `vecfit render`'s imports)
        try:
            m = svgelements.Matrix(text)
        except Exception:  # svgelements raises assorted errors on malformed lists
            return None
        m = (m.a, m.b, m.c, m.d, m.e, m.f)
    a, b, c, d, e, f = m
    out = np.array([[a, c, e], [b, d, f], [0.0, 0.0, 1.0]], dtype=np.float64)
    if not np.isfinite(out).all():
        return None
    return out


_TRANSFORM_ARITY = {"matrix": (6,), "translate": (1, 2), "scale": (1, 2), "rotate": (1, 3), "skewX": (1,),
                    "skewY": (1,)}
_WSP = r"[ \t\r\n\f]"
_COMMA_WSP = rf"(?:{_WSP}++,?+{_WSP}*+|,{_WSP}*+)"
# (possessive, as NUMBER: with numbers that may follow each other unseparated, "(" and 24
# digits without ")" had 2^23 ways to fail)
_TRANSFORM_ITEM = re.compile(rf"{_WSP}*+([A-Za-z]++){_WSP}*+\({_WSP}*+((?:{NUMBER}(?:{_COMMA_WSP}(?=[-+.\d]))?+)*+)"
                             rf"{_WSP}*+\)(?:{_WSP}*+,?+{_WSP}*+)")


def _transform_items(text: str) -> list[tuple[str, list[str]]] | None:
    """The items of ``text`` (function, its numbers as written) when it is a transform list
    by SVG's grammar: known functions with their numbers of arguments, separated by commas
    or whitespace; else None (svgelements reads more: it takes "translate(0,5, 0,5)" and
    "scale(2,,2)", where browsers and resvg take none)."""
    pos, items = 0, []
    while pos < len(text):
        m = _TRANSFORM_ITEM.match(text, pos)
        if m is None or m.end() == pos:
            return None if text[pos:].strip(" \t\r\n\f") else items
        numbers = _NUMBER_RE.findall(m.group(2))
        if m.group(1) not in _TRANSFORM_ARITY or len(numbers) not in _TRANSFORM_ARITY[m.group(1)]:
            return None
        items.append((m.group(1), numbers))
        pos = m.end()
    return items


# A number as svgelements splits it too ("5." and "5.e3" it reads otherwise).
_PLAIN_NUMBER = re.compile(r"[-+]?+(?:\d++(?:\.\d++)?+|\.\d++)(?:[eE][-+]?+\d++)?+")


def _product(items) -> tuple[float, ...] | None:
    """The matrix (a, b, c, d, e, f) of a list of matrix, translate and scale items, by
    svgelements' arithmetic (Matrix.pre_cat, matrix_multiply), so that its values are the
    same to the bit; None for a list with a rotation, a skew or a number written in a form
    svgelements splits otherwise (svgelements then reads the list)."""
    ma, mb, mc, md, me, mf = 1.0, 0.0, 0.0, 1.0, 0.0, 0.0
    for name, numbers in items:
        if name not in ("matrix", "translate", "scale") or not all(_PLAIN_NUMBER.fullmatch(t) for t in numbers):
            return None
        v = [float(t) for t in numbers]
        if name == "matrix":
            sa, sb, sc, sd, se, sf = v
        elif name == "translate":
            sa, sb, sc, sd, se, sf = 1.0, 0.0, 0.0, 1.0, v[0], (v[1] if len(v) == 2 else 0.0)
        else:
            sa, sb, sc, sd, se, sf = v[0], 0, 0, (v[1] if len(v) == 2 else v[0]), 0, 0
        # (svgelements' matrix_multiply(item, so far), term for term)
        ma, mb, mc, md, me, mf = (ma * sa + mc * sb + me * 0, mb * sa + md * sb + mf * 0,
                                  ma * sc + mc * sd + me * 0, mb * sc + md * sd + mf * 0,
                                  ma * se + mc * sf + me * 1, mb * se + md * sf + mf * 1)
    return ma, mb, mc, md, me, mf


def translate(x: float, y: float) -> np.ndarray:
    return np.array([[1.0, 0.0, x], [0.0, 1.0, y], [0.0, 0.0, 1.0]])


def parse_viewbox(text) -> tuple[float, float, float, float] | None:
    """viewBox as (min-x, min-y, width, height); None when absent or not four numbers.
    A zero or negative size is returned as is (the caller decides: an error for the root)."""
    values = parse_numbers(text)
    if values is None or len(values) != 4:
        return None
    return tuple(values)


_ALIGNS = {"none", "xminymin", "xmidymin", "xmaxymin", "xminymid", "xmidymid", "xmaxymid",
           "xminymax", "xmidymax", "xmaxymax"}


def view_transform(viewbox, width: float, height: float, aspect: str | None) -> np.ndarray:
    """The matrix mapping a viewBox onto a width x height viewport (SVG's algorithm for
    preserveAspectRatio; default xMidYMid meet)."""
    vx, vy, vw, vh = viewbox
    parts = (aspect or "").split()
    if parts and parts[0] == "defer":
        parts = parts[1:]
    align = parts[0].lower() if parts and parts[0].lower() in _ALIGNS else "xmidymid"
    slice_ = len(parts) > 1 and parts[1].lower() == "slice"
    sx, sy = width / vw, height / vh
    if align == "none":
        return np.array([[sx, 0, -vx * sx], [0, sy, -vy * sy], [0, 0, 1.0]])
    s = max(sx, sy) if slice_ else min(sx, sy)
    tx, ty = -vx * s, -vy * s
    free_x, free_y = width - vw * s, height - vh * s
    tx += {"xmin": 0.0, "xmid": free_x / 2, "xmax": free_x}[align[:4]]
    ty += {"ymin": 0.0, "ymid": free_y / 2, "ymax": free_y}[align[4:]]
    return np.array([[s, 0, tx], [0, s, ty], [0, 0, 1.0]])
