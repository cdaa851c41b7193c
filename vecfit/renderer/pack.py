"""Flatten a Scene into the core's arrays (structure of arrays, pixel space).

Geometry is mapped to pixel space here, with torch operations, so that gradients of
transforms, rect corners, circle radii and gradient geometry follow from autograd once
the core returns gradients of the flat float arrays. Integer tables (structure) are numpy.
A Scene of NumPy arrays (vecfit.scene.arrays.numpy_arrays) packs into NumPy float
arrays by the same code, without torch: the operations come from vecfit.scene.ops.

The layout of every table (enums, row widths) is the core's own (layout.py, from
csrc/scene/scene.h).

Packed.placement says where each scene value landed in the arrays (plain records, kept on
every pack); vecfit.renderer.routes reads them, for the fitting loop's persistent pack.
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from vecfit import limits as _limits
from vecfit.errors import VecfitError, VecfitWarning
from vecfit.scene import Circle, Ellipse, LinearGradient, Path, RadialGradient, Rect, Scene, Shape, Solid
from vecfit.scene.dashes import DashBudget, dash_path, dash_pattern, outline_path
from vecfit.scene.geometry import affine_apply, local_bbox, rect_as_path, value
from vecfit.scene.arrays import as_torch, is_tensor, to_numpy
from vecfit.scene.ops import ops_for
from vecfit.scene.placement import canvas_matrix, group_matrices, stacked_shape_matrices

from .layout import (CAPS, COLUMNS, DRAW_FILL, DRAW_STROKE, FILL_RULES, JOINS, PAINT_LINEAR,
                     PAINT_RADIAL, PAINT_SOLID, SHAPE_ELLIPSE, SHAPE_PATH)


@dataclass
class Packed:
    """The core's input arrays. Float arrays are torch tensors (differentiable), or NumPy
    arrays for a Scene of NumPy arrays."""
    points: list = field(default_factory=list)        # torch [n, 2] chunks
    point_widths: list = field(default_factory=list)  # torch [n] chunks (empty: no draw has them)
    segments: list = field(default_factory=list)      # int arrays [k, 5]
    subpaths: list = field(default_factory=list)      # rows of 3 ints
    shapes: list = field(default_factory=list)        # rows of 4 ints
    ellipses: list = field(default_factory=list)      # torch [6]
    draws: list = field(default_factory=list)         # rows of 8 ints
    draw_params: list = field(default_factory=list)   # torch [6]
    paints: list = field(default_factory=list)       # rows of 3 ints
    paint_params: list = field(default_factory=list)  # torch [11]
    stop_offsets: list = field(default_factory=list)  # torch [k]
    stop_colors: list = field(default_factory=list)   # torch [k, 4]
    layer_parents: list = field(default_factory=lambda: [-1])
    layer_opacity: list = field(default_factory=lambda: [1.0])
    n_points: int = 0
    n_stops: int = 0
    ops: object = None  # vecfit.scene.ops: the float arrays' kind
    placement: "Placement" = None  # where the scene's values landed (for routes.py)

    def arrays(self) -> dict:
        """Contiguous arrays for the core: float32 torch tensors (or NumPy arrays) and
        int32 numpy arrays."""
        ops = self.ops

        def cat(chunks, width):
            if not chunks:
                return ops.zeros((0, width))
            return ops.cat([ops.f32(c.reshape(-1, width)) for c in chunks])

        def ints(rows, width):
            return np.asarray(rows, dtype=np.int32).reshape(-1, width)

        return {
            "points": cat(self.points, COLUMNS["points"]),
            "point_widths": cat(self.point_widths, COLUMNS["point_widths"]).reshape(-1),
            "segments": (np.concatenate(self.segments).astype(np.int32) if self.segments
                         else np.zeros((0, COLUMNS["segments"]), dtype=np.int32)),
            "subpaths": ints(self.subpaths, COLUMNS["subpaths"]),
            "shapes": ints(self.shapes, COLUMNS["shapes"]),
            "ellipses": cat(self.ellipses, COLUMNS["ellipses"]),
            "draws": ints(self.draws, COLUMNS["draws"]),
            "draw_params": cat(self.draw_params, COLUMNS["draw_params"]),
            "paints": ints(self.paints, COLUMNS["paints"]),
            "paint_params": cat(self.paint_params, COLUMNS["paint_params"]),
            "stop_offsets": cat(self.stop_offsets, COLUMNS["stop_offsets"]).reshape(-1),
            "stop_colors": cat(self.stop_colors, COLUMNS["stop_colors"]),
            "layer_parents": np.asarray(self.layer_parents, dtype=np.int32),
            "layer_opacity": ops.stack([ops.f32(o).reshape(()) for o in self.layer_opacity]),
        }


@dataclass
class Placement:
    """Where the scene's values landed in the packed arrays (what vecfit.renderer.routes
    reads; the rows are those of Packed.arrays)."""
    matrices: object = None     # every shape's matrix to pixels [n, 3, 3]
    scale: object = None        # every shape's uniform scale [n]
    shapes: list = field(default_factory=list)     # (shape index, stroke drawn) of each shape packed
    paths: list = field(default_factory=list)      # (first point row, local points, shape index, Rect or None, widths or None)
    ellipses: list = field(default_factory=list)   # (ellipses row, shape index, Circle or Ellipse)
    solids: list = field(default_factory=list)     # the solid colours, in paint_params rows 0...
    solid_alphas: object = None                    # their alphas (fixed opacities multiplied out)
    gradients: list = field(default_factory=list)  # (paint, paint_params row, first stop, alpha)
    bbox_geometry: list = field(default_factory=list)  # the geometry bounding-box gradients depend on
    dashed: list = field(default_factory=list)     # shapes whose stroke is drawn from its dashes
    strokes: list = field(default_factory=list)    # (draw_params row, shape index)


class Packer:
    """``keep_empty``: an ellipse whose radius is 0 or less keeps its draw, with axes 0 (the
    core draws nothing there), so that the structure does not change as a radius crosses
    0 (the persistent pack, vecfit.renderer.persistent)."""

    def __init__(self, scene: Scene, width: int, height: int, keep_empty: bool = False):
        self.scene = scene
        self.keep_empty = keep_empty
        self.ops = ops_for(scene.view)
        self.placed = Placement()
        self.out = Packed(ops=self.ops, placement=self.placed)
        self.canvas = canvas_matrix(scene, width, height)
        self.group_matrix: list = []
        self.group_layer: list[int] = []
        self._group_draw_counts = self._count_group_draws()
        self._dashes = DashBudget()  # the scene's dashes (limits.MAX_DASHES)
        self._n_solid = 0
        self._n_gradients = 0
        self._keep_draws: list[bool] | None = None  # per draw: False where its gradient paints nothing

    # --------------------------------------------------------------- structure

    def _draws_of(self, shape: Shape) -> int:
        n = 1 if shape.fill is not None else 0
        if shape.stroke is not None and _stroke_width_positive(shape):
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
        self.group_matrix = group_matrices(self.scene, self.canvas)
        for i, group in enumerate(self.scene.groups):
            parent_layer = 0 if group.parent < 0 else self.group_layer[group.parent]
            if value(group.opacity) < 1 and self._group_draw_counts[i] > 1:
                self.group_layer.append(self._new_layer(parent_layer, group.opacity))
            else:
                self.group_layer.append(parent_layer)

    def _folded_opacities(self, shape: Shape) -> list:
        """Opacities of the groups above the shape that are not layers (one draw below)."""
        out = []
        g = shape.group
        while g >= 0:
            group = self.scene.groups[g]
            if value(group.opacity) < 1 and self._group_draw_counts[g] <= 1:
                out.append(group.opacity)
            g = group.parent
        return out

    def _add_gradient(self, paint, alpha, m, geometry) -> int | None:
        """Adds a gradient paint; returns its index among the gradients, or None when
        it paints nothing."""
        out, ops = self.out, self.ops
        g = m
        if paint.units == "objectBoundingBox":
            self.placed.bbox_geometry.append(geometry)
            box = local_bbox(geometry)
            if box is None:
                return None
            lo, hi = box
            size = hi - lo
            if value(size.min()) <= 0:
                return None  # SVG: a zero-size bounding box disables the gradient
            bbox = ops.zeros((3, 3))
            bbox[0, 0], bbox[1, 1], bbox[0, 2], bbox[1, 2], bbox[2, 2] = size[0], size[1], lo[0], lo[1], 1
            g = g @ bbox
        g = g @ ops.f32(paint.transform)
        if abs(value(ops.det(g[:2, :2]))) < 1e-30:
            return None
        to_paint = ops.inv(g)[:2].reshape(6)
        # its row: after the solids and the gradients before it (see _finish_paints)
        row = self._n_solid + self._n_gradients
        if isinstance(paint, LinearGradient):
            params = ops.cat([to_paint, ops.f32(paint.start), ops.f32(paint.end), ops.zeros(1)])
            kind = PAINT_LINEAR
        elif isinstance(paint, RadialGradient):
            # SVG 2 semantics, as resvg and browsers draw it: a focal point outside the
            # circle makes a cone, and the area outside the cone is not painted.
            c, f, r = ops.f32(paint.center), ops.f32(paint.focal), ops.f32(paint.radius).reshape(1)
            params = ops.cat([to_paint, c, r, f])
            kind = PAINT_RADIAL
        else:
            raise VecfitError(f"unknown paint {type(paint).__name__}")
        colors = ops.f32(paint.colors)
        colors = ops.cat([colors[:, :3], colors[:, 3:4] * alpha], dim=1)
        self.placed.gradients.append((paint, row, out.n_stops, alpha))
        out.paints.append([kind, out.n_stops, len(paint.offsets)])
        out.paint_params.append(params)
        out.stop_offsets.append(ops.f32(paint.offsets))
        out.stop_colors.append(colors)
        out.n_stops += len(paint.offsets)
        self._n_gradients += 1
        return self._n_gradients - 1

    # ------------------------------------------------------------------- draws

    def pack(self) -> Packed:
        self._prepare_groups()
        out, ops = self.out, self.ops
        shapes = self.scene.shapes
        matrices = stacked_shape_matrices(self.scene, self.canvas, self.group_matrix)
        self.placed.matrices = matrices
        # Similarity (no metric needed for strokes) and uniform scale of every shape.
        lin = matrices[:, :2, :2]
        scale = ops.sqrt(ops.abs(lin[:, 0, 0] * lin[:, 1, 1] - lin[:, 0, 1] * lin[:, 1, 0]))
        self.placed.scale = scale
        lin_np = ops.numpy(lin)
        big = np.maximum(np.maximum(np.abs(lin_np[:, 0, 0]), np.abs(lin_np[:, 1, 1])), 1e-30)
        similar = ((np.abs(lin_np[:, 0, 1]) <= 1e-9 * big) & (np.abs(lin_np[:, 1, 0]) <= 1e-9 * big)
                   & (np.abs(np.abs(lin_np[:, 0, 0]) - np.abs(lin_np[:, 1, 1])) <= 1e-6 * big))

        scale_np = ops.numpy(scale)
        paths = _PathBatch()
        solid_colors, solid_alphas = [], []   # per solid paint: colour [4], alpha factors
        gradient_rows = []                    # (paint, alpha, matrix, geometry)
        stroke_rows = []                      # (draw index, shape index)

        def paint_index(paint, factors, shape_index, geometry):
            if isinstance(paint, Solid):
                solid_colors.append(paint.color)
                solid_alphas.append(factors)
                return len(solid_colors) - 1
            alpha = ops.f32(1.0)
            for f in factors:
                alpha = alpha * f
            gradient_rows.append((paint, alpha, matrices[shape_index], geometry))
            return -len(gradient_rows)  # fixed up once the solids are counted

        for i, shape in enumerate(shapes):
            has_fill = shape.fill is not None
            has_stroke = (shape.stroke is not None and _stroke_width_positive(shape)
                          and scale_np[i] > 0)
            # A dashed stroke is drawn from its dashes, a path of its own (None: solid).
            dashes = dashed_stroke(shape, self._dashes) if has_stroke else None
            if dashes is not None and not dashes.subpaths:
                has_stroke = False  # no dash at all (a zero-length path)
            if not (has_fill or has_stroke):
                continue
            layer = 0 if shape.group < 0 else self.group_layer[shape.group]
            # Alpha factors of this shape's paints (multiplied out in one go later).
            factors = self._folded_opacities(shape) if shape.group >= 0 else []
            if has_fill and has_stroke and value(shape.opacity) < 1:
                layer = self._new_layer(layer, shape.opacity)
            else:
                factors.append(shape.opacity)
            geometry = shape.geometry
            self.placed.shapes.append((i, has_stroke))
            rect = None
            if isinstance(geometry, Rect):
                rect = geometry
                geometry = rect_as_path(geometry)
                if geometry is None:
                    continue
            index = None
            if dashes is None or has_fill:
                if isinstance(geometry, Path):
                    if not geometry.subpaths:
                        continue
                    index = paths.add(geometry, i, len(out.shapes), len(out.subpaths),
                                      with_widths=has_stroke and dashes is None, rect=rect)
                    out.shapes.append([SHAPE_PATH, len(out.subpaths), len(geometry.subpaths), -1])
                    out.subpaths.extend([None] * len(geometry.subpaths))  # filled by the batch
                else:
                    index = self._add_ellipse(geometry, matrices[i], i)
                    if index is None:
                        continue
            if dashes is not None and has_stroke:
                stroke_index = paths.add(dashes, i, len(out.shapes), len(out.subpaths), with_widths=True)
                self.placed.dashed.append(i)
                out.shapes.append([SHAPE_PATH, len(out.subpaths), len(dashes.subpaths), -1])
                out.subpaths.extend([None] * len(dashes.subpaths))
                geometry = dashes
            else:
                stroke_index = index
            if has_fill:
                paint = paint_index(shape.fill, factors + [shape.fill_opacity], i, shape.geometry)
                out.draws.append([index, DRAW_FILL, FILL_RULES[shape.fill_rule], paint, layer, 0, 0, 0])
            if has_stroke:
                paint = paint_index(shape.stroke, factors + [shape.stroke_opacity], i, shape.geometry)
                stroke_rows.append((len(out.draws), i))
                per_point = int(isinstance(geometry, Path) and geometry.widths is not None)
                out.draws.append([stroke_index, DRAW_STROKE, 0, paint, layer,
                                  CAPS[shape.linecap], JOINS[shape.linejoin], per_point])

        paths.finish(out, ops, matrices, scale, self.placed)
        self._finish_paints(solid_colors, solid_alphas, gradient_rows)
        self._finish_draw_params(stroke_rows, matrices, scale, similar)
        return out

    def _add_ellipse(self, geometry, m, shape_index: int) -> int | None:
        r = self.ops.expand(geometry.radius.reshape(1), 2) if isinstance(geometry, Circle) else geometry.radii
        present = value(r.min()) > 0
        if not present and not self.keep_empty:
            return None
        ops = self.ops
        c = affine_apply(m, ops.f32(geometry.center.reshape(1, 2)))[0]
        axes = m[:2, :2] @ ops.diag(ops.f32(r))
        if not present:
            axes = axes * 0.0  # (keep_empty: drawn as nothing)
        self.placed.ellipses.append((len(self.out.ellipses), shape_index, geometry))
        self.out.ellipses.append(ops.cat([c, axes.reshape(4)]))
        self.out.shapes.append([SHAPE_ELLIPSE, 0, 0, len(self.out.ellipses) - 1])
        return len(self.out.shapes) - 1

    def _finish_paints(self, solid_colors, solid_alphas, gradient_rows) -> None:
        """Paint table: the solids (stacked in one go), then the gradients; draws that
        point at a gradient are renumbered."""
        out, ops = self.out, self.ops
        n_solid = self._n_solid = len(solid_colors)
        if n_solid:
            colors = _stack(ops, solid_colors)
            # Multiply each paint's alpha factors: pad the lists with ones and stack once.
            depth = max(len(f) for f in solid_alphas)
            one = ops.f32(1.0)
            columns = [_stack(ops, [f[k] if k < len(f) else one for f in solid_alphas]) for k in range(depth)]
            alphas = ops.prod(ops.stack(columns), 0).reshape(n_solid)
            colors = ops.cat([colors[:, :3], colors[:, 3:4] * alphas[:, None]], dim=1)
            self.placed.solids, self.placed.solid_alphas = solid_colors, alphas
            ident = ops.expand(ops.eye(2, 3).reshape(1, 6), n_solid, 6)
            out.paint_params.append(ops.cat([ident, colors, ops.zeros((n_solid, 1))], dim=1))
            out.paints.extend([[PAINT_SOLID, 0, 0]] * n_solid)
        gradient_index = []
        for paint, alpha, m, geometry in gradient_rows:
            gradient_index.append(self._add_gradient(paint, alpha, m, geometry))
        keep = []
        for row in out.draws:
            if row[3] < 0:
                g = gradient_index[-row[3] - 1]
                if g is None:
                    keep.append(False)  # a gradient that paints nothing (zero-size bbox, ...)
                    continue
                row[3] = n_solid + g
            keep.append(True)
        self._keep_draws = keep

    def _finish_draw_params(self, stroke_rows, matrices, scale, similar) -> None:
        out, ops = self.out, self.ops
        n = len(out.draws)
        params = ops.zeros((n, 6))
        params[:, 1] = 4.0
        params[:, 2] = 1.0
        params[:, 5] = 1.0
        if stroke_rows:
            rows = ops.index([r for r, _ in stroke_rows])
            idx = [i for _, i in stroke_rows]
            widths = ops.stack([ops.f32(self.scene.shapes[i].stroke_width).reshape(()) for i in idx])
            s = scale[idx]
            lin = matrices[idx, :2, :2]
            det = lin[:, 0, 0] * lin[:, 1, 1] - lin[:, 0, 1] * lin[:, 1, 0]
            # stroke space: the shape's local space, uniformly scaled (identity for similarities)
            inv = ops.stack([lin[:, 1, 1], -lin[:, 0, 1], -lin[:, 1, 0], lin[:, 0, 0]], dim=1) / det[:, None]
            metric = ops.where(ops.from_numpy(similar[idx])[:, None],
                               ops.expand(ops.f32([1.0, 0, 0, 1]), len(idx), 4), s[:, None] * inv)
            limits = ops.f32([float(self.scene.shapes[i].miter_limit) for i in idx])
            stroke_params = ops.cat([(widths * s)[:, None], limits[:, None], metric], dim=1)
            params = ops.put_rows(params, rows, stroke_params)
        keep = self._keep_draws if self._keep_draws is not None else [True] * n
        row_after = np.cumsum(keep) - 1  # rows once the draws that paint nothing are dropped
        self.placed.strokes = [(int(row_after[row]), i) for row, i in stroke_rows if keep[row]]
        if not all(keep):
            params = params[ops.from_numpy(np.asarray(keep))]
            out.draws = [row for row, k in zip(out.draws, keep) if k]
        out.draw_params = [params]


class _PathBatch:
    """All path geometry of a scene, mapped to pixels and indexed in one go."""

    def __init__(self):
        self.points: list = []                  # local points per path
        self.owner: list[int] = []              # shape index (for its matrix) per path
        self.degrees: list[np.ndarray] = []
        self.subpaths: list[list] = []
        self.subpath_slot: list[int] = []       # first row in Packed.subpaths per path
        self.widths: list = []                  # per-point stroke widths per path, or None
        self.rects: list = []                   # the Rect a path was made from, or None

    def add(self, path: Path, shape_index: int, core_shape: int, subpath_slot: int,
            with_widths: bool = False, rect: Rect | None = None) -> int:
        widths = path.widths if with_widths else None
        if widths is not None and _count(widths) != len(path.points):
            raise VecfitError(f"a path's widths must have one value per point "
                              f"({_count(widths)} widths for {len(path.points)} points)")
        self.widths.append(widths)
        self.rects.append(rect)
        self.points.append(path.points)
        self.owner.append(shape_index)
        self.degrees.append(np.asarray(path.degrees, dtype=np.int64))
        self.subpaths.append(path.subpaths)
        self.subpath_slot.append(subpath_slot)
        return core_shape

    def finish(self, out: Packed, ops, matrices, scale, placed: Placement) -> None:
        if not self.points:
            return
        counts = [len(p) for p in self.points]
        rows = out.n_points + np.concatenate([[0], np.cumsum(counts)[:-1]])
        placed.paths = [(int(row), points, owner, rect, widths) for row, points, owner, rect, widths
                        in zip(rows, self.points, self.owner, self.rects, self.widths)]
        local = ops.f32(ops.cat(self.points))
        # (numpy: torch's repeat_interleave wakes its thread pool, 0.6 ms a call on 2 busy cores)
        owner = ops.from_numpy(np.repeat(np.asarray(self.owner, dtype=np.int64), counts))
        m = matrices[owner]
        out.points.append(ops.einsum("nij,nj->ni", m[:, :2, :2], local) + m[:, :2, 2])
        if any(w is not None for w in self.widths):
            # Per-point widths, aligned with the points, in stroke-space units like the
            # uniform width (times the shape's scale; zero where a path has none).
            local_w = ops.cat([ops.f32(w).reshape(-1) if w is not None else ops.zeros(n)
                               for w, n in zip(self.widths, counts)])
            out.point_widths.append(local_w * scale[owner])
        base = out.n_points
        out.n_points += len(local)

        # All subpaths of the batch as arrays: (first segment, count, closed), with segment
        # numbers counted over the whole batch.
        seg_base = np.concatenate([[0], np.cumsum([len(d) for d in self.degrees])])
        rows = [(first + int(b), count, int(bool(closed)))
                for subpaths, b in zip(self.subpaths, seg_base) for first, count, closed in subpaths]
        subs = np.asarray(rows, dtype=np.int64).reshape(-1, 3)
        first, count, closed_sub = subs[:, 0], subs[:, 1], subs[:, 2].astype(bool)
        slot0 = self.subpath_slot[0]
        out.subpaths[slot0:slot0 + len(subs)] = subs.tolist()
        deg = np.concatenate(self.degrees) if self.degrees else np.zeros(0, dtype=np.int64)
        running = np.concatenate([[0], np.cumsum(deg)])
        # Points per subpath, and where each starts (subpaths are stored one after another).
        sub_points = running[first + count] - running[first] + (~closed_sub)
        sub_first_point = base + np.concatenate([[0], np.cumsum(sub_points)[:-1]])
        sub_of_seg = np.repeat(np.arange(len(subs)), count)
        # Offset of each segment's first point inside its subpath.
        start = running[:-1] - running[first][sub_of_seg]
        j = np.arange(4)[None, :]
        local_idx = start[:, None] + j
        n_sub = sub_points[sub_of_seg][:, None]
        closed = closed_sub[sub_of_seg][:, None]
        local_idx = np.where(closed, local_idx % np.maximum(n_sub, 1), local_idx)
        idx = sub_first_point[sub_of_seg][:, None] + local_idx
        idx = np.where(j <= deg[:, None], idx, -1)
        out.segments.append(np.concatenate([deg[:, None], idx], axis=1))


def dashed_stroke(shape: Shape, budget: DashBudget | None = None) -> Path | None:
    """The dashes the shape's stroke is drawn from (vecfit.scene.dashes), or None where it
    is drawn solid: no dash pattern or one SVG draws solid, or dashes the scene's
    ``budget`` (limits.MAX_DASHES; a new one by default) has no room for, with a warning
    naming the element."""
    if shape.dash_array is None:
        return None
    pattern = dash_pattern(shape.dash_array)
    if pattern is None or not math.isfinite(float(shape.dash_offset)):
        return None
    geometry = shape.geometry
    plain = not any(is_tensor(v) for v in vars(geometry).values())
    g = outline_path(as_torch(geometry) if plain else geometry)  # (dashes are cut in torch)
    if g is None or not g.subpaths:
        return None
    dashes = dash_path(g, pattern, float(shape.dash_offset), budget=budget, width=dash_width(shape))
    if dashes is None:  # (the pattern and offset are valid: no room left in the budget)
        warnings.warn(f"{shape.source if shape.source is not None else 'a shape'}: stroke-dasharray makes more "
                      f"than {_limits.MAX_DASHES} dashes in the scene (the limit); stroked solid", VecfitWarning,
                      stacklevel=2)
        return None
    if plain:  # back to the Scene's kind
        dashes = dataclasses.replace(dashes, points=to_numpy(dashes.points),
                                     widths=None if dashes.widths is None else to_numpy(dashes.widths))
    return dashes


def dash_width(shape: Shape) -> float:
    """The stroke's widest width (what dash_count weighs dashes by)."""
    g = shape.geometry
    if isinstance(g, Path) and g.widths is not None and _count(g.widths):
        return value(g.widths.max())
    return value(shape.stroke_width)


def _stroke_width_positive(shape: Shape) -> bool:
    """Whether the stroke has any width (per-point widths replace stroke_width)."""
    g = shape.geometry
    if isinstance(g, Path) and g.widths is not None:
        return _count(g.widths) > 0 and value(g.widths.max()) > 0
    return value(shape.stroke_width) > 0


def _count(array) -> int:
    """Number of elements of a tensor or a NumPy array."""
    return math.prod(array.shape)


def _stack(ops, arrays: list):
    """A stack of float32 arrays of one shape, converting only when it must."""
    try:
        return ops.stack(arrays)
    except (RuntimeError, TypeError, ValueError):
        return ops.stack([ops.f32(t).reshape(arrays[0].shape) for t in arrays])


def pack_scene(scene: Scene, width: int, height: int, keep_empty: bool = False) -> Packed:
    """The scene's arrays for the core at width x height, with where its values landed
    (Packed.placement). ``keep_empty``: see Packer."""
    return Packer(scene, width, height, keep_empty).pack()
