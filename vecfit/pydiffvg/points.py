"""The scene at eval_positions: colours, and the analytical coverage the SDF is read from.

All the points go to the core in one call (render_points: each point shaded as the one
sample of a pixel centred on it, in the analytical mode), with gradients with respect to
the scene and the points. One 1 x 1 render per point, as this was, cost about 1 ms a
point in set-up alone.

Colour: the scene magnified 1000 times about the canvas origin, so that the kernel (half
a pixel) is 0.0005 canvas units: the colour at the point itself (edges that close to it
are blurred), with the analytical gradients (paint parameters; geometry only where an
edge passes that close, as for any point sample).
"""
from __future__ import annotations

import copy

import torch

from vecfit import _core
from vecfit.errors import VecfitError
from vecfit.renderer.raster import FLOAT_INPUTS, packed_for_core
from vecfit.scene import Scene

from .convert import Parsed, to_scene

ZOOM = 1000.0


class _AtPoints(torch.autograd.Function):
    """[N, 4] straight RGBA at pixel-space points [N, 2] of the packed scene."""

    @staticmethod
    def forward(ctx, positions, radius, structure, *floats):
        scene = dict(structure)
        for name, t in zip(FLOAT_INPUTS, floats):
            scene[name] = t.detach().numpy()
        xy = positions.detach().double().numpy()
        try:
            colours = _core.render_points(scene, xy, radius, 0)
        except ValueError as e:  # the core refused the scene
            raise VecfitError(str(e)) from None
        ctx.saved = (scene, xy, colours, radius, [t.shape for t in floats], positions.dtype)
        return torch.from_numpy(colours)

    @staticmethod
    def backward(ctx, grad):
        scene, xy, colours, radius, shapes, dtype = ctx.saved
        grads, d_xy = _core.render_points_grad(scene, xy, colours, grad.detach().float().contiguous().numpy(),
                                               radius, 0)
        out = [torch.from_numpy(grads[name]).reshape(shape) for name, shape in zip(FLOAT_INPUTS, shapes)]
        return (torch.from_numpy(d_xy).to(dtype), None, None, *out)


def at_points(scene: Scene, positions: torch.Tensor, scale: float, radius: float) -> torch.Tensor:
    """[N, 4] straight RGBA of ``scene`` at canvas positions [N, 2], with the canvas mapped
    to pixels ``scale`` to a unit and the analytical kernel ``radius`` pixels (>= 0.5)."""
    one = copy.copy(scene)
    one.width = one.height = 1.0  # (packed at 1 x 1: a pixel is a canvas unit, times scale)
    if scale != 1:
        one.view = torch.tensor([[scale, 0.0, 0.0], [0.0, scale, 0.0], [0.0, 0.0, 1.0]])
    structure, floats = packed_for_core(one, 1, 1)
    return _AtPoints.apply(positions.reshape(-1, 2).cpu().float() * scale, float(radius), structure, *floats)


def colors_at(parsed: Parsed, positions: torch.Tensor, device: str) -> torch.Tensor:
    """[N, 4] straight RGBA at canvas positions [N, 2]; differentiable with respect to the
    scene and the positions. (On the CPU: the device is not used.)"""
    if positions.numel() == 0:
        return torch.zeros(0, 4)
    return at_points(to_scene(parsed), positions, ZOOM, 0.5)
