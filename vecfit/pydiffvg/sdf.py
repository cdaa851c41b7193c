"""OutputType.sdf: the signed distance to the nearest boundary of the scene's shapes.

Each group's filled region (and, separately, its stroke) is rendered alone in vecfit's
analytical mode, whose coverage is a known smooth kernel of the exact signed distance:
K(d / r) = 1/2 + ((d/r)^3 - 3 d/r) / 4. With the kernel radius r twice the image's
diagonal, |d / r| <= 1/2 everywhere, and inverting K gives d back (to float rounding:
about 1e-5 px) with its gradients, through vecfit's analytical backward pass.

The result, in canvas units: the smallest distance to any region's boundary, negative
where the point lies inside some region (a filled group or a stroke).
"""
from __future__ import annotations

import copy
import math

import torch

from vecfit.renderer.raster import render

from .convert import Parsed, to_scene
from .points import at_points
from .enums import ColorType

WHITE = torch.tensor([1.0, 1.0, 1.0, 1.0])


def _regions(parsed: Parsed):
    """One single-region copy of the parsed scene per group fill and per group stroke."""
    for ids, fill, stroke, even_odd, m in parsed.groups:
        for is_fill, paint in ((True, fill), (False, stroke)):
            if paint is None:
                continue
            one = copy.copy(parsed)
            solid = (ColorType.constant, (WHITE,))
            one.groups = [(ids, solid if is_fill else None, None if is_fill else solid, even_odd, m)]
            yield one


def _distance(coverage: torch.Tensor, r: float) -> torch.Tensor:
    """d with K(d / r) = coverage: the middle root of t^3 - 3t + 2 - 4 coverage = 0."""
    c = coverage.double().clamp(1e-12, 1 - 1e-12)
    theta = torch.arccos(2 * c - 1)
    return (2 * torch.cos(theta / 3 - 2 * math.pi / 3) * r).float()


def _combine(distances: list[torch.Tensor]) -> torch.Tensor:
    if len(distances) == 1:
        return distances[0]
    d = torch.stack(distances)
    nearest = d.abs().min(dim=0).values
    inside = (d < 0).any(dim=0)
    return torch.where(inside, -nearest, nearest)


def sdf_image(parsed: Parsed, width: int, height: int, device: str) -> torch.Tensor:
    """[H, W, 1] signed distances at the pixel centres, in canvas units."""
    r = 2 * math.hypot(width, height)
    scale = math.sqrt(width / float(parsed.canvas_width) * height / float(parsed.canvas_height))
    out = []
    for region in _regions(parsed):
        alpha = render(to_scene(region), width, height, samples=1, mode="analytic", filter="tent",
                       filter_radius=r, device=device)[..., 3]
        out.append(_distance(alpha, r) / scale)
    if not out:
        return torch.full((height, width, 1), float("inf"))
    return _combine(out)[..., None]


def sdf_at(parsed: Parsed, positions: torch.Tensor, device: str) -> torch.Tensor:
    """[N, 1] signed distances at canvas positions [N, 2], all the points of a region in one
    call of the core (points.at_points). Differentiable with respect to the scene and the
    positions. (On the CPU: the device is not used.)"""
    positions = positions.reshape(-1, 2).cpu().float()
    r = 2 * math.hypot(float(parsed.canvas_width), float(parsed.canvas_height))
    out = [_distance(at_points(to_scene(region), positions, 1.0, r)[:, 3], r) for region in _regions(parsed)]
    if not out:
        return torch.full((positions.shape[0], 1), float("inf"))
    return _combine(out)[:, None]
