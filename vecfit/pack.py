"""Flatten a Scene into the core's arrays (structure of arrays, pixel space).

Geometry is mapped to pixel space here, with torch operations, so that gradients of
transforms, rect corners, circle radii and gradient geometry follow from autograd once
the core returns gradients of the flat float arrays. Integer tables (structure) are numpy.

Layout of every table: see csrc/scene.h.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import torch

from .errors import VecfitError
from .scene import (Circle, Ellipse, LinearGradient, Path, RadialGradient, Rect, Scene,
                    Shape, Solid)

SHAPE_PATH, SHAPE_ELLIPSE = 0, 1
DRAW_FILL, DRAW_STROKE = 0, 1
FILL_RULES = {"nonzero": 0, "evenodd": 1}
CAPS = {"butt": 0, "round": 1, "square": 2}
JOINS = {"miter": 0, "round": 1, "bevel": 2}
PAINT_SOLID, PAINT_LINEAR, PAINT_RADIAL = 0, 1, 2
KAPPA = 0.5522847498307936  # cubic approximation of a quarter ellipse


@dataclass
class Packed:
    """The core's input arrays. Float arrays are torch tensors (differentiable)."""
    points: list = field(default_factory=list)        # torch [n, 2] chunks
    segments: list = field(default_factory=list)      # rows of 5 ints
    subpaths: list = field(default_factory=list)      # rows of 3 ints
    shapes: list = field(default_factory=list)        # rows of 4 ints
    ellipses: list = field(default_factory=list)      # torch [6]
    draws: list = field(default_factory=list)         # rows of 7 ints
    draw_params: list = field(default_factory=list)   # torch [6]
    paints: list = field(default_factory=list)        # rows of 3 ints
    paint_params: list = field(default_factory=list)  # torch [11]
    stop_offsets: list = field(default_factory=list)  # torch [k]
    stop_colors: list = field(default_factory=list)   # torch [k, 4]
    layer_parents: list = field(default_factory=lambda: [-1])
    layer_opacity: list = field(default_factory=lambda: [torch.tensor(1.0)])
    n_points: int = 0
    n_stops: int = 0

    def arrays(self) -> dict:
        """Contiguous arrays for the core: float32 torch tensors and int32 numpy arrays."""
        def cat(chunks, width):
            if not chunks:
                return torch.zeros((0, width), dtype=torch.float32)
            return torch.cat([c.reshape(-1, width).to(torch.float32) for c in chunks])

        def ints(rows, width):
            return np.asarray(rows, dtype=np.int32).reshape(-1, width)

        return {
            "points": cat(self.points, 2),
            "segments": ints(self.segments, 5),
            "subpaths": ints(self.subpaths, 3),
            "shapes": ints(self.shapes, 4),
            "ellipses": cat(self.ellipses, 6),
            "draws": ints(self.draws, 7),
            "draw_params": cat(self.draw_params, 6),
            "paints": ints(self.paints, 3),
            "paint_params": cat(self.paint_params, 11),
            "stop_offsets": cat(self.stop_offsets, 1).reshape(-1),
            "stop_colors": cat(self.stop_colors, 4),
            "layer_parents": np.asarray(self.layer_parents, dtype=np.int32),
            "layer_opacity": torch.stack([torch.as_tensor(o, dtype=torch.float32).reshape(())
                                          for o in self.layer_opacity]),
        }


def _affine_apply(m: torch.Tensor, p: torch.Tensor) -> torch.Tensor:
    """Apply a 3x3 affine matrix to points [n, 2]."""
    return p @ m[:2, :2].T + m[:2, 2]


def _rect_path(rect: Rect) -> tuple[torch.Tensor, list[int]]:
    """A rect as a closed path: four lines, with quarter-ellipse cubics for round corners."""
    x0, y0 = rect.p_min[0], rect.p_min[1]
    x1, y1 = rect.p_max[0], rect.p_max[1]
    rx, ry = rect.corner_radii[0], rect.corner_radii[1]
    if float(rx) <= 0 or float(ry) <= 0:
        pts = torch.stack([torch.stack([x0, y0]), torch.stack([x1, y0]),
                           torch.stack([x1, y1]), torch.stack([x0, y1])])
        return pts, [1, 1, 1, 1]
    kx, ky = KAPPA * rx, KAPPA * ry
    P = lambda x, y: torch.stack([x, y])  # noqa: E731
    pts = [
        P(x0 + rx, y0), P(x1 - rx, y0),
        P(x1 - rx + kx, y0), P(x1, y0 + ry - ky), P(x1, y0 + ry),
        P(x1, y1 - ry),
        P(x1, y1 - ry + ky), P(x1 - rx + kx, y1), P(x1 - rx, y1),
        P(x0 + rx, y1),
        P(x0 + rx - kx, y1), P(x0, y1 - ry + ky), P(x0, y1 - ry),
        P(x0, y0 + ry),
        P(x0, y0 + ry - ky), P(x0 + rx - kx, y0),  # closing cubic ends at the start point
    ]
    return torch.stack(pts), [1, 3, 1, 3, 1, 3, 1, 3]


def _local_bbox(geometry) -> tuple[torch.Tensor, torch.Tensor] | None:
    """Tight bounds (min, max) of the geometry in its local space, for bounding-box units."""
    if isinstance(geometry, (Circle, Ellipse)):
        r = geometry.radius.expand(2) if isinstance(geometry, Circle) else geometry.radii
        return geometry.center - r, geometry.center + r
    if isinstance(geometry, Rect):
        return geometry.p_min, geometry.p_max
    samples = []
    t = torch.linspace(0, 1, 33, dtype=torch.float32)[:, None]
    for pts, degrees in _path_segments(geometry):
        for deg, ctrl in zip(degrees, pts):
            if deg == 1:
                samples.append(ctrl)
            elif deg == 2:
                u = 1 - t
                samples.append(u * u * ctrl[0] + 2 * u * t * ctrl[1] + t * t * ctrl[2])
            else:
                u = 1 - t
                samples.append(u ** 3 * ctrl[0] + 3 * u * u * t * ctrl[1] + 3 * u * t * t * ctrl[2]
                               + t ** 3 * ctrl[3])
    if not samples:
        return None
    allp = torch.cat(samples)
    return allp.min(dim=0).values, allp.max(dim=0).values


def _path_segments(path: Path):
    """Per subpath: (list of control-point tensors per segment, degrees)."""
    for (first, count, closed), (p0, n) in zip(path.subpaths, path.subpath_point_ranges()):
        pts = path.points[p0:p0 + n]
        degrees = [int(d) for d in path.degrees[first:first + count]]
        ctrl, k = [], 0
        for d in degrees:
            idx = [(k + i) % n if closed else k + i for i in range(d + 1)]
            ctrl.append(pts[idx])
            k += d
        yield ctrl, degrees


def _is_similarity(a: torch.Tensor) -> bool:
    """True for uniform scale (with reflection) without rotation: strokes need no metric."""
    a = a.detach()
    s = max(abs(float(a[0, 0])), abs(float(a[1, 1])), 1e-30)
    return (abs(float(a[0, 1])) <= 1e-9 * s and abs(float(a[1, 0])) <= 1e-9 * s
            and abs(abs(float(a[0, 0])) - abs(float(a[1, 1]))) <= 1e-6 * s)


class Packer:
    def __init__(self, scene: Scene, width: int, height: int):
        self.scene = scene
        self.out = Packed()
        sx, sy = width / scene.width, height / scene.height
        self.canvas = torch.diag(torch.tensor([sx, sy, 1.0], dtype=torch.float32)) @ scene.view.float()
        self.group_matrix: list[torch.Tensor] = []
        self.group_layer: list[int] = []
        self._group_draw_counts = self._count_group_draws()

    # --------------------------------------------------------------- structure

    def _draws_of(self, shape: Shape) -> int:
        n = 1 if shape.fill is not None else 0
        if shape.stroke is not None and float(shape.stroke_width) > 0:
            n += 1
        return n

    def _count_group_draws(self) -> list[int]:
        counts = [0] * len(self.scene.groups)
        for shape in self.scene.shapes:
            g = shape.group
            while g >= 0:
                counts[g] += self._draws_of(shape)
                g = self.scene.groups[g].parent
        return counts

    def _new_layer(self, parent: int, opacity) -> int:
        self.out.layer_parents.append(parent)
        self.out.layer_opacity.append(opacity)
        return len(self.out.layer_parents) - 1

    def _prepare_groups(self) -> None:
        """Matrices to pixels and layers: a group with opacity < 1 over several draws is a
        layer; over one draw its opacity folds into that draw's alpha."""
        for i, group in enumerate(self.scene.groups):
            if group.parent >= i:
                raise VecfitError("scene groups must come after their parents")
            parent_m = self.canvas if group.parent < 0 else self.group_matrix[group.parent]
            parent_layer = 0 if group.parent < 0 else self.group_layer[group.parent]
            self.group_matrix.append(parent_m @ group.transform.float())
            if float(group.opacity) < 1 and self._group_draw_counts[i] > 1:
                self.group_layer.append(self._new_layer(parent_layer, group.opacity))
            else:
                self.group_layer.append(parent_layer)

    def _folded_opacity(self, shape: Shape) -> torch.Tensor:
        """Product of the opacities of groups that are not layers (one draw below them)."""
        k = torch.tensor(1.0)
        g = shape.group
        while g >= 0:
            group = self.scene.groups[g]
            if float(group.opacity) < 1 and self._group_draw_counts[g] <= 1:
                k = k * group.opacity
            g = group.parent
        return k

    # ---------------------------------------------------------------- geometry

    def _add_geometry(self, geometry, m: torch.Tensor) -> int | None:
        """Adds the shape's geometry in pixel space; returns its shape index."""
        out = self.out
        if isinstance(geometry, (Circle, Ellipse)):
            r = geometry.radius.reshape(1).expand(2) if isinstance(geometry, Circle) else geometry.radii
            if float(r.min()) <= 0:
                return None
            c = _affine_apply(m, geometry.center.reshape(1, 2).float())[0]
            axes = m[:2, :2] @ torch.diag(r.float())
            out.ellipses.append(torch.cat([c, axes.reshape(4)]))
            out.shapes.append([SHAPE_ELLIPSE, 0, 0, len(out.ellipses) - 1])
            return len(out.shapes) - 1
        if isinstance(geometry, Rect):
            if float(geometry.p_max[0] - geometry.p_min[0]) <= 0 or float(geometry.p_max[1] - geometry.p_min[1]) <= 0:
                return None
            pts, degrees = _rect_path(geometry)
            geometry = Path(points=pts, degrees=np.array(degrees), subpaths=[(0, len(degrees), True)])
        if not isinstance(geometry, Path):
            raise VecfitError(f"unknown geometry {type(geometry).__name__}")
        first_subpath = len(out.subpaths)
        base = out.n_points
        out.points.append(_affine_apply(m, geometry.points.float()))
        out.n_points += len(geometry.points)
        for (first, count, closed), (p0, n) in zip(geometry.subpaths, geometry.subpath_point_ranges()):
            seg0 = len(out.segments)
            k = 0
            for d in geometry.degrees[first:first + count]:
                d = int(d)
                idx = [base + p0 + ((k + i) % n if closed else k + i) for i in range(d + 1)]
                out.segments.append([d] + idx + [-1] * (4 - len(idx)))
                k += d
            out.subpaths.append([seg0, count, int(bool(closed))])
        out.shapes.append([SHAPE_PATH, first_subpath, len(out.subpaths) - first_subpath, -1])
        return len(out.shapes) - 1

    # ------------------------------------------------------------------ paints

    def _add_paint(self, paint, alpha: torch.Tensor, m: torch.Tensor, geometry) -> int | None:
        out = self.out
        if isinstance(paint, Solid):
            color = paint.color.float()
            color = torch.cat([color[:3], color[3:4] * alpha])
            out.paints.append([PAINT_SOLID, 0, 0])
            out.paint_params.append(torch.cat([torch.eye(2, 3).reshape(6), color, torch.zeros(1)]))
            return len(out.paints) - 1
        g = m
        if paint.units == "objectBoundingBox":
            box = _local_bbox(geometry)
            if box is None:
                return None
            lo, hi = box
            size = hi - lo
            if float(size.min()) <= 0:
                return None  # SVG: a zero-size bounding box disables the gradient
            bbox = torch.zeros(3, 3)
            bbox[0, 0], bbox[1, 1], bbox[0, 2], bbox[1, 2], bbox[2, 2] = size[0], size[1], lo[0], lo[1], 1
            g = g @ bbox
        g = g @ paint.transform.float()
        if abs(float(torch.linalg.det(g[:2, :2]))) < 1e-30:
            return None
        to_paint = torch.linalg.inv(g)[:2].reshape(6)
        if isinstance(paint, LinearGradient):
            params = torch.cat([to_paint, paint.start.float(), paint.end.float(), torch.zeros(1)])
            kind = PAINT_LINEAR
        elif isinstance(paint, RadialGradient):
            c, f, r = paint.center.float(), paint.focal.float(), paint.radius.float().reshape(1)
            # SVG 1.1: a focal point outside the circle is moved onto it; keep it just
            # inside so that the cone stays well defined.
            d = f - c
            dist = torch.linalg.norm(d)
            limit = r[0] * 0.999
            if float(dist) > float(limit):
                f = c + d * (limit / dist)
            params = torch.cat([to_paint, c, r, f])
            kind = PAINT_RADIAL
        else:
            raise VecfitError(f"unknown paint {type(paint).__name__}")
        colors = paint.colors.float()
        colors = torch.cat([colors[:, :3], colors[:, 3:4] * alpha], dim=1)
        out.paints.append([kind, out.n_stops, len(paint.offsets)])
        out.paint_params.append(params)
        out.stop_offsets.append(paint.offsets.float())
        out.stop_colors.append(colors)
        out.n_stops += len(paint.offsets)
        return len(out.paints) - 1

    # ------------------------------------------------------------------- draws

    def pack(self) -> Packed:
        self._prepare_groups()
        out = self.out
        for shape in self.scene.shapes:
            parent_m = self.canvas if shape.group < 0 else self.group_matrix[shape.group]
            layer = 0 if shape.group < 0 else self.group_layer[shape.group]
            m = parent_m @ shape.transform.float()
            n_draws = self._draws_of(shape)
            if n_draws == 0:
                continue
            alpha = self._folded_opacity(shape)
            if float(shape.opacity) < 1 and n_draws > 1:
                layer = self._new_layer(layer, shape.opacity)
            else:
                alpha = alpha * shape.opacity
            index = self._add_geometry(shape.geometry, m)
            if index is None:
                continue
            if shape.fill is not None:
                paint = self._add_paint(shape.fill, alpha * shape.fill_opacity, m, shape.geometry)
                if paint is not None:
                    out.draws.append([index, DRAW_FILL, FILL_RULES[shape.fill_rule], paint, layer, 0, 0])
                    out.draw_params.append(torch.tensor([0, 4, 1, 0, 0, 1], dtype=torch.float32))
            if shape.stroke is not None and float(shape.stroke_width) > 0:
                paint = self._add_paint(shape.stroke, alpha * shape.stroke_opacity, m, shape.geometry)
                if paint is not None:
                    a = m[:2, :2]
                    scale = torch.sqrt(torch.abs(torch.linalg.det(a)))
                    if float(scale) <= 0:
                        continue
                    if _is_similarity(a):
                        metric = torch.eye(2).reshape(4)
                    else:  # stroke space: the shape's local space, uniformly scaled
                        metric = (scale * torch.linalg.inv(a)).reshape(4)
                    width = shape.stroke_width.float().reshape(1) * scale
                    limit = torch.tensor([float(shape.miter_limit)])
                    out.draws.append([index, DRAW_STROKE, 0, paint, layer,
                                      CAPS[shape.linecap], JOINS[shape.linejoin]])
                    out.draw_params.append(torch.cat([width, limit, metric]))
        return out


def pack_scene(scene: Scene, width: int, height: int) -> Packed:
    return Packer(scene, width, height).pack()
