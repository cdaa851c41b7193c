"""SVG input and output: SVG files <-> Scene."""
from .read import load_svg
from .skips import VecfitWarning

__all__ = ["load_svg", "VecfitWarning"]
