"""Render many scenes in one call of the core: what a training loop needs, where a step
renders a batch of small scenes (a decoder's output for each image of the batch).

    images = render_batch(scenes, 32, 32, samples=2)   # [B, H, W, 4], differentiable

Each scene is packed as ``render`` packs it; the core then prepares and renders them in
parallel, one scene per thread, forward and backward. The images and gradients equal
those of B separate ``render`` calls with the same options and seeds.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import torch

from vecfit import _core
from vecfit.errors import VecfitError
from vecfit.limits import MAX_PIXELS

from vecfit.scene import Scene

from . import device as devices
from .options import RenderOptions, background_rgba
from .raster import FLOAT_INPUTS, packed_for_core, render
from .stopwatch import add_core_phases, phase


def _scene_dicts(structures, floats) -> list[dict]:
    n = len(FLOAT_INPUTS)
    out = []
    for b, structure in enumerate(structures):
        d = dict(structure)
        for name, t in zip(FLOAT_INPUTS, floats[b * n:(b + 1) * n]):
            d[name] = t.detach().cpu().numpy()
        out.append(d)
    return out


class _RenderBatch(torch.autograd.Function):
    """The core's batch forward; its backward returns each scene's float-array gradients
    (autograd carries them on through each scene's packing)."""

    @staticmethod
    def forward(ctx, options, seeds, boundary_density, structures, *floats):
        ctx.scenes = _scene_dicts(structures, floats)
        try:
            with phase("call forward"):
                ctx.images = _core.render_batch(ctx.scenes, options, seeds)
            add_core_phases()
        except ValueError as e:  # the core refused a scene
            raise VecfitError(str(e)) from None
        ctx.options, ctx.seeds, ctx.boundary_density = options, seeds, boundary_density
        ctx.shapes = [t.shape for t in floats]
        return torch.from_numpy(ctx.images)

    @staticmethod
    def backward(ctx, grad_images):
        d_images = np.ascontiguousarray(grad_images.detach().cpu().numpy(), dtype=np.float32)
        with phase("call backward"):
            grads = _core.render_grad_batch(ctx.scenes, ctx.images, d_images, ctx.options, ctx.seeds,
                                            ctx.boundary_density)
        add_core_phases()
        out = [torch.from_numpy(g[name]) for g in grads for name in FLOAT_INPUTS]
        return (None, None, None, None, *[g.reshape(shape) for g, shape in zip(out, ctx.shapes)])


_D = RenderOptions  # (its defaults)


def render_batch(scenes: Sequence[Scene], width: int, height: int, *, samples: int = _D.samples,
                 mode: str = _D.mode, filter: str = _D.filter, filter_radius: float = _D.filter_radius,
                 seed: int | Sequence[int] = _D.seed, background=_D.background, threads: int | None = _D.threads,
                 boundary_samples: float = _D.boundary_samples, interior_samples: int = _D.interior_samples,
                 device: str = "cpu") -> torch.Tensor:
    """Render ``scenes`` at width x height into a [B, H, W, 4] tensor of straight RGBA,
    differentiable with respect to every tensor of every scene, as ``render`` (same
    options; ``seed`` is one seed for all or one per scene). threads: how many scenes at
    once (None or 0: all cores). On a GPU (``device``) the scenes are rendered one call
    each (the batch kernel is the CPU's)."""
    scenes = list(scenes)
    if not scenes:
        raise VecfitError("render_batch needs at least one scene")
    seeds = [int(seed)] * len(scenes) if isinstance(seed, (int, np.integer)) else [int(s) for s in seed]
    if len(seeds) != len(scenes):
        raise VecfitError(f"{len(seeds)} seeds for {len(scenes)} scenes")
    width, height = int(width), int(height)
    if width < 1 or height < 1 or width * height * len(scenes) > MAX_PIXELS:
        raise VecfitError(f"{len(scenes)} images of {width} x {height} pixels cannot be rendered "
                          f"(at most {MAX_PIXELS // 1_000_000} million pixels in all)")
    options = RenderOptions(width, height, samples=int(samples), mode=mode, filter=filter,
                            filter_radius=float(filter_radius), threads=int(threads or 0),
                            background=background_rgba(background), interior_samples=int(interior_samples),
                            boundary_samples=float(boundary_samples))
    if devices.resolve(device) >= 0:
        return torch.stack([render(s, width, height, samples=samples, mode=mode, filter=filter,
                                   filter_radius=filter_radius, seed=sd, background=background,
                                   threads=threads, boundary_samples=boundary_samples,
                                   interior_samples=interior_samples, device=device)
                            for s, sd in zip(scenes, seeds)])
    structures, floats = [], []
    for scene in scenes:
        structure, f = packed_for_core(scene, width, height)
        structures.append(structure)
        floats.extend(f)
    return _RenderBatch.apply(options.core(), seeds, options.boundary_samples, structures,
                              *floats)  # (no graph without grads)
