"""vecfit: vectorize raster images and refine vector graphics against them.

The public API: load_svg, render, the Scene and its parts, and the device queries."""
import os

# Before torch loads its OpenMP runtime: idle OpenMP threads sleep instead of spinning.
# Spinning, they took a quarter of the CPU from the core's own threads between torch's
# small per-iteration operations (a refine iteration of peppers took 1.9x as long with
# them spinning, on 2 busy cores; see benchmarks/RESULTS.md). A user's own setting wins.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from .errors import SvgError, VecfitError
from .renderer.device import cuda_device_count, has_cuda
from .renderer.batch import render_batch
from .renderer.raster import render
from .renderer.scene import (Circle, Ellipse, Group, LinearGradient, Path, RadialGradient, Rect,
                             Scene, Shape, Solid)

__version__ = "0.1.0"

__all__ = ["Circle", "Ellipse", "Group", "LinearGradient", "Path", "RadialGradient", "Rect", "Scene",
           "Shape", "Solid", "SvgError", "VecfitError", "cuda_device_count", "has_cuda", "load_svg",
           "render", "render_batch", "__version__"]


def load_svg(path) -> Scene:
    """Read an SVG file into a Scene (see vecfit.svg.read)."""
    from .svg.read import load_svg as _load
    return _load(path)
