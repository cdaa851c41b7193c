"""RenderOptions: how the core renders, as one typed value (the core's struct of the same
name, csrc/forward/forward.h), checked here with messages for the user and passed to the
core's entry points whole instead of as a row of positional arguments.

Its defaults are the render defaults of Python: vecfit.render, render_numpy, render_batch
and the render command read them here. A fit renders with the same but for FITTING. (Plain
Python, the core imported only to build its struct: the command line reads the defaults
at start-up.)"""
from __future__ import annotations

import math
from dataclasses import dataclass

from vecfit.errors import VecfitError
from vecfit.names import FILTERS, MODES


@dataclass(frozen=True)
class RenderOptions:
    """width x height pixels; samples: N for N x N per pixel; mode: "mc" or "analytic";
    filter and filter_radius: the pixel filter (box always covers exactly the pixel);
    seed; threads (0: all cores); background: None or straight RGBA; interior_samples:
    of the N x N, those the Monte Carlo backward pass revisits (0: all); premultiplied:
    the image as premultiplied RGBA (the layers of renderer/layers.py); boundary_budget:
    the Monte Carlo backward's boundary samples per pixel of the image at most (0: no
    bound), allotted by the pixel adjoints; boundary_samples: the Monte Carlo backward's
    boundary samples per pixel of boundary length (the core's boundary_density, which its
    backward entry points take beside the struct)."""
    width: int
    height: int
    samples: int = 2
    mode: str = "mc"
    filter: str = "box"
    filter_radius: float = 0.5
    seed: int = 0
    threads: int = 0
    background: tuple | None = None
    interior_samples: int = 0
    premultiplied: bool = False
    boundary_budget: float = 0.0
    boundary_samples: float = 2.0

    def __post_init__(self):
        check_options(self.samples, self.mode, self.filter, self.filter_radius)
        if self.interior_samples < 0:
            raise VecfitError("interior_samples must be 0 or more")
        if not (math.isfinite(self.boundary_budget) and self.boundary_budget >= 0):
            raise VecfitError(f"boundary_budget must be a number >= 0, not {self.boundary_budget}")

    def core(self) -> "_core.RenderOptions":
        """The core's struct."""
        from vecfit import _core

        bg = self.background
        return _core.RenderOptions(
            width=int(self.width), height=int(self.height), samples=int(self.samples), mode=self.mode,
            filter=self.filter, filter_radius=float(self.filter_radius), seed=int(self.seed),
            threads=int(self.threads or 0), background=None if bg is None else [float(v) for v in bg],
            interior_samples=int(self.interior_samples), premultiplied=bool(self.premultiplied),
            boundary_budget=float(self.boundary_budget))


# Where a fit (configs/refine.toml's [optimize], the loop's Settings) renders otherwise than
# vecfit.render, on purpose: its Monte Carlo backward revisits one of each pixel's N x N
# samples for the colours' term (an iteration's noise averages out over the next ones, at
# a fraction of the cost), and bounds the boundary samples at 2 per pixel of the image, put
# where the error is (dense traces had iterations dominated by their boundaries). A single
# render's gradients keep every sample and no bound. tests/unit/renderer/test_options.py
# holds refine.toml to RenderOptions' defaults but for these.
FITTING = {"interior_samples": 1, "boundary_budget": 2.0}


def check_options(samples, mode: str, filter: str, filter_radius: float) -> None:
    if mode not in MODES:
        raise VecfitError(f"mode must be one of {', '.join(MODES)}, not {mode!r}")
    if filter not in FILTERS:
        raise VecfitError(f"filter must be one of {', '.join(FILTERS)}, not {filter!r}")
    if int(samples) < 1:
        raise VecfitError("samples must be at least 1")
    if not (filter_radius > 0 and math.isfinite(filter_radius)):
        raise VecfitError("filter radius must be a positive number")


def background_rgba(background) -> tuple | None:
    """None, or the background as 4 floats (RGB gets alpha 1)."""
    if background is None:
        return None
    bg = [float(v) for v in background]
    if len(bg) == 3:
        bg.append(1.0)
    if len(bg) != 4:
        raise VecfitError("background must have 3 or 4 components")
    return tuple(bg)
