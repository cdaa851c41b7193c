"""vecfit.scene.placement and vecfit.scene.geometry (the Python side: rects and ellipses as
paths, bounding boxes, shape-to-pixel matrices), on torch and NumPy Scenes, against values
worked out by hand. (tests/unit/scene/test_geometry.py tests the core's geometry.)"""
from __future__ import annotations

import numpy as np
import pytest
import torch

from vecfit.errors import VecfitError
from vecfit.scene import Circle, Ellipse, Group, Path, Rect, Scene, Shape, Solid
from vecfit.scene import arrays
from vecfit.scene.arrays import numpy_arrays
from vecfit.scene.geometry import (KAPPA, affine_apply, ellipse_as_path, local_bbox, local_bbox_size,
                                   path_segments, rect_as_path, rect_path, value)
from vecfit.scene.placement import canvas_matrix, group_matrices, pixel_scales, shape_matrices


def T(x):
    """float32: a tensor, or a NumPy array within ``numpy_arrays()``."""
    return arrays.floats(x)


def affine(a, b, c, d, e, f):
    """SVG's matrix(a b c d e f) as 3 x 3."""
    return T([[a, c, e], [b, d, f], [0, 0, 1]])


def square(x, y, side, **kw):
    return Shape(Rect(T([x, y]), T([x + side, y + side])), fill=Solid(T([0, 0, 0, 1])), **kw)


def nested_scene():
    """A 100 x 50 Scene shown at 2x (view), a group translated by (10, 0) holding a
    group scaled by 3, and a shape in each: root, outer group, inner group (skewed)."""
    groups = [Group(transform=affine(1, 0, 0, 1, 10, 0)),
              Group(transform=affine(3, 0, 0, 3, 0, 0), parent=0)]
    shapes = [square(0, 0, 1),
              square(0, 0, 1, group=0),
              square(0, 0, 1, group=1, transform=affine(1, 0, 0.5, 1, 0, 0))]
    return Scene(100, 50, shapes, groups, view=affine(2, 0, 0, 2, 0, 0))


# ------------------------------------------------------------------------ placement

def test_canvas_matrix_scales_the_view_to_the_render_size():
    scene = nested_scene()
    # native 100 x 50 rendered at 50 x 100: x halved, y doubled, after the view's 2x
    m = canvas_matrix(scene, 50, 100)
    assert torch.allclose(m, affine(1, 0, 0, 4, 0, 0))


def test_shape_matrices_compose_view_groups_and_shape():
    m = shape_matrices(nested_scene(), 100, 50)
    assert m.shape == (3, 3, 3)
    assert torch.allclose(m[0], affine(2, 0, 0, 2, 0, 0))
    assert torch.allclose(m[1], affine(2, 0, 0, 2, 20, 0))
    # inner: view 2x . translate (10, 0) . scale 3 . skew x by 0.5 y
    assert torch.allclose(m[2], affine(6, 0, 3, 6, 20, 0))
    corner = affine_apply(m[2], T([[1.0, 1.0]]))
    assert torch.allclose(corner, T([[6 + 3 + 20, 6.0]]))


def test_numpy_scene_gets_the_same_matrices():
    expected = shape_matrices(nested_scene(), 64, 48).numpy()
    with numpy_arrays():
        scene = nested_scene()
    got = shape_matrices(scene, 64, 48)
    assert isinstance(got, np.ndarray) and got.dtype == np.float32
    np.testing.assert_allclose(got, expected, rtol=1e-6)


def test_groups_must_come_after_their_parents():
    scene = nested_scene()
    scene.groups[0].parent = 1
    with pytest.raises(VecfitError, match="after their parents"):
        group_matrices(scene, canvas_matrix(scene, 100, 50))


def test_pixel_scales_are_the_root_of_the_area_factor():
    scene = nested_scene()
    np.testing.assert_allclose(pixel_scales(scene), [2.0, 2.0, 6.0], rtol=1e-6)
    # at twice the native size every scale doubles; an empty scene has none
    np.testing.assert_allclose(pixel_scales(scene, 200, 100), [4.0, 4.0, 12.0], rtol=1e-6)
    assert pixel_scales(Scene(10, 10)).shape == (0,)
    assert shape_matrices(Scene(10, 10), 10, 10).shape == (0, 3, 3)


def test_matrices_are_differentiable_in_the_transforms():
    scene = nested_scene()
    scale = scene.groups[1].transform
    scale.requires_grad_(True)
    shape_matrices(scene, 100, 50)[2, 0, 0].backward()
    # d(m[2][0,0]) / d(inner scale's a) = view's 2 (the skew leaves that entry alone)
    assert float(scale.grad[0, 0]) == pytest.approx(2.0)


# ------------------------------------------------------------------------- geometry

def test_value_reads_tensors_arrays_and_numbers():
    assert value(T(2.5).requires_grad_(True)) == 2.5
    assert value(np.array([[1.25]])) == 1.25
    assert value(3) == 3.0


def test_sharp_rect_is_four_lines_clockwise_from_its_corner():
    pts, degrees = rect_path(Rect(T([1, 2]), T([5, 7])))
    assert degrees == [1, 1, 1, 1]
    assert torch.equal(pts, T([[1, 2], [5, 2], [5, 7], [1, 7]]))


def test_round_rect_is_lines_and_quarter_ellipse_cubics():
    pts, degrees = rect_path(Rect(T([0, 0]), T([10, 6]), T([2, 1])))
    assert degrees == [1, 3, 1, 3, 1, 3, 1, 3] and pts.shape == (16, 2)
    assert torch.allclose(pts[0], T([2, 0])) and torch.allclose(pts[1], T([8, 0]))
    # first corner: from (8, 0) by handles KAPPA * radius long to (10, 1)
    assert torch.allclose(pts[2], T([8 + 2 * KAPPA, 0])) and torch.allclose(pts[3], T([10, 1 - KAPPA]))
    assert torch.allclose(pts[4], T([10, 1]))


def test_rect_as_path_is_closed_and_none_when_empty():
    path = rect_as_path(Rect(T([1, 2]), T([5, 7])))
    assert path.subpaths == [(0, 4, True)] and path.subpath_point_ranges() == [(0, 4)]
    assert rect_as_path(Rect(T([1, 2]), T([1, 7]))) is None
    assert rect_as_path(Rect(T([1, 2]), T([5, 1]))) is None


def test_ellipse_as_path_starts_at_plus_x_and_turns_to_plus_y():
    path = ellipse_as_path(Ellipse(T([10, 20]), T([4, 2])))
    assert path.degrees.tolist() == [3, 3, 3, 3] and path.points.shape == (12, 2)
    assert torch.allclose(path.points[0], T([14, 20]))
    assert torch.allclose(path.points[3], T([10, 22]))  # SVG 2's direction: through (cx, cy + ry)
    assert torch.allclose(path.points[6], T([6, 20]))
    circle = ellipse_as_path(Circle(T([0, 0]), T(3.0)))
    assert torch.allclose(circle.points[9], T([0, -3]))
    assert ellipse_as_path(Circle(T([0, 0]), T(0.0))) is None


def test_ellipse_path_is_differentiable_in_the_radius():
    r = T(3.0).requires_grad_(True)
    ellipse_as_path(Circle(T([0, 0]), r)).points[0, 0].backward()
    assert float(r.grad) == pytest.approx(1.0)


def test_bounding_boxes_of_each_kind():
    lo, hi = local_bbox(Circle(T([5, 5]), T(2.0)))
    assert lo.tolist() == [3, 3] and hi.tolist() == [7, 7]
    lo, hi = local_bbox(Ellipse(T([5, 5]), T([3, 1])))
    assert lo.tolist() == [2, 4] and hi.tolist() == [8, 6]
    lo, hi = local_bbox(Rect(T([1, 2]), T([4, 6])))
    assert lo.tolist() == [1, 2] and hi.tolist() == [4, 6]
    # an open cubic (0,0) (0,4) (4,4) (4,0): its top is at y = 3 (t = 1/2), not at the handles' 4
    cubic = Path(T([[0, 0], [0, 4], [4, 4], [4, 0]]), np.array([3]), [(0, 1, False)])
    lo, hi = local_bbox(cubic)
    assert torch.allclose(lo, T([0, 0])) and torch.allclose(hi, T([4, 3]))
    assert local_bbox_size(Rect(T([0, 0]), T([4, 9]))) == pytest.approx(6.0)  # sqrt(4 * 9)
    assert local_bbox(Path(T(np.zeros((0, 2))), np.array([], int), [])) is None


def test_bounding_box_of_a_numpy_path_is_numpy():
    with numpy_arrays():
        path = Path(np.array([[0, 0], [2, 5], [6, 1]], np.float32), np.array([1, 1]), [(0, 2, False)])
    lo, hi = local_bbox(path)
    assert isinstance(lo, np.ndarray)
    np.testing.assert_allclose([lo, hi], [[0, 0], [6, 5]])


def test_path_segments_wrap_a_closed_subpath_to_its_start():
    # a closed triangle (3 lines) then an open quadratic: the last line ends at point 0
    path = Path(T([[0, 0], [4, 0], [4, 3], [10, 10], [12, 14], [14, 10]]), np.array([1, 1, 1, 2]),
                [(0, 3, True), (3, 1, False)])
    (tri, tri_degrees), (quad, quad_degrees) = list(path_segments(path))
    assert tri_degrees == [1, 1, 1] and quad_degrees == [2]
    assert torch.equal(tri[2], T([[4, 3], [0, 0]]))
    assert torch.equal(quad[0], T([[10, 10], [12, 14], [14, 10]]))
