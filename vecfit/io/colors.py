"""Colour options given on the command line."""
from __future__ import annotations

from vecfit.errors import VecfitError

NAMED = {"white": "#ffffff", "black": "#000000"}


def parse_background(text: str | None) -> tuple[float, float, float, float] | None:
    """'none' -> None; 'white', 'black', '#rgb', '#rrggbb' or '#rrggbbaa' -> RGBA in [0, 1]."""
    if text is None or text.strip().lower() in ("", "none", "transparent"):
        return None
    s = NAMED.get(text.strip().lower(), text.strip())
    if s.startswith("#"):
        h = s[1:]
        if len(h) in (3, 4):
            h = "".join(c * 2 for c in h)
        if len(h) in (6, 8):
            try:
                values = [int(h[i:i + 2], 16) / 255 for i in range(0, len(h), 2)]
            except ValueError:
                values = []
            if values:
                return tuple(values + [1.0] * (4 - len(values)))
    raise VecfitError(f"background must be none, white, black or #rrggbb[aa], not {text!r}")


def fitting_background(text: str | None) -> tuple[float, float, float, float] | None:
    """A background to fit against (an [optimize] background other than auto): none or an
    opaque colour. The shapes are fitted to the target as seen over it, so it cannot be
    translucent."""
    bg = parse_background(text)
    if bg is not None and bg[3] < 1:
        raise VecfitError("background must be opaque (no alpha below ff) or none: the shapes are "
                          "fitted to the target seen over it")
    return bg
