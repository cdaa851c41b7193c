"""Learning rates in pixels: each length parameter's rate is scaled into its tensor's own
units (pixels per unit of its shape's space, and of its gradient's space), so that
`points = 2` moves a point about two pixels a step whatever the SVG's units."""
from __future__ import annotations

import math

import numpy as np
import torch

from vecfit.scene.arrays import to_numpy
from vecfit.scene.geometry import local_bbox_size
from vecfit.scene.placement import canvas_matrix, group_matrices, shape_matrices
from vecfit.scene import Circle, Ellipse, LinearGradient, Path, RadialGradient, Scene

from .adam import ParameterKind

# Kinds measured in lengths: their learning rates are given in pixels of the optimised
# image and converted into each tensor's own units.
LENGTH_KINDS = ("points", "stroke_widths", "radii", "gradient_points", "gradient_radii")


def shape_pixel_scales(scene: Scene, width: int, height: int) -> np.ndarray:
    """Pixels per unit of each shape's own space (sqrt |det| of its map to the canvas)."""
    with torch.no_grad():
        lin = shape_matrices(scene, width, height)[:, :2, :2]
        det = lin[:, 0, 0] * lin[:, 1, 1] - lin[:, 0, 1] * lin[:, 1, 0]
    return torch.sqrt(torch.abs(det)).numpy().astype(np.float64)


def learning_rate_scales(scene: Scene, width: int, height: int, out: dict | None = None) -> dict[int, float]:
    """Units of each length tensor per pixel of the rendered image, keyed by id(tensor);
    those of clip paths' and masks' shapes too, through the element that uses them."""
    pixels_per_unit = shape_pixel_scales(scene, width, height)
    out = {} if out is None else out

    def put(t, ppu):
        if t is not None and id(t) not in out and ppu > 0 and math.isfinite(ppu):
            out[id(t)] = 1.0 / ppu

    for shape, ppu in zip(scene.shapes, pixels_per_unit):
        g = shape.geometry
        for name in ("points", "widths", "center", "radius", "radii", "p_min", "p_max", "corner_radii"):
            put(getattr(g, name, None), ppu)
        put(shape.stroke_width, ppu)
        for paint in (shape.fill, shape.stroke):
            if isinstance(paint, (LinearGradient, RadialGradient)):
                gppu = ppu * math.sqrt(abs(float(torch.linalg.det(paint.transform.detach()[:2, :2].double()))))
                if paint.units == "objectBoundingBox":
                    gppu *= local_bbox_size(g) or 0.0
                for name in ("start", "end", "center", "focal", "radius"):
                    put(getattr(paint, name, None), gppu)
    _effect_scales(scene, width, height, out)
    return out


def _effect_scales(scene: Scene, width: int, height: int, out: dict) -> None:
    """The scales of what clip paths and masks draw: their content is placed by the
    element that uses it (a clip path used by several takes the first's)."""
    with torch.no_grad():
        canvas = canvas_matrix(scene, width, height)
        groups = group_matrices(scene, canvas)
        shapes = shape_matrices(scene, width, height)
        owners = [(g, groups[i]) for i, g in enumerate(scene.groups)]
        owners += [(s, shapes[i]) for i, s in enumerate(scene.shapes)]
        for owner, matrix in owners:
            for effect in (owner.clip, owner.mask):
                while effect is not None:
                    content = effect.content
                    placed = Scene(width=width, height=height, shapes=content.shapes, groups=content.groups,
                                   view=matrix @ content.view.float())
                    learning_rate_scales(placed, width, height, out)
                    effect = getattr(effect, "clip", None) or getattr(effect, "mask", None)


def parameter_kinds(scene: Scene, lr: dict, width: int, height: int, keep_alpha=()) -> list[ParameterKind]:
    """The kinds with a positive rate, each with its per-element scale of the rate: lengths
    in each tensor's own units, zero for what stays fixed (the last row of a transform,
    the alphas of the colour tensors in ``keep_alpha``)."""
    scales = learning_rate_scales(scene, width, height)
    kinds = []
    for name, tensors in scene.parameters().items():
        rate = float(lr.get(name, 0.0))
        if rate <= 0 or not tensors:
            continue
        per_tensor = []
        for t in tensors:
            if name in LENGTH_KINDS:
                per_tensor.append(scales.get(id(t), 1.0))
            else:
                per_tensor.append(1.0)
        kind = ParameterKind(name, tensors, per_tensor, rate)
        if name == "transforms":  # the last row of an affine matrix stays 0 0 1
            kind.scale.view(-1, 3, 3)[:, 2, :] = 0.0
        if name == "colors":  # colours are RGBA rows: keep the A of some
            kept = {id(t) for t in keep_alpha}
            offset = 0
            for t in tensors:
                if id(t) in kept:
                    kind.scale[offset:offset + t.numel()].view(-1, 4)[:, 3] = 0.0
                offset += t.numel()
        kinds.append(kind)
    return kinds


def outline_density(scene: Scene, width: int, height: int) -> float:
    """Control-polygon length of the scene's paths, in pixels of a width x height image,
    per pixel of it (closed subpaths include their closing edge). Illustrator's traces of
    kitty and peppers: 0.20; vecfit's 3,000-path traces of skimage's photos: 0.45-0.91.
    The Monte Carlo backward's boundary samples are counted by this length."""
    scales = shape_pixel_scales(scene, width, height)
    total = sum(scale * _outline_length(shape.geometry) for shape, scale in zip(scene.shapes, scales)
                if isinstance(shape.geometry, Path))
    return total / max(width * height, 1)


def boundary_length_density(scene: Scene, width: int, height: int) -> float:
    """What the Monte Carlo backward's boundary samples are counted by, per pixel of a
    width x height image: each path's control-polygon length (outline_density's), once for
    a fill and twice for a stroke (its two sides), and the perimeters of circles,
    ellipses and rectangles alike."""
    scales = shape_pixel_scales(scene, width, height)
    total = 0.0
    for shape, scale in zip(scene.shapes, scales):
        sides = (shape.fill is not None) + 2 * (shape.stroke is not None)
        if sides:
            total += sides * scale * _outline_length(shape.geometry)
    return total / max(width * height, 1)


def _outline_length(g) -> float:
    """The geometry's outline in its own units: a path's control polygons, a primitive's
    perimeter (an ellipse's by Ramanujan's approximation)."""
    if isinstance(g, Path):
        p = np.asarray(to_numpy(g.points), np.float64)
        total = 0.0
        for (first, count, closed), (p0, n) in zip(g.subpaths, g.subpath_point_ranges()):
            q = p[p0:p0 + n]
            if closed and n > 1:
                q = np.concatenate([q, q[:1]])
            total += float(np.sqrt(((q[1:] - q[:-1]) ** 2).sum(1)).sum())
        return total
    if isinstance(g, Circle):
        return 2 * math.pi * abs(float(to_numpy(g.radius)))
    if isinstance(g, Ellipse):
        a, b = (abs(float(r)) for r in to_numpy(g.radii))
        return math.pi * (3 * (a + b) - math.sqrt(max((3 * a + b) * (a + 3 * b), 0.0)))
    size = np.abs(np.asarray(to_numpy(g.p_max), np.float64) - np.asarray(to_numpy(g.p_min), np.float64))
    return 2 * float(size.sum())


def held_boundary_budget(budget: float, growth: float, boundary_samples: float, length_density: float) -> float:
    """The boundary budget (samples per image pixel, 0: none) of a fit whose boundary
    samples may grow to ``growth`` times what its first full-size iteration asks
    (``boundary_samples`` per pixel of ``length_density``, boundary_length_density's):
    the smaller of the two bounds. ``growth`` 0, or nothing drawn to count, holds nothing.

    A dense trace's outlines lengthen over a run (the fit, not noise: DESIGN.md "Flat
    iteration cost"), and the samples counted by their length with them; held to the
    start's number they are allotted where the error is (the budget's rule), so the last
    iterations cost about what the first did."""
    asked = growth * boundary_samples * length_density
    if not asked > 0:
        return budget
    return asked if budget <= 0 else min(budget, asked)


def dense_point_rate(rate: float, density: float, dense_outline: float, dense_points: float) -> float:
    """The point rate (pixels a step) for a scene of this outline_density: ``rate`` up to
    ``dense_outline``, falling linearly to ``dense_points`` at twice that, never above
    ``rate`` (dense_outline 0: always ``rate``).

    Where outlines are dense, neighbouring shapes' noisy steps push on the same pixels and
    control polygons grow (coffee's 3,000-path trace: 2.2x over a default run), and each
    iteration costs more. At 1.25 px, trace's own rate, the run took 79.8 s for +7.04 dB
    against 109.5 s for +6.73 dB at 2.0, and at 1.0 px (the default floor) 2-7% faster
    again for 0.00-0.06 dB; on Illustrator's sparse traces 2.0 still gains 0.3-0.4 dB
    more, so the rate follows the density (benchmarks/RESULTS.md, "Dense scenes")."""
    if dense_outline <= 0 or density <= dense_outline:
        return rate
    share = min((density - dense_outline) / dense_outline, 1.0)
    return min(rate, rate + share * (dense_points - rate))
