"""diffvg's serialized scene (RenderFunction.serialize_scene's flat list) -> a vecfit Scene.

Every float goes through torch operations only, so vecfit.render's gradients flow back to
the caller's tensors. How diffvg's model maps onto vecfit's:

- a ShapeGroup of one shape becomes that shape; of several, one compound path (circles,
  ellipses and rects as paths) so that the fill rule counts winding across the shapes, as
  diffvg does; a per-shape stroke width then becomes a per-point width;
- the group's stroke is drawn first, as its own Shape, and its fill over it (diffvg's
  order; SVG's is the other way round);
- a stroke is every point within ``stroke_width`` of the outline (diffvg's widths are half
  widths): round caps and joins, width doubled;
- gradients are in canvas coordinates: their transform is the inverse of
  ``shape_to_canvas``; a radial gradient's two radii become a scale of the unit circle.
"""
from __future__ import annotations

import math

import numpy as np
import torch

from vecfit.errors import VecfitError
from vecfit import scene as vs

from .enums import ColorType, ShapeType

KAPPA = 4 * (math.sqrt(2) - 1) / 3  # cubic control distance of a quarter circle

_ROUND = dict(linecap="round", linejoin="round")


def _constants() -> dict:
    """The Shape fields diffvg has no say in, made once per scene (new tensors per Shape
    would cost more than the rest of the conversion on scenes of thousands of shapes);
    they are read, never optimised, so shapes may share them."""
    one = torch.tensor(1.0)  # a fill's stroke width too (not used)
    return dict(opacity=one, fill_opacity=one, stroke_opacity=one, stroke_width=one)


class Parsed:
    """The flat list read back: canvas size, options, the scene and the filter."""

    def __init__(self, args):
        it = iter(args)
        self.canvas_width, self.canvas_height = next(it), next(it)
        num_shapes, num_groups = next(it), next(it)
        self.output_type, self.use_prefiltering, self.eval_positions = next(it), next(it), next(it)
        self.shapes = [_read_shape(it) for _ in range(num_shapes)]
        self.groups = [_read_group(it) for _ in range(num_groups)]
        self.filter_type, self.filter_radius = next(it), next(it)


def _read_shape(it):
    kind = next(it)
    if kind in (ShapeType.circle, ShapeType.ellipse):
        radius, center = next(it), next(it)
        data = (radius, center)
    elif kind == ShapeType.path:
        data = (next(it), next(it), next(it), next(it), next(it))  # ncp, points, widths, closed, approx
    elif kind == ShapeType.rect:
        data = (next(it), next(it))
    else:
        raise VecfitError(f"unknown shape type {kind!r}")
    return kind, data, next(it)  # the last: the (half) stroke width


def _read_paint(it):
    kind = next(it)
    if kind is None:
        return None
    if kind == ColorType.constant:
        return kind, (next(it),)
    if kind in (ColorType.linear_gradient, ColorType.radial_gradient):
        return kind, (next(it), next(it), next(it), next(it))
    raise VecfitError(f"unknown colour type {kind!r}")


def _read_group(it):
    ids = next(it)
    fill = _read_paint(it)
    stroke = _read_paint(it)
    even_odd, m = next(it), next(it)
    return ids, fill, stroke, even_odd, m


def _f(t) -> torch.Tensor:
    """A float32 CPU tensor, in the caller's autograd graph."""
    if not isinstance(t, torch.Tensor):
        return torch.as_tensor(t, dtype=torch.float32)
    if not t.is_cpu:
        t = t.cpu()
    return t if t.dtype is torch.float32 else t.float()


def _matrix(m) -> torch.Tensor:
    m = _f(m)
    if m.shape == (2, 3):
        m = torch.cat([m, torch.tensor([[0.0, 0.0, 1.0]])])
    if m.shape != (3, 3):
        raise VecfitError(f"shape_to_canvas must be 3x3 or 2x3, not {tuple(m.shape)}")
    return m


_PATH, _CIRCLE, _ELLIPSE, _RECT = (int(k) for k in (ShapeType.path, ShapeType.circle, ShapeType.ellipse,
                                                    ShapeType.rect))  # enum attribute look-ups are slow
_CONSTANT = int(ColorType.constant)


def _geometry(kind, data, zero_radii):
    """A shape's vecfit geometry (rects share ``zero_radii``, their corner radii)."""
    if kind != _PATH:
        if kind == _CIRCLE:
            return vs.Circle(center=_f(data[1]), radius=_f(data[0]).reshape(()))
        if kind == _ELLIPSE:
            return vs.Ellipse(center=_f(data[1]), radii=_f(data[0]))
        return vs.Rect(p_min=_f(data[0]), p_max=_f(data[1]), corner_radii=zero_radii)
    ncp, points, _, closed, _ = data
    # tolist: converting a small tensor through numpy costs ~100 us, tolist ~2 us
    degrees = np.array(ncp.tolist() if isinstance(ncp, torch.Tensor) else ncp, dtype=np.int64) + 1
    return vs.Path(points=_f(points), degrees=degrees, subpaths=[(0, len(degrees), bool(closed))])


def _as_path(g) -> vs.Path:
    """Circles, ellipses and rects as closed paths (for groups of several shapes)."""
    if isinstance(g, vs.Path):
        return g
    if isinstance(g, vs.Rect):
        x0, y0, x1, y1 = g.p_min[0], g.p_min[1], g.p_max[0], g.p_max[1]
        pts = torch.stack([torch.stack([x0, y0]), torch.stack([x1, y0]), torch.stack([x1, y1]),
                           torch.stack([x0, y1])])
        return vs.Path(points=pts, degrees=np.ones(4, dtype=np.int64), subpaths=[(0, 4, True)])
    r = g.radius.expand(2) if isinstance(g, vs.Circle) else g.radii
    unit = torch.tensor([[1, 0], [1, KAPPA], [KAPPA, 1], [0, 1], [-KAPPA, 1], [-1, KAPPA], [-1, 0],
                         [-1, -KAPPA], [-KAPPA, -1], [0, -1], [KAPPA, -1], [1, -KAPPA]], dtype=torch.float32)
    return vs.Path(points=g.center + unit * r, degrees=np.full(4, 3, dtype=np.int64), subpaths=[(0, 4, True)])


def _path_widths(kind, data, half_width, geometry) -> torch.Tensor:
    """Full stroke width per stored point of the shape as a path."""
    n = geometry.points.shape[0]
    if kind == ShapeType.path and data[2] is not None:
        return 2 * _f(data[2])
    return (2 * _f(half_width)).reshape(()).expand(n)


def _paint(paint, inverse):
    if paint is None:
        return None
    kind, data = paint
    if kind == ColorType.constant:
        return vs.Solid(color=_f(data[0]))
    if kind == ColorType.linear_gradient:
        begin, end, offsets, colors = (_f(t) for t in data)
        return vs.LinearGradient(start=begin, end=end, offsets=offsets, colors=colors,
                                 transform=inverse(), units="userSpaceOnUse")
    center, radius, offsets, colors = (_f(t) for t in data)
    zero, one = torch.zeros(()), torch.ones(())
    ellipse = torch.stack([torch.stack([radius[0], zero, center[0]]), torch.stack([zero, radius[1], center[1]]),
                           torch.tensor([0.0, 0.0, 1.0])])
    return vs.RadialGradient(center=torch.zeros(2), radius=one, focal=torch.zeros(2), offsets=offsets,
                             colors=colors, transform=inverse() @ ellipse, units="userSpaceOnUse")


# Shapes made on earlier calls for groups of one shape with a solid fill and nothing
# derived from the caller's tensors (no stroke, float32 CPU tensors, a 3x3 matrix): the
# Shape then holds the caller's own tensors, so it stays valid while those same tensor
# objects are passed (their values may change in place; an integer tensor's version is
# checked). Code written for diffvg passes the same tensors every iteration; reusing
# these Shapes keeps the adapter's cost on scenes of thousands of shapes within 15%
# of vecfit.render's (benchmarks/pydiffvg.py). Keyed by id(shape_ids); the entry holds
# the objects themselves, so an id cannot be reused by another object while cached.
_reuse: dict[int, tuple] = {}


def _reusable(ids, fill, stroke, m, shape_entry) -> bool:
    if stroke is not None or fill is None or fill[0] != _CONSTANT or not isinstance(ids, torch.Tensor):
        return False
    kind, data, _ = shape_entry
    floats = [fill[1][0], m] + ([data[1]] if kind == _PATH else list(data))
    return all(isinstance(t, torch.Tensor) and t.is_cpu and t.dtype is torch.float32 for t in floats) \
        and m.shape == (3, 3)


def _cached(ids, fill, even_odd, m, shapes):
    entry = _reuse.get(id(ids))
    if entry is None:
        return None
    ids_obj, ids_version, index, fill_obj, m_obj, odd, data, ncp_version, shape = entry
    if ids_obj is not ids or ids._version != ids_version or fill_obj is not fill[1][0] or m_obj is not m \
            or odd != even_odd:
        return None
    kind, now, _ = shapes[index]
    if len(now) != len(data) or any(a is not b for a, b in zip(now, data)):
        return None
    if kind == _PATH and now[0]._version != ncp_version:
        return None
    return shape


def _remember(ids, fill, even_odd, m, index, shapes, shape) -> None:
    kind, data, _ = shapes[index]
    ncp_version = data[0]._version if kind == _PATH and isinstance(data[0], torch.Tensor) else None
    if kind == _PATH and ncp_version is None:
        return
    _reuse[id(ids)] = (ids, ids._version, index, fill[1][0], m, even_odd, data, ncp_version, shape)


def to_scene(p: Parsed) -> vs.Scene:
    scene = vs.Scene(width=float(p.canvas_width), height=float(p.canvas_height))
    cache = {}
    fixed = _constants()
    zero_radii = torch.zeros(2)
    if len(_reuse) > 4 * len(p.groups) + 256:
        _reuse.clear()
    for ids, fill, stroke, even_odd, m in p.groups:
        if fill is None and stroke is None:
            continue
        if stroke is None:
            shape = _cached(ids, fill, even_odd, m, p.shapes)
            if shape is not None:
                scene.shapes.append(shape)
                continue
        ids_obj, m_obj = ids, m
        m = _matrix(m)
        inv = []

        def inverse():
            if not inv:
                inv.append(torch.linalg.inv(m))
            return inv[0]

        ids = ids.reshape(-1).tolist() if isinstance(ids, torch.Tensor) else [int(i) for i in ids]
        if not ids or min(ids) < 0 or max(ids) >= len(p.shapes):
            raise VecfitError(f"shape ids {ids} are out of range (there are {len(p.shapes)} shapes)")
        widths = width = None
        if len(ids) == 1:
            kind, data, half = p.shapes[ids[0]]
            geometry = cache.get(ids[0])
            if geometry is None:
                geometry = cache[ids[0]] = _geometry(kind, data, zero_radii)
            if stroke is not None:
                if kind == _PATH and data[2] is not None:
                    widths = 2 * _f(data[2])
                width = 2 * _f(half).reshape(())
        else:
            parts = [(_as_path(_geometry(k, d, zero_radii)), k, d, h) for k, d, h in (p.shapes[i] for i in ids)]
            points, degrees, subpaths, per_point, segments = [], [], [], [], 0
            for g, k, d, h in parts:
                subpaths.append((segments, len(g.degrees), g.subpaths[0][2]))
                segments += len(g.degrees)
                points.append(g.points)
                degrees.append(g.degrees)
                if stroke is not None:
                    per_point.append(_path_widths(k, d, h, g))
            geometry = vs.Path(points=torch.cat(points), degrees=np.concatenate(degrees), subpaths=subpaths)
            if stroke is not None:
                widths = torch.cat(per_point)
                width = 2 * _f(parts[0][3]).reshape(())
        if stroke is not None:
            g = geometry
            if widths is not None:  # per-point widths live on the path: a copy for the stroke
                g = vs.Path(points=geometry.points, degrees=geometry.degrees, subpaths=geometry.subpaths,
                            widths=widths)
            scene.shapes.append(vs.Shape(geometry=g, stroke=_paint(stroke, inverse), transform=m, **_ROUND,
                                         **{**fixed, "stroke_width": width}))
        if fill is not None:
            shape = vs.Shape(geometry=geometry, fill=_paint(fill, inverse),
                             fill_rule="evenodd" if even_odd else "nonzero", transform=m, **fixed)
            scene.shapes.append(shape)
            if len(ids) == 1 and _reusable(ids_obj, fill, stroke, m_obj, p.shapes[ids[0]]):
                _remember(ids_obj, fill, even_odd, m_obj, ids[0], p.shapes, shape)
    return scene
