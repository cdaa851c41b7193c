"""Render a Scene with the compiled core.

The image is straight (not premultiplied) RGBA in [0, 1], shape [H, W, 4]; pixel (x, y)
covers [x, x+1) x [y, y+1) in pixel units.
"""
from __future__ import annotations

import math

import numpy as np
import torch

from . import _core
from .errors import VecfitError
from .pack import pack_scene
from .scene import Scene

MODES = ("mc", "analytic")
FILTERS = ("box", "tent", "gaussian")


def output_size(scene: Scene, width: int | None, height: int | None) -> tuple[int, int]:
    """Pixel size to render at: the scene's own size, or the given width and/or height
    (given only one, the other keeps the scene's aspect ratio, rounded to a pixel)."""
    if width is None and height is None:
        return max(1, round(scene.width)), max(1, round(scene.height))
    if width is None:
        width = max(1, round(height * scene.width / scene.height))
    if height is None:
        height = max(1, round(width * scene.height / scene.width))
    return int(width), int(height)


def render(scene: Scene, width: int | None = None, height: int | None = None, *,
           samples: int = 2, mode: str = "mc", filter: str = "box", filter_radius: float = 0.5,
           seed: int = 0, background=None, threads: int | None = None,
           _brute_force: bool = False) -> torch.Tensor:
    """Render ``scene`` into an [H, W, 4] float tensor of straight RGBA.

    samples: N means N x N stratified samples per pixel (jittered in "mc" mode, at the
    strata centres in "analytic" mode). filter: the pixel filter, with its radius in
    pixels (box always covers exactly the pixel). background: None (transparent) or an
    RGBA / RGB sequence in [0, 1]. threads: None or 0 for all cores.
    """
    if mode not in MODES:
        raise VecfitError(f"mode must be one of {', '.join(MODES)}, not {mode!r}")
    if filter not in FILTERS:
        raise VecfitError(f"filter must be one of {', '.join(FILTERS)}, not {filter!r}")
    if int(samples) < 1:
        raise VecfitError("samples must be at least 1")
    if not (filter_radius > 0 and math.isfinite(filter_radius)):
        raise VecfitError("filter radius must be a positive number")
    width, height = output_size(scene, width, height)
    if background is not None:
        bg = [float(v) for v in background]
        if len(bg) == 3:
            bg.append(1.0)
        if len(bg) != 4:
            raise VecfitError("background must have 3 or 4 components")
        background = bg
    arrays = pack_scene(scene, width, height).arrays()
    core_args = {k: (v.detach().cpu().numpy() if isinstance(v, torch.Tensor) else v)
                 for k, v in arrays.items()}
    for name, value in core_args.items():
        if value.dtype.kind == "f" and not np.isfinite(value).all():
            raise VecfitError(f"the scene has non-finite values ({name})")
    image = _core.render(
        core_args["points"], core_args["segments"], core_args["subpaths"], core_args["shapes"],
        core_args["ellipses"], core_args["draws"], core_args["draw_params"], core_args["paints"],
        core_args["paint_params"], core_args["stop_offsets"], core_args["stop_colors"],
        core_args["layer_parents"], core_args["layer_opacity"], width, height, int(samples),
        mode, filter, float(filter_radius), int(seed), int(threads or 0), background,
        _brute_force)
    return torch.from_numpy(image)
