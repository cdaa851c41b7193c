"""Tests of the NumPy reference renderer (tests/oracles/reference_render.py) against known values.

Areas are measured as the sum of alpha over the image (opaque paint, so alpha = coverage).

Sampling error: on a regular s x s grid, a straight edge that is not aligned with the grid
misclassifies about one sample per sample column it crosses, with a sign that behaves like a
random rounding, so an outline of length P (pixels) has an area error of about
sqrt(P s / 12) / s^2 px^2 (one standard deviation). ``_area_tol`` allows 5 of those plus a small
floor. That model does not hold for axis-aligned edges, whose error is systematic (up to
length / (2 s)), so axis-aligned edges sit on integer or half-integer coordinates, which never pass
through a sample (samples sit at (k + 0.5) / s) and are exact, and polygons with a generic
orientation are rotated off the axes.
"""
from __future__ import annotations

import math
import time

import numpy as np
import pytest
import torch

from reference_render import (bezier_eval, paint_straight, premultiply, render_reference,
                              stop_colors, winding_numbers)
from vecfit.scene import (Circle, Ellipse, Group, LinearGradient, Path, RadialGradient,
                                   Rect, Scene, Shape, Solid)

S = 16  # samples per pixel side in the area tests


def T(x):
    return torch.tensor(x, dtype=torch.float32)


def _area_tol(perimeter, s=S):
    return 5.0 * math.sqrt(perimeter * s / 12.0) / s ** 2 + 0.02


def polyline(pts, closed=False):
    pts = np.asarray(pts, dtype=np.float64)
    n = len(pts) - 1 if not closed else len(pts)
    return Path(T(pts), np.ones(n, dtype=np.int32), [(0, n, closed)])


def area_of(shape, size=64, s=S, **kw):
    img = render_reference(Scene(size, size, [shape]), size, size, s, **kw)
    return float(img[..., 3].sum())


def shoelace(pts):
    pts = np.asarray(pts, dtype=np.float64)
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


BLACK = lambda: Solid(T([0.0, 0.0, 0.0, 1.0]))


# ------------------------------------------------------------------------------- fills

def test_square_area_exact():
    sq = Shape(polyline([[10, 10], [30.5, 10], [30.5, 30], [10, 30]], closed=True), fill=BLACK())
    assert area_of(sq, s=8) == pytest.approx(20.5 * 20, abs=1e-9)


@pytest.mark.slow
def test_rotated_square_area():
    a = math.radians(27.0)
    c, h = np.array([32.0, 32.0]), 14.0
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    pts = c + np.array([[-h, -h], [h, -h], [h, h], [-h, h]]) @ rot.T
    sq = Shape(polyline(pts, closed=True), fill=BLACK())
    assert area_of(sq) == pytest.approx((2 * h) ** 2, abs=_area_tol(8 * h))


def test_square_open_subpath_is_filled_as_closed():
    sq = Shape(polyline([[10, 10], [30, 10], [30, 30], [10, 30]], closed=False), fill=BLACK())
    assert area_of(sq, s=8) == pytest.approx(400.0, abs=1e-9)


def test_circle_area():
    circ = Shape(Circle(T([32.0, 31.3]), T(17.3)), fill=BLACK())
    r = 17.3
    assert area_of(circ) == pytest.approx(math.pi * r * r, abs=_area_tol(2 * math.pi * r))


def test_ellipse_area_and_ellipse_equals_circle():
    e = Shape(Ellipse(T([32.0, 30.0]), T([25.0, 11.5])), fill=BLACK())
    assert area_of(e) == pytest.approx(math.pi * 25 * 11.5, abs=_area_tol(2 * math.pi * 25))
    a = render_reference(Scene(48, 48, [Shape(Circle(T([24.2, 23.7]), T(15.0)), fill=BLACK())]),
                         48, 48, 8)
    b = render_reference(Scene(48, 48, [Shape(Ellipse(T([24.2, 23.7]), T([15.0, 15.0])),
                                              fill=BLACK())]), 48, 48, 8)
    np.testing.assert_array_equal(a, b)


def test_rounded_rect_area():
    r = Shape(Rect(T([8.0, 10.0]), T([56.0, 50.0]), T([9.0, 6.0])), fill=BLACK())
    expected = 48 * 40 - (4 - math.pi) * 9 * 6
    assert area_of(r) == pytest.approx(expected, abs=_area_tol(2 * (48 + 40)))
    plain = Shape(Rect(T([8.0, 10.0]), T([56.0, 50.0])), fill=BLACK())
    assert area_of(plain, s=4) == pytest.approx(48 * 40, abs=1e-9)


@pytest.mark.slow
def test_cubic_blob_area_against_shoelace_of_dense_samples():
    ctrl = np.array([[10, 40], [5, 5], [55, 0], [50, 30], [45, 60], [20, 62]], dtype=np.float64)
    # two cubics: p0 c c p1 c c (back to p0)
    path = Path(T(ctrl), np.array([3, 3]), [(0, 2, True)])
    full = np.concatenate([ctrl, ctrl[:1]])
    dense = np.concatenate([bezier_eval(full[0:4], np.linspace(0, 1, 20001)),
                            bezier_eval(full[3:7], np.linspace(0, 1, 20001))])
    expected = shoelace(dense)
    per = float(np.sum(np.hypot(*np.diff(dense, axis=0).T)))
    assert area_of(Shape(path, fill=BLACK())) == pytest.approx(expected, abs=_area_tol(per))


A0 = -math.pi / 2 + math.radians(7.0)  # rotated off the axes: a pentagram has a horizontal edge


def _pentagram(c, R):
    ang = [A0 + k * 4 * math.pi / 5 for k in range(5)]
    return np.array([[c[0] + R * math.cos(a), c[1] + R * math.sin(a)] for a in ang])


@pytest.mark.slow
def test_evenodd_vs_nonzero_star():
    c, R = (32.0, 33.0), 28.0
    star = _pentagram(c, R)
    ri = R * math.cos(2 * math.pi / 5) / math.cos(math.pi / 5)  # inner pentagon circumradius
    outline = []
    for k in range(5):
        a = A0 + k * 2 * math.pi / 5
        outline.append([c[0] + R * math.cos(a), c[1] + R * math.sin(a)])
        b = a + math.pi / 5
        outline.append([c[0] + ri * math.cos(b), c[1] + ri * math.sin(b)])
    inner = [[c[0] + ri * math.cos(A0 + math.pi / 5 + k * 2 * math.pi / 5),
              c[1] + ri * math.sin(A0 + math.pi / 5 + k * 2 * math.pi / 5)]
             for k in range(5)]
    a_star, a_inner = shoelace(outline), shoelace(inner)
    per = 5 * 2 * R * math.sin(2 * math.pi / 5) * 2
    nz = area_of(Shape(polyline(star, closed=True), fill=BLACK(), fill_rule="nonzero"))
    eo = area_of(Shape(polyline(star, closed=True), fill=BLACK(), fill_rule="evenodd"))
    assert nz == pytest.approx(a_star, abs=_area_tol(per))
    assert eo == pytest.approx(a_star - a_inner, abs=_area_tol(per))
    # the centre pixel: filled with nonzero, empty with evenodd
    img_nz = render_reference(Scene(64, 64, [Shape(polyline(star, True), fill=BLACK())]), 64, 64, 4)
    img_eo = render_reference(Scene(64, 64, [Shape(polyline(star, True), fill=BLACK(),
                                                    fill_rule="evenodd")]), 64, 64, 4)
    assert img_nz[33, 32, 3] == 1.0 and img_eo[33, 32, 3] == 0.0


def test_two_subpaths_hole():
    outer = [[8, 8], [56, 8], [56, 56], [8, 56]]
    cw_inner = [[20, 20], [20, 44], [44, 44], [44, 20]]     # opposite direction: a hole (nonzero)
    ccw_inner = [[20, 20], [44, 20], [44, 44], [20, 44]]    # same direction: winding 2
    for inner, rule, expected in [(cw_inner, "nonzero", 48 ** 2 - 24 ** 2),
                                  (ccw_inner, "nonzero", 48 ** 2),
                                  (ccw_inner, "evenodd", 48 ** 2 - 24 ** 2)]:
        path = Path(T(outer + inner), np.ones(8, dtype=np.int32), [(0, 4, True), (4, 4, True)])
        assert area_of(Shape(path, fill=BLACK(), fill_rule=rule), s=4) == pytest.approx(expected)


def test_winding_numbers_helper():
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)  # CCW in a y-up frame
    q = np.array([[0.5, 0.5], [1.5, 0.5], [0.5, -0.5], [0.0, 0.5]])
    assert list(winding_numbers([sq], q)[:3]) == [1, 0, 0]
    assert list(winding_numbers([sq, sq], q)[:3]) == [2, 0, 0]
    assert list(winding_numbers([sq[::-1]], q)[:3]) == [-1, 0, 0]


# ----------------------------------------------------------------------------- strokes

def _line(p, q, w, cap="butt"):
    return Shape(polyline([p, q]), stroke=BLACK(), stroke_width=T(w), linecap=cap)


@pytest.mark.parametrize("cap,extra", [("butt", 0.0), ("square", 0.5), ("round", math.pi / 8)])
def test_straight_line_caps_axis_aligned(cap, extra):
    L, w = 36.0, 6.0
    got = area_of(_line([14.0, 30.0], [14.0 + L, 30.0], w, cap))
    expected = L * w + 2 * extra * w * w
    tol = 1e-9 if cap != "round" else _area_tol(math.pi * w)
    assert got == pytest.approx(expected, abs=tol)


@pytest.mark.slow
@pytest.mark.parametrize("cap,extra", [("butt", 0.0), ("square", 0.5), ("round", math.pi / 8)])
def test_straight_line_caps_diagonal(cap, extra):
    p, q, w = np.array([12.3, 15.1]), np.array([49.7, 44.2]), 5.0
    L = float(np.hypot(*(q - p)))
    got = area_of(_line(p, q, w, cap))
    assert got == pytest.approx(L * w + 2 * extra * w * w, abs=_area_tol(2 * L + 2 * w))


@pytest.mark.slow
@pytest.mark.parametrize("join,miter_limit,expected_extra", [
    ("miter", 4.0, 0.0),                              # 2 L w: the miter square equals the overlap
    ("miter", 1.4, -1.0 / 8),                        # limit below sqrt(2): bevel
    ("bevel", 4.0, -1.0 / 8),                        # - w^2/4 overlap + w^2/8 triangle
    ("round", 4.0, -1.0 / 4 + math.pi / 16),         # - w^2/4 overlap + quarter disk
])
def test_right_angle_join_area(join, miter_limit, expected_extra):
    L, w = 30.0, 8.0
    pts = [[12.0, 14.0], [12.0 + L, 14.0], [12.0 + L, 14.0 + L]]
    sh = Shape(polyline(pts), stroke=BLACK(), stroke_width=T(w), linejoin=join,
               miter_limit=miter_limit)
    got = area_of(sh)
    expected = 2 * L * w + expected_extra * w * w
    # diagonal edges only in the bevel triangle and the round join
    assert got == pytest.approx(expected, abs=_area_tol(4 * w))


def test_sharp_join_miter_limit():
    """A 30-degree interior angle: miter ratio 1/sin(15 deg) = 3.86: miter with the default
    limit 4, bevel with limit 3.8."""
    v = np.array([40.0, 30.0])
    a = math.radians(30.0)
    p0 = v + 25 * np.array([-1.0, 0.0])
    p2 = v + 25 * np.array([-math.cos(a), math.sin(a)])
    w, h = 4.0, 2.0
    miter = area_of(Shape(polyline([p0, v, p2]), stroke=BLACK(), stroke_width=T(w),
                          miter_limit=4.0))
    bevel = area_of(Shape(polyline([p0, v, p2]), stroke=BLACK(), stroke_width=T(w),
                          miter_limit=3.8))
    # miter minus bevel = the triangle (n_in end, tip, n_out end): base 2 h cos(phi/2), height
    # (h / cos(phi/2) - h cos(phi/2)), phi = turning angle = 150 degrees
    phi = math.pi - a
    ch = math.cos(phi / 2)
    tri = 0.5 * (2 * h * math.sin(phi / 2)) * (h / ch - h * ch)
    assert miter - bevel == pytest.approx(tri, abs=2 * _area_tol(4 * w))


@pytest.mark.slow
def test_closed_square_stroke_has_joins_everywhere_and_no_caps():
    L, w = 30.0, 6.0
    pts = [[17.0, 17.0], [47.0, 17.0], [47.0, 47.0], [17.0, 47.0]]
    for cap in ("butt", "round", "square"):  # caps never apply to a closed subpath
        sh = Shape(polyline(pts, closed=True), stroke=BLACK(), stroke_width=T(w), linecap=cap)
        assert area_of(sh) == pytest.approx((L + w) ** 2 - (L - w) ** 2, abs=1e-9)
    rnd = Shape(polyline(pts, closed=True), stroke=BLACK(), stroke_width=T(w), linejoin="round")
    assert area_of(rnd) == pytest.approx((L + w) ** 2 - (L - w) ** 2 - (4 - math.pi) * w * w / 4,
                                         abs=_area_tol(2 * math.pi * w))
    # the same square as a Rect, and as an open subpath that returns to its start (which gets
    # caps at the start point instead of a join)
    rect = Shape(Rect(T([17.0, 17.0]), T([47.0, 47.0])), stroke=BLACK(), stroke_width=T(w))
    assert area_of(rect) == pytest.approx((L + w) ** 2 - (L - w) ** 2, abs=1e-9)
    open_sq = Shape(polyline(pts + [pts[0]]), stroke=BLACK(), stroke_width=T(w))
    assert area_of(open_sq) == pytest.approx((L + w) ** 2 - (L - w) ** 2 - w * w / 4, abs=1e-9)


@pytest.mark.slow
def test_circle_stroke_annulus_and_ellipse_sweep_agree():
    r, w = 16.0, 5.0
    circ = Shape(Circle(T([32.0, 32.0]), T(r)), stroke=BLACK(), stroke_width=T(w))
    assert area_of(circ) == pytest.approx(2 * math.pi * r * w, abs=_area_tol(4 * math.pi * r))
    ell = Shape(Ellipse(T([32.0, 32.0]), T([r, r])), stroke=BLACK(), stroke_width=T(w))
    a = render_reference(Scene(64, 64, [circ]), 64, 64, 8)
    b = render_reference(Scene(64, 64, [ell]), 64, 64, 8)
    assert np.abs(a - b).max() <= 1.0 / 64 + 1e-12  # at most one sample in a pixel differs


def test_stroke_wider_than_circle_fills_centre():
    circ = Shape(Circle(T([32.0, 32.0]), T(4.0)), stroke=BLACK(), stroke_width=T(12.0))
    assert area_of(circ) == pytest.approx(math.pi * 10.0 ** 2, abs=_area_tol(20 * math.pi))


@pytest.mark.slow
def test_curved_stroke_area_is_length_times_width():
    """Where the radius of curvature exceeds w / 2 and the sweep does not overlap itself, the
    normal sweep of a curve has area (arc length) x w exactly."""
    ctrl = np.array([[8.0, 40.0], [20.0, 10.0], [44.0, 10.0], [56.0, 40.0]])
    dense = bezier_eval(ctrl, np.linspace(0, 1, 100001))
    L = float(np.sum(np.hypot(*np.diff(dense, axis=0).T)))
    w = 3.0
    sh = Shape(Path(T(ctrl), np.array([3]), [(0, 1, False)]), stroke=BLACK(), stroke_width=T(w))
    assert area_of(sh) == pytest.approx(L * w, abs=_area_tol(2 * L))


@pytest.mark.slow
def test_stroke_under_nonuniform_scale_and_skew():
    """The stroke is defined in local space: a shape transform scales its area by |det|."""
    p, q, w = [4.0, 6.0], [20.3, 13.1], 3.0
    L = math.hypot(16.3, 7.1)
    m = np.array([[2.0, 0.37, 3.1], [0.13, 2.9, 2.3], [0, 0, 1]])  # generic: no rational slopes
    sh = Shape(polyline([p, q]), stroke=BLACK(), stroke_width=T(w), transform=T(m))
    got = area_of(sh)
    det = float(np.linalg.det(m))
    assert got == pytest.approx(det * L * w, abs=_area_tol(6 * 2 * L))
    # a horizontal line of width 2 scaled by 3 in y is a band 6 pixels tall
    sh = Shape(polyline([[10.0, 10.0], [50.0, 10.0]]), stroke=BLACK(), stroke_width=T(2.0),
               transform=torch.tensor([[1.0, 0, 0], [0, 3.0, 0], [0, 0, 1]]))
    img = render_reference(Scene(64, 64, [sh]), 64, 64, 4)
    assert img[..., 3].sum() == pytest.approx(40 * 6)
    assert img[27:33, 10:50, 3].min() == 1.0


def test_zero_length_subpath_caps():
    w = 6.0
    pts = [[30.0, 30.0], [30.0, 30.0]]
    for cap, expected, tol in [("butt", 0.0, 0.0), ("square", w * w, 1e-9),
                               ("round", math.pi * w * w / 4, _area_tol(math.pi * w))]:
        got = area_of(Shape(polyline(pts), stroke=BLACK(), stroke_width=T(w), linecap=cap))
        assert got == pytest.approx(expected, abs=tol), cap
    # a closed zero-length subpath ("M x y Z") too, and a cubic with all points equal
    dot = Path(T([[30.0, 30.0]]), np.array([1]), [(0, 1, True)])
    assert area_of(Shape(dot, stroke=BLACK(), stroke_width=T(w), linecap="square")) == \
        pytest.approx(w * w)
    cub = Path(T([[30.0, 30.0]] * 4), np.array([3]), [(0, 1, False)])
    assert area_of(Shape(cub, stroke=BLACK(), stroke_width=T(w), linecap="round")) == \
        pytest.approx(math.pi * w * w / 4, abs=_area_tol(math.pi * w))


def test_zero_length_square_cap_follows_local_axes():
    a = math.radians(30.0)
    rot = torch.tensor([[math.cos(a), -math.sin(a), 32.0], [math.sin(a), math.cos(a), 32.0],
                        [0, 0, 1]])
    sh = Shape(polyline([[0.0, 0.0], [0.0, 0.0]]), stroke=BLACK(), stroke_width=T(10.0),
               linecap="square", transform=rot)
    img = render_reference(Scene(64, 64, [sh]), 64, 64, 8)
    assert img[..., 3].sum() == pytest.approx(100.0, abs=_area_tol(40))
    # rotated with the local axes: pixel [36, 36] (offsets 4..5 on both axes from the centre) lies
    # inside an axis-aligned 10 x 10 square but outside the rotated one; pixel [34, 35] lies
    # inside the rotated one (local x in [3.6, 4.96], y in [-0.27, 1.1])
    assert img[36, 36, 3] == 0.0 and img[34, 35, 3] == 1.0


def test_zero_length_segments_do_not_break_joins():
    """A zero-length line in the middle of a polyline is skipped when finding join neighbours:
    the right angle still gets its miter."""
    L, w = 30.0, 8.0
    pts = [[12.0, 14.0], [12.0 + L, 14.0], [12.0 + L, 14.0], [12.0 + L, 14.0 + L]]
    sh = Shape(polyline(pts), stroke=BLACK(), stroke_width=T(w), linecap="butt")
    assert area_of(sh) == pytest.approx(2 * L * w, abs=1e-9)


# ------------------------------------------------------------------------------- paints

def _rect_scene(paint, p0=(0.0, 0.0), p1=(64.0, 64.0), size=64):
    return Scene(size, size, [Shape(Rect(T(list(p0)), T(list(p1))), fill=paint)])


def _bw_stops():
    return T([0.0, 1.0]), T([[0.0, 0.0, 0.0, 1.0], [1.0, 1.0, 1.0, 1.0]])


def test_linear_gradient_user_space():
    off, col = _bw_stops()
    g = LinearGradient(T([8.0, 0.0]), T([56.0, 0.0]), off, col, units="userSpaceOnUse")
    img = render_reference(_rect_scene(g), 64, 64, 4)
    x = np.arange(64) + 0.5
    expected = np.clip((x - 8.0) / 48.0, 0, 1)
    # the gradient is linear inside a pixel except where it is clamped: exact away from 8 and 56
    ok = (np.abs(x - 8.0) > 0.5) & (np.abs(x - 56.0) > 0.5)
    np.testing.assert_allclose(img[20, ok, 0], expected[ok], atol=1e-12)
    np.testing.assert_allclose(img[20, :, 3], 1.0)


def test_linear_gradient_bbox_units_and_transform():
    off, col = _bw_stops()
    # bbox units on a rect [16, 48] x [8, 40]; gradientTransform swaps x and y: vertical gradient
    swap = torch.tensor([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0, 0, 1]])
    g = LinearGradient(T([0.0, 0.0]), T([1.0, 0.0]), off, col, transform=swap,
                       units="objectBoundingBox")
    img = render_reference(_rect_scene(g, (16.0, 8.0), (48.0, 40.0)), 64, 64, 4)
    y = np.arange(8, 40) + 0.5
    np.testing.assert_allclose(img[8:40, 30, 0], (y - 8.0) / 32.0, atol=1e-12)
    np.testing.assert_allclose(img[20, 16:48, 0], (20.5 - 8.0) / 32.0, atol=1e-12)


def test_gradient_interpolates_straight_then_premultiplies():
    off = T([0.0, 1.0])
    col = T([[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0]])
    q = np.array([[0.5, 0.0], [0.25, 0.0]])
    g = LinearGradient(T([0.0, 0.0]), T([1.0, 0.0]), off, col, units="userSpaceOnUse")
    c = paint_straight(g, q, None)
    np.testing.assert_allclose(c[0], [0.5, 0.0, 0.5, 0.5])
    np.testing.assert_allclose(premultiply(c)[1], [0.75 * 0.75, 0, 0.25 * 0.75, 0.75])


def test_stop_colors_pad_and_hard_stops():
    off = np.array([0.2, 0.5, 0.5, 0.8])
    col = np.array([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1], [1, 1, 1, 1]], dtype=np.float64)
    t = np.array([0.0, 0.2, 0.35, 0.4999, 0.5, 0.65, 0.8, 1.0])
    c = stop_colors(off, col, t)
    np.testing.assert_allclose(c[0], col[0])
    np.testing.assert_allclose(c[1], col[0])
    np.testing.assert_allclose(c[2], [0.5, 0.5, 0, 1])
    np.testing.assert_allclose(c[4], col[2])  # at a repeated offset, the later stop wins
    np.testing.assert_allclose(c[5], [0.5, 0.5, 1, 1])
    np.testing.assert_allclose(c[6], col[3])
    np.testing.assert_allclose(c[7], col[3])


def test_radial_gradient_values():
    off, col = _bw_stops()
    c = T([10.0, 20.0])
    g = RadialGradient(c, T(8.0), c.clone(), off, col, units="userSpaceOnUse")
    d = 8 / math.sqrt(2)
    q = np.array([[10.0, 20.0], [14.0, 20.0], [10.0, 28.0], [10.0 + d, 20 - d], [30.0, 20.0]])
    np.testing.assert_allclose(paint_straight(g, q, None)[:, 0], [0, 0.5, 1, 1, 1], atol=1e-12)
    # with a focal point: t = 0 at the focus, linear along each ray from the focus (the circles of
    # the cone are homothetic about the focus), 1 on the circle
    f = T([6.0, 20.0])
    g = RadialGradient(c, T(8.0), f, off, col, units="userSpaceOnUse")
    edge_r, edge_l = np.array([18.0, 20.0]), np.array([2.0, 20.0])
    q = np.array([[6.0, 20.0], 0.5 * (np.array([6.0, 20.0]) + edge_r),
                  0.25 * np.array([6.0, 20.0]) + 0.75 * edge_l, [10.0, 12.0]])
    np.testing.assert_allclose(paint_straight(g, q, None)[:, 0], [0, 0.5, 0.75, 1], atol=1e-12)


def test_radial_gradient_focal_outside_is_clamped():
    off, col = _bw_stops()
    g = RadialGradient(T([10.0, 10.0]), T(5.0), T([30.0, 10.0]), off, col,
                       units="userSpaceOnUse")
    c = paint_straight(g, np.array([[14.995, 10.0], [5.0, 10.0], [10.0, 10.0]]), None)
    assert np.isfinite(c).all()
    np.testing.assert_allclose(c[:, 0], [0.0, 1.0, 0.5], atol=2e-3)


def test_radial_gradient_bbox_units_is_an_ellipse():
    off, col = _bw_stops()
    g = RadialGradient(T([0.5, 0.5]), T(0.5), T([0.5, 0.5]), off, col)  # default bbox units
    bbox = (np.array([10.0, 20.0]), np.array([50.0, 30.0]))
    q = np.array([[30.0, 25.0], [50.0, 25.0], [30.0, 30.0], [40.0, 25.0], [30.0, 27.5]])
    np.testing.assert_allclose(paint_straight(g, q, bbox)[:, 0], [0, 1, 1, 0.5, 0.5], atol=1e-12)


def test_bbox_of_a_curve_is_tight_not_control_polygon():
    """objectBoundingBox uses the geometry's bounding box: a cubic arch's control points reach
    y = 0 but the curve only reaches y = 15."""
    ctrl = [[0.0, 40.0], [0.0, 0.0], [64.0, 0.0], [64.0, 40.0]]  # top at y = 10
    path = Path(T(ctrl), np.array([3, 1]), [(0, 2, True)])  # closed by a line
    off, col = _bw_stops()
    swap = torch.tensor([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0, 0, 1]])
    g = LinearGradient(T([0.0, 0.0]), T([1.0, 0.0]), off, col, transform=swap)
    img = render_reference(Scene(64, 64, [Shape(path, fill=g)]), 64, 64, 4)
    # the curve spans y in [10, 40]: the row at y = 25.5 is at t = 0.5167
    np.testing.assert_allclose(img[25, 32, 0], (25.5 - 10.0) / 30.0, atol=1e-12)


# ---------------------------------------------------------------------- opacity, layers

RED, BLUE = [1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]


def _sq(x0, y0, x1, y1, color, **kw):
    return Shape(Rect(T([x0, y0]), T([x1, y1])), fill=Solid(T(color)), **kw)


def test_alpha_compositing_source_over():
    a = _sq(0, 0, 40, 40, [1.0, 0.0, 0.0, 0.5])
    b = _sq(20, 20, 64, 64, [0.0, 0.0, 1.0, 0.5])
    img = render_reference(Scene(64, 64, [a, b]), 64, 64, 2)
    np.testing.assert_allclose(img[10, 10], [1, 0, 0, 0.5])
    np.testing.assert_allclose(img[50, 50], [0, 0, 1, 0.5])
    # overlap: premul = blue 0.5 + 0.5 * red 0.5 -> (0.25, 0, 0.5, 0.75)
    np.testing.assert_allclose(img[30, 30], [0.25 / 0.75, 0, 0.5 / 0.75, 0.75])


def test_group_opacity_is_a_layer():
    groups = [Group(opacity=T(0.5))]
    a = _sq(0, 0, 40, 40, RED, group=0)
    b = _sq(20, 20, 64, 64, BLUE, group=0)
    img = render_reference(Scene(64, 64, [a, b], groups), 64, 64, 2)
    np.testing.assert_allclose(img[30, 30], [0, 0, 1, 0.5])   # the blue hides the red entirely
    np.testing.assert_allclose(img[10, 10], [1, 0, 0, 0.5])
    # the same with per-shape opacity: the overlap sees both
    a = _sq(0, 0, 40, 40, RED, opacity=T(0.5))
    b = _sq(20, 20, 64, 64, BLUE, opacity=T(0.5))
    img = render_reference(Scene(64, 64, [a, b]), 64, 64, 2)
    np.testing.assert_allclose(img[30, 30], [0.25 / 0.75, 0, 0.5 / 0.75, 0.75])


def test_nested_group_opacity():
    groups = [Group(opacity=T(0.5)), Group(opacity=T(0.5), parent=0)]
    shapes = [_sq(0, 0, 64, 32, RED, group=0),       # in the outer group only: 0.5
              _sq(0, 32, 64, 64, BLUE, group=1),     # in both: 0.25
              _sq(0, 0, 32, 64, [0.0, 1.0, 0.0, 1.0])]  # outside any group, on top: opaque
    img = render_reference(Scene(64, 64, shapes, groups), 64, 64, 2)
    np.testing.assert_allclose(img[10, 50], [1, 0, 0, 0.5])
    np.testing.assert_allclose(img[50, 50], [0, 0, 1, 0.25])
    np.testing.assert_allclose(img[50, 10], [0, 1, 0, 1])


def test_shape_opacity_is_a_layer_over_fill_and_stroke():
    def shape(**kw):
        return Shape(Rect(T([16.0, 16.0]), T([48.0, 48.0])), fill=Solid(T(RED)),
                     stroke=Solid(T(BLUE)), stroke_width=T(8.0), **kw)
    img = render_reference(Scene(64, 64, [shape(opacity=T(0.5))]), 64, 64, 2)
    # the stroke's inner half hides the fill
    np.testing.assert_allclose(img[17, 32], [0, 0, 1, 0.5])
    np.testing.assert_allclose(img[32, 32], [1, 0, 0, 0.5])
    np.testing.assert_allclose(img[13, 32], [0, 0, 1, 0.5])
    img = render_reference(Scene(64, 64, [shape(fill_opacity=T(0.5), stroke_opacity=T(0.5))]),
                           64, 64, 2)
    np.testing.assert_allclose(img[17, 32], [0.25 / 0.75, 0, 0.5 / 0.75, 0.75])
    np.testing.assert_allclose(img[13, 32], [0, 0, 1, 0.5])


def test_fill_opacity_multiplies_paint_alpha_and_background():
    sh = _sq(0, 0, 32, 64, [0.0, 1.0, 0.0, 0.5], fill_opacity=T(0.5))
    img = render_reference(Scene(64, 64, [sh]), 64, 64, 2, background=(1.0, 1.0, 1.0, 1.0))
    np.testing.assert_allclose(img[5, 5], [0.75, 1.0, 0.75, 1.0])
    np.testing.assert_allclose(img[5, 50], [1.0, 1.0, 1.0, 1.0])


def test_paint_order():
    a = _sq(0, 0, 40, 40, RED)
    b = _sq(20, 20, 64, 64, BLUE)
    np.testing.assert_allclose(render_reference(Scene(64, 64, [a, b]), 64, 64, 2)[30, 30], BLUE)
    np.testing.assert_allclose(render_reference(Scene(64, 64, [b, a]), 64, 64, 2)[30, 30], RED)


# --------------------------------------------------------------------------- transforms

def test_transform_chain_equivalences():
    """The same drawing via shape.transform, a group chain, the view, and the output scale."""
    m = torch.tensor([[1.5, 0.3, 4.0], [-0.2, 0.8, 6.0], [0, 0, 1]])
    half, two = torch.diag(T([0.5, 0.5, 1.0])), torch.diag(T([2.0, 2.0, 1.0]))

    def shape(**kw):
        return Shape(Path(T([[5.0, 5.0], [30.0, 2.0], [35.0, 30.0], [8.0, 25.0]]),
                          np.array([2, 1]), [(0, 2, False)]),
                     fill=Solid(T([0.2, 0.4, 0.6, 1.0])), stroke=Solid(T(RED)),
                     stroke_width=T(3.0), linejoin="miter", linecap="square", **kw)
    a = render_reference(Scene(48, 48, [shape(transform=m)]), 48, 48, 4)
    b = render_reference(Scene(48, 48, [shape(transform=two, group=1)],
                               [Group(transform=m), Group(transform=half, parent=0)]), 48, 48, 4)
    c = render_reference(Scene(48, 48, [shape()], view=m), 48, 48, 4)
    d = render_reference(Scene(24, 24, [shape(transform=half @ m)]), 48, 48, 4)
    np.testing.assert_allclose(b, a, atol=1e-12)
    np.testing.assert_allclose(c, a, atol=1e-12)
    np.testing.assert_allclose(d, a, atol=1e-12)


def test_jitter_is_seeded_and_close_to_regular():
    shapes = [Shape(Circle(T([30.0, 30.0]), T(20.0)), fill=Solid(T(RED)))]
    a = render_reference(Scene(64, 64, shapes), 64, 64, 8, jitter=True, seed=3)
    b = render_reference(Scene(64, 64, shapes), 64, 64, 8, jitter=True, seed=3)
    c = render_reference(Scene(64, 64, shapes), 64, 64, 8)
    np.testing.assert_array_equal(a, b)
    assert np.abs(a[..., 3] - c[..., 3]).max() < 0.25
    assert abs(a[..., 3].sum() - c[..., 3].sum()) < 2.0


@pytest.mark.slow
def test_speed_64px_ten_shapes():
    rng = np.random.default_rng(0)
    shapes = []
    for i in range(10):
        pts = rng.uniform(4, 60, (6, 2))
        shapes.append(Shape(Path(T(pts), np.array([3, 3]), [(0, 2, True)]),
                            fill=Solid(T(list(rng.random(3)) + [0.8])),
                            stroke=Solid(T([0.0, 0.0, 0.0, 1.0])), stroke_width=T(2.0),
                            linejoin=["miter", "round", "bevel"][i % 3]))
    t = time.perf_counter()
    img = render_reference(Scene(64, 64, shapes), 64, 64, 8)
    assert time.perf_counter() - t < 10.0
    assert img.shape == (64, 64, 4) and img.dtype == np.float64


@pytest.mark.slow
@pytest.mark.parametrize("join", ["miter", "bevel", "round"])
def test_smooth_closed_bezier_stroke_area(join):
    """A circle made of four tangent-continuous cubics: the joins between them are smooth (no
    join geometry, whatever the linejoin) and the sweep has area (length) x w."""
    k = 0.5522847498
    c, r, w = np.array([32.0, 32.0]), 20.0, 8.0
    P = c + r * np.array([[1, 0], [1, k], [k, 1], [0, 1], [-k, 1], [-1, k], [-1, 0], [-1, -k],
                          [-k, -1], [0, -1], [k, -1], [1, -k]])
    path = Path(T(P), np.array([3, 3, 3, 3]), [(0, 4, True)])
    full = np.concatenate([P, P[:1]])
    dense = np.concatenate([bezier_eval(full[3 * i:3 * i + 4], np.linspace(0, 1, 20001))
                            for i in range(4)])
    L = float(np.sum(np.hypot(*np.diff(dense, axis=0).T)))
    got = area_of(Shape(path, stroke=BLACK(), stroke_width=T(w), linejoin=join))
    assert got == pytest.approx(L * w, abs=_area_tol(2 * L))
