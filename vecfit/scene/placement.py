"""Where a Scene's shapes land on a canvas: the matrices from each group's and each
shape's own space to pixels (differentiable in the transforms; NumPy for a Scene of
NumPy arrays, see ops.py)."""
from __future__ import annotations

from vecfit.errors import VecfitError

from .model import Scene
from .ops import ops_for


def canvas_matrix(scene: Scene, width: int, height: int):
    """Root user space -> pixels of a ``width`` x ``height`` render."""
    sx, sy = width / scene.width, height / scene.height
    ops = ops_for(scene.view)
    return ops.diag(ops.f32([sx, sy, 1.0])) @ ops.f32(scene.view)


def group_matrices(scene: Scene, canvas) -> list:
    """Each group's own space -> pixels, given the root's ``canvas`` matrix."""
    ops = ops_for(canvas)
    out: list = []
    for i, group in enumerate(scene.groups):
        if group.parent >= i:
            raise VecfitError("scene groups must come after their parents")
        parent = canvas if group.parent < 0 else out[group.parent]
        out.append(parent @ ops.f32(group.transform))
    return out


def stacked_shape_matrices(scene: Scene, canvas, groups: list):
    """[S, 3, 3]: each shape's own space -> pixels, in one batched product."""
    shapes = scene.shapes
    ops = ops_for(canvas)
    if not shapes:
        return ops.zeros((0, 3, 3))
    parents = ops.stack([canvas] + groups)
    index = ops.index([s.group + 1 for s in shapes])
    own = ops.stack([ops.f32(s.transform) for s in shapes])
    return parents[index] @ own


def shape_matrices(scene: Scene, width: int, height: int):
    """[S, 3, 3]: each shape's map from its own space to pixels of a width x height render."""
    canvas = canvas_matrix(scene, width, height)
    return stacked_shape_matrices(scene, canvas, group_matrices(scene, canvas))


def pixel_scales(scene: Scene, width: float | None = None, height: float | None = None):
    """[S] float64 NumPy: pixels per unit of each shape's own space on a width x height
    canvas (default: the Scene's own size), the square root of its map's area factor."""
    import numpy as np

    from .arrays import to_numpy

    if not scene.shapes:
        return np.zeros(0)
    w = scene.width if width is None else width
    h = scene.height if height is None else height
    m = np.asarray(to_numpy(shape_matrices(scene, w, h)), np.float64)[:, :2, :2]
    return np.sqrt(np.abs(m[:, 0, 0] * m[:, 1, 1] - m[:, 0, 1] * m[:, 1, 0]))
