"""A Scene's points moved as seam carving moves the pixels under them: the starting point
of each retarget round's fit."""
from __future__ import annotations

import torch

from vecfit.scene.placement import shape_matrices
from vecfit.scene import Circle, Ellipse, Path, Rect, Scene

from .seams import shift


def point_tensors(shape) -> list[torch.Tensor]:
    """The [.., 2] tensors of a shape's geometry that are positions (not radii)."""
    g = shape.geometry
    if isinstance(g, Path):
        return [g.points]
    if isinstance(g, (Circle, Ellipse)):
        return [g.center]
    if isinstance(g, Rect):
        return [g.p_min, g.p_max]
    return []


def carve_points(scene: Scene, seams: list, width: int, height: int, axis: int = 0) -> None:
    """Move the scene's points (in place) as removing ``seams`` from its render at
    ``width`` x ``height`` moves the pixels: vertical seams (axis 0) move x, horizontal
    ones (axis 1; seams of the transposed image) move y. Each point is mapped in pixels
    through its shape's transforms and back."""
    with torch.no_grad():
        matrices = shape_matrices(scene, width, height).double()
        for shape, m in zip(scene.shapes, matrices):
            if abs(float(torch.linalg.det(m[:2, :2]))) < 1e-12:
                continue  # a shape flattened by its transform draws nothing
            inverse = torch.linalg.inv(m)
            for t in point_tensors(shape):
                p = t.detach().double().reshape(-1, 2)
                pixels = p @ m[:2, :2].T + m[:2, 2]
                along, across = pixels[:, axis].numpy(), pixels[:, 1 - axis].numpy()
                pixels[:, axis] = torch.from_numpy(shift(along, across, seams))
                local = pixels @ inverse[:2, :2].T + inverse[:2, 2]
                t.copy_(local.reshape(t.shape).to(t.dtype))
