"""The paper's Fig. 9 check (Li et al. 2020): does a renderer's gradient equal the
derivative of its own image? Every geometry point of the scene moves right by delta;
L(delta) = sum(W * image) with W a smooth random weighting that vanishes near the canvas
border; dL/d delta by autograd against central differences of the same renderer, same
seed both sides. Used by benchmarks/fig9.py and tests/oracles/test_fig9.py.
"""
from __future__ import annotations

import copy

import torch

from vecfit.renderer.raster import render
from vecfit.scene import Circle, ClipPath, Ellipse, Path, Rect, Scene


def weighting(seed: int, height: int, width: int, border: float = 4.0) -> torch.Tensor:
    """[H, W, 4] smooth random weights (bicubic from 8x8), ramping to 0 within `border`
    pixels of the canvas edge (an edge lying on the border is a kink: DESIGN.md)."""
    g = torch.Generator().manual_seed(seed)
    coarse = torch.rand(1, 4, 8, 8, generator=g)
    w = torch.nn.functional.interpolate(coarse, size=(height, width), mode="bicubic", align_corners=True)[0]
    ry = torch.clamp(torch.minimum(torch.arange(height), torch.arange(height).flip(0)) / border, 0, 1)
    rx = torch.clamp(torch.minimum(torch.arange(width), torch.arange(width).flip(0)) / border, 0, 1)
    return (w * ry[None, :, None] * rx[None, None, :]).permute(1, 2, 0)


def shifted(scene: Scene, dx: torch.Tensor, keep=None, _copies=None, axis: int = 0) -> Scene:
    """A copy of the scene whose every geometry point (in its shape's own space) is moved
    by dx along `axis` (0: x, 1: y), those of its clip paths and masks included.
    keep(i, shape) -> False drops shape i (for bisecting by shape)."""
    copies = {} if _copies is None else _copies  # id(clip or mask) -> its moved copy
    out = copy.copy(scene)
    zero = torch.zeros_like(dx)
    step = torch.stack([dx, zero] if axis == 0 else [zero, dx])
    shapes = []
    for i, s in enumerate(scene.shapes):
        if keep is not None and not keep(i, s):
            continue
        s = copy.copy(s)
        g = copy.copy(s.geometry)
        if isinstance(g, Path):
            g.points = g.points.detach() + step
        elif isinstance(g, Rect):
            g.p_min, g.p_max = g.p_min.detach() + step, g.p_max.detach() + step
        elif isinstance(g, (Circle, Ellipse)):
            g.center = g.center.detach() + step
        s.geometry = g
        s.clip, s.mask = _shifted_effect(s.clip, dx, copies, axis), _shifted_effect(s.mask, dx, copies, axis)
        shapes.append(s)
    out.shapes = shapes
    out.groups = [copy.copy(g) for g in scene.groups]
    for g in out.groups:
        g.clip, g.mask = _shifted_effect(g.clip, dx, copies, axis), _shifted_effect(g.mask, dx, copies, axis)
    return out


def _shifted_effect(effect, dx, copies, axis):
    if effect is None:
        return None
    if id(effect) not in copies:
        moved = copies[id(effect)] = copy.copy(effect)
        moved.content = shifted(effect.content, dx, None, copies, axis)
        if isinstance(effect, ClipPath):
            moved.clip = _shifted_effect(effect.clip, dx, copies, axis)
        else:
            moved.mask = _shifted_effect(effect.mask, dx, copies, axis)
    return copies[id(effect)]


def weighted(image: torch.Tensor, W: torch.Tensor) -> torch.Tensor:
    return (image.double() * W.double()).sum()  # (a float32 sum's rounding shows in small steps)


def fig9(scene: Scene, width: int, height: int, weights, step: float = 0.5, keep=None, axis: int = 0, **kw):
    """[(autograd, central difference)] of dL/d delta for each weighting W (one render
    and one backward pass per W for autograd, two renders for the differences); kw go to
    render (mode, samples, seed, ...); keep(i, shape) selects shapes; axis 1 moves the
    points down instead of right."""
    dx = torch.tensor(0.0, requires_grad=True)
    image = render(shifted(scene, dx, keep, axis=axis), width, height, **kw)
    ads = [torch.autograd.grad(weighted(image, W), dx, retain_graph=True)[0].item() for W in weights]
    with torch.no_grad():
        plus = render(shifted(scene, torch.tensor(step), keep, axis=axis), width, height, **kw)
        minus = render(shifted(scene, torch.tensor(-step), keep, axis=axis), width, height, **kw)
    return [(ad, float(weighted(plus, W) - weighted(minus, W)) / (2 * step)) for ad, W in zip(ads, weights)]


def mean_derivative(scene: Scene, width: int, height: int, weights, step: float = 0.5, points: int = 16, **kw):
    """Per weighting, the mean of the autograd derivative at `points` midpoints of
    [-step, step]: what the central difference over +-step equals when L is continuous
    (it is the mean of L' over the interval), to check autograd with a wide step where L
    curves within it."""
    total = [0.0] * len(weights)
    for k in range(points):
        dx = torch.tensor(-step + (k + 0.5) * 2 * step / points, requires_grad=True)
        image = render(shifted(scene, dx), width, height, **kw)
        for i, W in enumerate(weights):
            total[i] += torch.autograd.grad(weighted(image, W), dx, retain_graph=True)[0].item() / points
    return total
