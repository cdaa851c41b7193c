"""vecfit: vectorize raster images and refine vector graphics against them.

The public API: load_svg, render, render_batch, the Scene and its parts, and the device
queries. They are imported on first use: importing vecfit (and so starting the command
line) does not import torch, so that a Ctrl-C in the first second is handled by the
command (exit 130) rather than interrupting an import."""
from __future__ import annotations

import importlib
import os

from .errors import SvgError, VecfitError

# Before torch loads its OpenMP runtime: idle OpenMP threads sleep instead of spinning.
# Spinning, they took a quarter of the CPU from the core's own threads between torch's
# small per-iteration operations (a refine iteration of peppers took 1.9x as long with
# them spinning, on 2 busy cores; see benchmarks/RESULTS.md). A user's own setting wins.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
# Before NumPy loads OpenBLAS: its worker threads, started as it loads, sleep when idle
# instead of spinning for their first 2^28 cycles (a tenth of a second of a core, taken
# from the command's own start-up and the core's render threads on a busy machine).
os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", "4")

__version__ = "0.1.0"

__all__ = ["Circle", "Ellipse", "Group", "LinearGradient", "Path", "RadialGradient", "Rect", "Scene",
           "Shape", "Solid", "SvgError", "VecfitError", "cuda_device_count", "has_cuda", "load_svg",
           "render", "render_batch", "trace", "refine", "paint", "edit", "retarget", "__version__"]

_LAZY = {"render": ".renderer.raster", "render_batch": ".renderer.many",
         "cuda_device_count": ".renderer.device", "has_cuda": ".renderer.device",
         "trace": ".jobs.api", "refine": ".jobs.api", "paint": ".jobs.api", "edit": ".jobs.api",
         "retarget": ".jobs.api",
         **{name: ".scene" for name in ("Circle", "Ellipse", "Group", "LinearGradient", "Path",
                                                 "RadialGradient", "Rect", "Scene", "Shape", "Solid")}}


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'vecfit' has no attribute {name!r}")
    value = getattr(importlib.import_module(_LAZY[name], __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))


def load_svg(path) -> Scene:
    """Read an SVG file into a Scene (see vecfit.svg.read)."""
    from .svg.read import load_svg as _load
    return _load(path)
