"""Where a Scene's shapes land on a canvas: the matrices from each group's and each
shape's own space to pixels (differentiable in the transforms)."""
from __future__ import annotations

import torch

from vecfit.errors import VecfitError

from .model import Scene


def canvas_matrix(scene: Scene, width: int, height: int) -> torch.Tensor:
    """Root user space -> pixels of a ``width`` x ``height`` render."""
    sx, sy = width / scene.width, height / scene.height
    return torch.diag(torch.tensor([sx, sy, 1.0], dtype=torch.float32)) @ scene.view.float()


def group_matrices(scene: Scene, canvas: torch.Tensor) -> list[torch.Tensor]:
    """Each group's own space -> pixels, given the root's ``canvas`` matrix."""
    out: list[torch.Tensor] = []
    for i, group in enumerate(scene.groups):
        if group.parent >= i:
            raise VecfitError("scene groups must come after their parents")
        parent = canvas if group.parent < 0 else out[group.parent]
        out.append(parent @ group.transform.float())
    return out


def stacked_shape_matrices(scene: Scene, canvas: torch.Tensor, groups: list[torch.Tensor]) -> torch.Tensor:
    """[S, 3, 3]: each shape's own space -> pixels, in one batched product."""
    shapes = scene.shapes
    if not shapes:
        return torch.zeros((0, 3, 3))
    parents = torch.stack([canvas] + groups)
    index = torch.tensor([s.group + 1 for s in shapes])
    own = torch.stack([s.transform.float() for s in shapes])
    return parents[index] @ own


def shape_matrices(scene: Scene, width: int, height: int) -> torch.Tensor:
    """[S, 3, 3]: each shape's map from its own space to pixels of a width x height render."""
    canvas = canvas_matrix(scene, width, height)
    return stacked_shape_matrices(scene, canvas, group_matrices(scene, canvas))
