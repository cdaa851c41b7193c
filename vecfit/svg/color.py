"""CSS colour syntax to straight RGBA floats in [0, 1].

Accepts what SVG 1.1 and CSS Color 3/4 allow in SVG files: names, ``transparent``,
#rgb, #rgba, #rrggbb, #rrggbbaa, rgb()/rgba() and hsl()/hsla() with numbers or
percentages, commas or spaces, and an optional alpha (``/ a`` or a fourth argument).
Out-of-range components are clamped, as browsers and resvg do.
"""
from __future__ import annotations

import colorsys
import functools
import math
import re

from .units import NUMBER

RGBA = tuple[float, float, float, float]


@functools.cache
def _names() -> dict[str, RGBA]:
    """CSS's colour keywords, from Pillow's table, copied once (Pillow caches parsed tuples
    back into its own table), at the first keyword met: importing Pillow costs `vecfit
    render` a twentieth of a second, and many files write only hex colours."""
    from PIL import ImageColor

    names = {name: tuple(c / 255.0 for c in ImageColor.getrgb(name)) + (1.0,)
             for name in list(ImageColor.colormap)}
    names["transparent"] = (0.0, 0.0, 0.0, 0.0)
    return names

_HEX = re.compile(r"#([0-9a-fA-F]{3,8})$")
# The function's name; its arguments are what lies between "(" and the closing ")",
# stripped (as a pattern, "\s*(.*?)\s*\)$" tried every split of a run of spaces: cubic).
_FUNC = re.compile(r"(rgba?|hsla?)\(", re.IGNORECASE)
_ARG = re.compile(rf"({NUMBER})(%|deg)?$", re.IGNORECASE)


def _clamp01(v: float) -> float:
    return 0.0 if v < 0 else 1.0 if v > 1 else v


@functools.lru_cache(maxsize=1024)
def parse_color(text) -> RGBA | None:
    """A colour value, or None when ``text`` is not one (``currentColor`` included: the
    caller resolves it). (Cached: files repeat a few colours over thousands of shapes.)"""
    if text is None:
        return None
    text = text.strip()
    m = _HEX.match(text)
    if m:
        return _hex(m.group(1))
    m = _FUNC.match(text)
    if m and text.endswith(")"):
        body = text[m.end():-1].strip()
        if "\n" not in body:  # (as the pattern before: a line break only beside the parentheses)
            return _function(m.group(1).lower(), body)
    return _names().get(text.lower())


def _hex(digits: str) -> RGBA | None:
    if len(digits) in (3, 4):
        digits = "".join(c * 2 for c in digits)
    if len(digits) == 6:
        digits += "ff"
    if len(digits) != 8:
        return None
    r, g, b, a = (int(digits[i:i + 2], 16) / 255.0 for i in range(0, 8, 2))
    return (r, g, b, a)


def _split_args(body: str):
    """Arguments as (value, unit) pairs; CSS 4's ``r g b / a`` and CSS 3's commas."""
    alpha = None
    if "/" in body:
        body, alpha = body.split("/", 1)
    parts = [p for p in re.split(r"[\s,]+", body.strip()) if p]
    if alpha is not None:
        parts.append(alpha.strip())
    out = []
    for p in parts:
        m = _ARG.match(p)
        if not m:
            return None
        out.append((float(m.group(1)), (m.group(2) or "").lower()))
    return out


def _alpha(arg) -> float:
    value, unit = arg
    return _clamp01(value / 100.0 if unit == "%" else value)


def _function(name: str, body: str) -> RGBA | None:
    args = _split_args(body)
    if args is None or len(args) not in (3, 4) or not all(math.isfinite(v) for v, _ in args):
        return None
    a = _alpha(args[3]) if len(args) == 4 else 1.0
    if name.startswith("rgb"):
        rgb = [_clamp01(v / 100.0 if unit == "%" else v / 255.0) for v, unit in args[:3]]
        return (rgb[0], rgb[1], rgb[2], a)
    (h, _), (s, _), (l, _) = args[:3]
    r, g, b = colorsys.hls_to_rgb((h / 360.0) % 1.0, _clamp01(l / 100.0), _clamp01(s / 100.0))
    return (r, g, b, a)
