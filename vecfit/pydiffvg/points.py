"""Colour at eval_positions: the scene's straight RGBA at given canvas points.

Each point is the centre of a 1 x 1 image of the scene magnified 1000 times about it,
rendered in the analytical mode (one sample, the smallest kernel): the pixel is the
colour at the point itself (edges within 0.0005 canvas units of it are blurred), and its
gradients are the analytical ones (paint parameters; geometry only where an edge passes
that close, as for any point sample). One render per point: meant for hundreds of points.
"""
from __future__ import annotations

import torch

from vecfit.renderer.raster import render

from .convert import Parsed, to_scene

ZOOM = 1000.0


def colors_at(parsed: Parsed, positions: torch.Tensor, device: str) -> torch.Tensor:
    """[N, 4] straight RGBA at canvas positions [N, 2]; differentiable with respect to the
    scene and the positions."""
    positions = positions.reshape(-1, 2).cpu().float()
    scene = to_scene(parsed)
    scene.width = scene.height = 1.0
    out = []
    for p in positions:
        # canvas -> a 1 x 1 image whose centre is p, magnified ZOOM times
        scene.view = torch.cat([torch.cat([ZOOM * torch.eye(2), (0.5 - ZOOM * p)[:, None]], dim=1),
                                torch.tensor([[0.0, 0.0, 1.0]])])
        out.append(render(scene, 1, 1, samples=1, mode="analytic", filter="box", device=device)[0, 0])
    return torch.stack(out) if out else torch.zeros(0, 4)
