"""vecfit: vectorize raster images and refine vector graphics against them."""
from .errors import SvgError, VecfitError
from .scene import (Circle, Ellipse, Group, LinearGradient, Path, RadialGradient, Rect,
                    Scene, Shape, Solid)

__version__ = "0.1.0"


def load_svg(path) -> Scene:
    """Read an SVG file into a Scene (see vecfit.svg.read)."""
    from .svg.read import load_svg as _load
    return _load(path)


def render(*args, **kwargs):
    """Render a Scene to an [H, W, 4] straight-RGBA tensor (see vecfit.render)."""
    from .render import render as _render
    return _render(*args, **kwargs)
