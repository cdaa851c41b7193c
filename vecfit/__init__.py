"""vecfit: vectorize raster images and refine vector graphics against them."""
from .device import cuda_device_count, has_cuda
from .errors import SvgError, VecfitError
from .render import render
from .scene import (Circle, Ellipse, Group, LinearGradient, Path, RadialGradient, Rect,
                    Scene, Shape, Solid)

__version__ = "0.1.0"


def load_svg(path) -> Scene:
    """Read an SVG file into a Scene (see vecfit.svg.read)."""
    from .svg.read import load_svg as _load
    return _load(path)
