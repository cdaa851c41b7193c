"""SVG input and output: SVG files <-> Scene.

The names below are loaded on first use: the tracer needs only the number formatting of
vecfit.svg.numbers, and reading SVG (svgelements, PIL's colour table) would add 0.05 s to
`vecfit trace --no-refine`."""
from __future__ import annotations

__all__ = ["load_svg", "VecfitWarning"]


def __getattr__(name):
    if name == "load_svg":
        from .read import load_svg
        return load_svg
    if name == "VecfitWarning":
        from .skips import VecfitWarning
        return VecfitWarning
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
