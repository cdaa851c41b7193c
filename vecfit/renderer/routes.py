"""Where each scene tensor's values land in the packed float arrays, and with which
coefficient: the routes the persistent pack (persistent.py) refreshes the floats by.

Read from a pack's Placement (pack.py), which says where the packer put each path, ellipse,
paint and stroke; the packer itself knows nothing of routes. A route is affine:

    out[out_index] = coefficient * tensor.reshape(-1)[source_index] + constant

(the contributions to one entry summed). Besides the routes, a pack's Routes say which
tensors enter the floats in other ways (``nonlinear``: the persistent pack then does not
apply while they are optimised) and which draws exist because of a value (``presence``,
``differences``: the pack is stale once one comes or goes).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import torch

from vecfit.scene import Circle, LinearGradient, Path, RadialGradient, Rect, Scene
from vecfit.scene.geometry import value

from .layout import COLUMNS
from .pack import Packed

PAINT_ROW = COLUMNS["paint_params"]


@dataclass
class Route:
    """out[out_index] (+)= coefficient * tensor.reshape(-1)[source_index] (+ constant)."""
    array: str
    out_index: np.ndarray
    tensor: torch.Tensor
    source_index: np.ndarray
    coefficient: np.ndarray
    constant: np.ndarray | None = None  # the part that does not depend on the tensor (else 0)
    gate: torch.Tensor | None = None    # the route applies while this tensor's values are all > 0 (else 0)


@dataclass
class Routes:
    routes: list[Route] = field(default_factory=list)
    nonlinear: set[int] = field(default_factory=set)    # ids of tensors used in other ways
    presence: list[tuple] = field(default_factory=list)  # (tensor, draw present, every): see present_if_positive
    differences: list[tuple] = field(default_factory=list)  # (a, i, b, j, present): a draw exists while a[i] > b[j]

    # ------------------------------------------------------------ affine routes

    def copy(self, array: str, first: int, tensor: torch.Tensor) -> None:
        n = tensor.numel()
        self.routes.append(Route(array, first + np.arange(n), tensor, np.arange(n), np.ones(n)))

    def scaled(self, array: str, first: int, tensor: torch.Tensor, scale: float) -> None:
        n = tensor.numel()
        self.routes.append(Route(array, first + np.arange(n), tensor, np.arange(n), np.full(n, scale)))

    def colors(self, array: str, first: int, tensor: torch.Tensor, alpha) -> None:
        """RGBA rows: RGB copied, A times the row's ``alpha`` (fixed opacities)."""
        n = tensor.numel()
        coefficient = np.ones((n // 4, 4))
        coefficient[:, 3] = np.asarray(alpha, dtype=np.float64).reshape(-1)
        self.routes.append(Route(array, first + np.arange(n), tensor, np.arange(n), coefficient.reshape(-1)))

    def points(self, array: str, row: int, tensor: torch.Tensor, m: np.ndarray) -> None:
        """[n, 2] points mapped by the affine matrix m into rows row... of a 2-column array."""
        n = len(tensor)
        k = np.arange(n)
        for c in range(2):  # out[.., c] = m[c, 0] x + m[c, 1] y + m[c, 2]
            for j in range(2):
                if m[c, j] != 0:
                    self.routes.append(Route(array, 2 * (row + k) + c, tensor, 2 * k + j, np.full(n, m[c, j]),
                                             np.full(n, m[c, 2])))

    def ellipse(self, row: int, center: torch.Tensor, radii: torch.Tensor, m: np.ndarray) -> None:
        """An ellipses row: centre mapped by m, axes = m's linear part times diag(radii)
        while every radius is > 0, else 0 (the pack keeps the draw, drawing nothing:
        pack_scene's keep_empty), so that a radius crossing 0 changes no structure."""
        first = row * COLUMNS["ellipses"]
        for c in range(2):
            for j in range(2):
                if m[c, j] != 0:
                    self.routes.append(Route("ellipses", np.array([first + c]), center, np.array([j]),
                                             np.array([m[c, j]]), np.array([m[c, 2]])))
        circle = radii.numel() == 1
        for i in range(2):
            for j in range(2):
                self.routes.append(Route("ellipses", np.array([first + 2 + 2 * i + j]), radii,
                                         np.array([0 if circle else j]), np.array([m[i, j]]), gate=radii))

    def rect_corners(self, array: str, row: int, rect: Rect, m: np.ndarray) -> None:
        """A square-cornered rect's four corners (x0 y0, x1 y0, x1 y1, x0 y1) mapped by m."""
        corners = np.arange(4)
        x_of = {id(rect.p_min): corners[[0, 3]], id(rect.p_max): corners[[1, 2]]}
        y_of = {id(rect.p_min): corners[[0, 1]], id(rect.p_max): corners[[2, 3]]}
        for tensor in (rect.p_min, rect.p_max):
            for j, of in ((0, x_of), (1, y_of)):
                k = of[id(tensor)]
                for c in range(2):
                    if m[c, j] != 0:
                        self.routes.append(Route(array, 2 * (row + k) + c, tensor, np.full(len(k), j),
                                                 np.full(len(k), m[c, j]), np.full(len(k), m[c, 2])))

    # ------------------------------------------------- what is not a route

    def rect(self, rect: Rect) -> None:
        """A rect becomes a path (geometry.rect_as_path): with square corners, its corners
        are its p_min and p_max (rect_corners); rounded, the radii enter non-linearly. It
        is drawn while its width and height are above 0 and keeps square corners while a
        radius is 0."""
        rx, ry = (float(v) for v in rect.corner_radii.detach())
        if rx > 0 and ry > 0:
            self.used_otherwise(rect.p_min, rect.p_max, rect.corner_radii)
            return
        self.present_if_positive(rect.corner_radii, False, every=True)
        for axis in range(2):
            size = float(rect.p_max.detach()[axis] - rect.p_min.detach()[axis])
            self.differences.append((rect.p_max, axis, rect.p_min, axis, size > 0))

    def used_otherwise(self, *tensors: torch.Tensor) -> None:
        self.nonlinear.update(id(t) for t in tensors)

    def present_if_positive(self, tensor: torch.Tensor, present: bool, every: bool = False) -> None:
        """A draw exists while the tensor's largest value (``every``: its smallest) is > 0."""
        self.presence.append((tensor, bool(present), every))


def routes_of(scene: Scene, packed: Packed) -> Routes:
    """The routes of a pack of ``scene`` (torch tensors), from where it put each value."""
    placed, out = packed.placement, Routes()
    m = placed.matrices.detach().numpy()
    scale = placed.scale.detach().numpy()
    for i, stroked in placed.shapes:
        shape = scene.shapes[i]
        g = shape.geometry
        if shape.stroke is not None and scale[i] > 0:  # the stroke is drawn while its width is > 0
            out.present_if_positive(g.widths if isinstance(g, Path) and g.widths is not None
                                    else shape.stroke_width, stroked)
        if isinstance(g, Rect):
            out.rect(g)
    for row, points, owner, rect, widths in placed.paths:
        if rect is not None:
            out.rect_corners("points", row, rect, m[owner])
        else:
            out.points("points", row, points, m[owner])
        if widths is not None:
            out.scaled("point_widths", row, widths, float(scale[owner]))
    for row, owner, geometry in placed.ellipses:
        out.ellipse(row, geometry.center, geometry.radius if isinstance(geometry, Circle) else geometry.radii,
                    m[owner])
    if placed.solids:
        for row, (color, alpha) in enumerate(zip(placed.solids, placed.solid_alphas.detach())):
            out.colors("paint_params", row * PAINT_ROW + 6, color, alpha.reshape(1))
    for geometry in placed.bbox_geometry:
        out.used_otherwise(*_geometry_tensors(geometry))
    for i in placed.dashed:  # the dashes are cut where the outline's arc lengths say
        g = scene.shapes[i].geometry
        out.used_otherwise(*_geometry_tensors(g), *([g.widths] if isinstance(g, Path) and g.widths is not None
                                                    else []))
    for paint, row, first_stop, alpha in placed.gradients:
        first = row * PAINT_ROW
        if isinstance(paint, LinearGradient):
            out.copy("paint_params", first + 6, paint.start)
            out.copy("paint_params", first + 8, paint.end)
        elif isinstance(paint, RadialGradient):
            out.copy("paint_params", first + 6, paint.center)
            out.copy("paint_params", first + 8, paint.radius)
            out.copy("paint_params", first + 9, paint.focal)
        out.copy("stop_offsets", first_stop, paint.offsets)
        out.colors("stop_colors", first_stop * 4, paint.colors, np.full(len(paint.offsets), value(alpha)))
    for row, i in placed.strokes:
        out.scaled("draw_params", row * COLUMNS["draw_params"], scene.shapes[i].stroke_width, float(scale[i]))
    return out


def _geometry_tensors(geometry) -> list:
    if isinstance(geometry, Path):
        return [geometry.points]
    if isinstance(geometry, Rect):
        return [geometry.p_min, geometry.p_max, geometry.corner_radii]
    return [geometry.center, geometry.radius if isinstance(geometry, Circle) else geometry.radii]
