"""Render a Scene with the compiled core.

The image is straight (not premultiplied) RGBA in [0, 1], shape [H, W, 4]; pixel (x, y)
covers [x, x+1) x [y, y+1) in pixel units.
"""
from __future__ import annotations

import torch

from vecfit import _core
from vecfit.errors import VecfitError

from vecfit.scene import Scene

from . import device as devices
from .forward import FLOAT_INPUTS, _core_render, check_finite, output_size, packed_for_core  # noqa: F401
from .options import RenderOptions, background_rgba
from .stopwatch import add_core_phases, phase


class _Render(torch.autograd.Function):
    """The core's forward pass; its backward returns the gradients of the float arrays
    (the autograd graph of vecfit.renderer.pack carries them on to the Scene's tensors)."""

    @staticmethod
    def forward(ctx, options, device, boundary_density, structure, *floats):
        ctx.scene, ctx.image, ctx.prepared = _core_render(options, device, structure, floats, keep=True)
        ctx.options, ctx.device, ctx.boundary_density = options, device, boundary_density
        ctx.shapes = [t.shape for t in floats]
        return torch.from_numpy(ctx.image)

    @staticmethod
    def backward(ctx, grad_image):
        try:
            with phase("call backward"):
                grads = _core.render_grad(ctx.scene, ctx.image, grad_image.detach().cpu().contiguous().numpy(),
                                          ctx.options, ctx.boundary_density, ctx.device, ctx.prepared)
            ctx.prepared = None  # (its memory, before the next forward pass)
            add_core_phases()
        except RuntimeError as e:  # the GPU failed (out of memory, driver)
            raise VecfitError(f"gradients on {devices.device_name(ctx.device)} failed: {e}") from None
        out = [torch.from_numpy(grads[name]).reshape(shape) for name, shape in zip(FLOAT_INPUTS, ctx.shapes)]
        return (None, None, None, None, *out)


_D = RenderOptions  # (its defaults)


def render(scene: Scene, width: int | None = None, height: int | None = None, *,
           samples: int = _D.samples, mode: str = _D.mode, filter: str = _D.filter,
           filter_radius: float = _D.filter_radius, seed: int = _D.seed, background=_D.background,
           threads: int | None = _D.threads, boundary_samples: float = _D.boundary_samples,
           interior_samples: int = _D.interior_samples, boundary_budget: float = _D.boundary_budget,
           device: str = "cpu", packed: tuple | None = None, _premultiplied: bool = False) -> torch.Tensor:
    """Render ``scene`` into an [H, W, 4] float tensor of straight RGBA.

    samples: N means N x N stratified samples per pixel (jittered in "mc" mode, at the
    strata centres in "analytic" mode). filter: the pixel filter, with its radius in
    pixels (box always covers exactly the pixel). background: None (transparent) or an
    RGBA / RGB sequence in [0, 1]. threads: None or 0 for all cores. (The defaults are
    RenderOptions'.)

    The result is differentiable with respect to every tensor of the scene. In "mc" mode
    the backward pass samples the boundaries (``boundary_samples`` points per pixel of
    boundary length, same seed) and revisits ``interior_samples`` of each pixel's N x N
    samples for the colours' (interior) term, a random run weighted up (0: all of them);
    ``boundary_budget`` (> 0) bounds the boundary samples at that many per pixel of the
    image, allotted by the pixel adjoints near each boundary, still unbiased (0: no bound).
    In "analytic" mode the backward pass differentiates the prefilter.

    device: where the pixels are shaded: "cpu", "cuda" or "cuda:N" (needs a core built
    with VECFIT_CUDA=1; see vecfit.has_cuda()), or "auto" (a GPU when there is one). The
    same seed gives the same image on either; gradients are computed where the image was.
    The scene's tensors and the result are CPU tensors either way (the scene is packed
    and prepared on the host).

    packed: the scene already packed at this size, (integer tables, float arrays in
    FLOAT_INPUTS order), as PersistentPack.arrays gives it; the image and its gradients
    then follow those arrays, and the scene gives only its size.

    (_premultiplied: the image as premultiplied RGBA, for the layers of layers.py.)
    """
    width, height = output_size(scene, width, height)
    if packed is None and scene.has_effects():  # clip paths, masks, filters: in layers
        from .layers import render_layered

        def draw(sub: Scene, number: int) -> torch.Tensor:
            layer_seed = (int(seed) + 1_000_003 * number) % (1 << 62)
            return render(sub, samples=samples, mode=mode, filter=filter, filter_radius=filter_radius, seed=layer_seed,
                          threads=threads, boundary_samples=boundary_samples, interior_samples=interior_samples,
                          boundary_budget=boundary_budget, device=device, _premultiplied=True)
        return render_layered(scene, width, height, draw, background_rgba(background))
    options = RenderOptions(width, height, samples=int(samples), mode=mode, filter=filter,
                            filter_radius=float(filter_radius), seed=int(seed), threads=int(threads or 0),
                            background=background_rgba(background), interior_samples=int(interior_samples),
                            premultiplied=bool(_premultiplied),
                            boundary_budget=float(boundary_budget), boundary_samples=float(boundary_samples))
    if packed is None:
        structure, floats = packed_for_core(scene, width, height)
    else:
        structure, floats = packed
        check_finite(floats)
    core, where = options.core(), devices.resolve(device)
    if torch.is_grad_enabled() and any(t.requires_grad for t in floats):
        return _Render.apply(core, where, options.boundary_samples, structure, *floats)
    return torch.from_numpy(_core_render(core, where, structure, floats)[1])


def backward_fallbacks() -> int:
    """How many backward passes so far (in this process) were redone on the CPU because a
    sample needed longer lists than a GPU thread holds (more than 32 draws over one point,
    or a compositing tape of over 96 steps). A GPU run that falls back is no faster."""
    return int(_core.backward_fallbacks())

