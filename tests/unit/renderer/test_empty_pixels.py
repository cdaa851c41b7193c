"""A pixel with nothing in it (alpha 0, no background) still passes on the gradient of its
alpha: a boundary moving into it changes its alpha. Before, such pixels were skipped, and
an edge lying exactly on a pixel line had no gradient towards the empty side (the boundary
sample there belongs to the empty pixel): the right and bottom edges of an integer-aligned
rect got 0 instead of its side length."""
from __future__ import annotations

import numpy as np
import pytest
import torch

import vecfit
from vecfit.scene import Path, Scene, Shape, Solid


@pytest.mark.parametrize("right", [26.0, 26.25])
def test_edges_on_pixel_lines_move_into_empty_pixels(right):
    pts = torch.tensor([[11.0, 8.0], [right, 8.0], [right, 31.0], [11.0, 31.0]], requires_grad=True)
    scene = Scene(width=40, height=40, shapes=[Shape(
        geometry=Path(points=pts, degrees=np.array([1, 1, 1, 1]), subpaths=[(0, 4, True)]),
        fill=Solid(torch.tensor([0.2, 0.3, 0.9, 1.0])))])
    vecfit.render(scene, 40, 40, samples=2, seed=0)[..., 3].sum().backward()
    # d(sum of alpha)/d(edge position) = the edge's length (the vertical edges 23 px, the
    # horizontal ones 15 px), shared between its two end points; + outwards.
    assert torch.isfinite(pts.grad).all()
    right_edge = pts.grad[1, 0] + pts.grad[2, 0]
    bottom_edge = pts.grad[2, 1] + pts.grad[3, 1]
    assert abs(right_edge.item() - 23.0) <= 0.05 * 23
    assert abs(bottom_edge.item() - 15.0) <= 0.05 * 15
    assert abs((pts.grad[0, 0] + pts.grad[3, 0]).item() + 23.0) <= 0.05 * 23
