"""Property tests of the core's geometry functions against brute force (hypothesis).

Each function is compared with something that shares none of its code: closest points with
dense sampling of the parameter refined by golden-section search, winding numbers with a
crossing count over a fine polyline (tests/oracles/reference_render.py), polynomial roots with
numpy.roots (or with roots known by construction).

Tolerances are stated relative to ``scale`` = max(1, largest coordinate magnitude involved).
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from reference_render import bezier_eval, winding_numbers

core = pytest.importorskip(
    "vecfit._core", reason="vecfit._core is not built (compile the C++ core to run these tests)")

SETTINGS = settings(max_examples=200, deadline=None,
                    suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])

coord = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)
point = st.tuples(coord, coord)


def _scale(*arrays):
    return max(1.0, max(float(np.max(np.abs(np.asarray(a, dtype=np.float64)))) for a in arrays))


# ======================================================================= closest point

@st.composite
def bezier(draw, degrees=(1, 2, 3)):
    """Control points [d+1, 2]; now and then a control point repeats the previous one (the
    degenerate tangents the core must survive), or the whole curve is a point."""
    d = draw(st.sampled_from(degrees))
    pts = [draw(point)]
    for _ in range(d):
        if draw(st.integers(0, 7)) == 0:
            pts.append(pts[-1])
        else:
            pts.append(draw(point))
    return np.array(pts, dtype=np.float64)


def _golden(f, a, b, iters=100):
    g = (math.sqrt(5) - 1) / 2
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iters):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = f(d)
    x = 0.5 * (a + b)
    return x, f(x)


def _local_minima(dist, periodic=False):
    """Indices of the local minima of a sampled function (ends count for a non-periodic one)."""
    n = len(dist)
    if periodic:
        prev, nxt = np.roll(dist, 1), np.roll(dist, -1)
    else:
        prev = np.concatenate([[np.inf], dist[:-1]])
        nxt = np.concatenate([dist[1:], [np.inf]])
    idx = np.nonzero((dist <= prev) & (dist <= nxt))[0]
    return idx[np.argsort(dist[idx])][:8] if n else idx


def _brute_closest(f, lo, hi, n, periodic=False):
    """Global minimum of the distance f over [lo, hi]: n + 1 samples, then golden-section search
    around each of the best local minima. Returns [(x, distance)] of the basins, best first."""
    xs = np.linspace(lo, hi, n + 1)
    if periodic:
        xs = xs[:-1]
    dist = f(xs)
    h = (hi - lo) / n
    out = []
    for i in _local_minima(dist, periodic):
        a, b = xs[i] - h, xs[i] + h
        if not periodic:
            a, b = max(lo, a), min(hi, b)
        x, fx = _golden(lambda t: float(f(np.array([t]))[0]), a, b)
        if fx > dist[i]:
            x, fx = xs[i], dist[i]
        out.append((x, float(fx)))
    out.sort(key=lambda r: r[1])
    return out


def _check_closest(curve_at, basins, q_core, d_core, p, scale, well_conditioned):
    """Shared checks: the core's point q_core realises its distance; that distance is the global
    minimum; the point is the minimiser unless two separate basins nearly tie or the minimum is
    flat (``well_conditioned`` false)."""
    p = np.asarray(p, dtype=np.float64)
    best_x, best_d = basins[0]
    assert abs(float(np.hypot(*(q_core - p))) - d_core) <= 1e-9 * scale, \
        "the returned distance is not the distance to the returned point"
    assert d_core <= best_d + 1e-6 * scale, f"not the global minimum: {d_core} > {best_d}"
    assert d_core >= best_d - 1e-6 * scale, f"below the brute-force minimum: {d_core} < {best_d}"
    q_best = curve_at(best_x)
    tie = any(abs(d - best_d) <= 1e-4 * scale
              and float(np.hypot(*(curve_at(x) - q_best))) > 1e-3 * scale
              for x, d in basins[1:])
    if not tie and well_conditioned(best_x):
        assert float(np.hypot(*(q_core - q_best))) <= 1e-4 * scale, \
            f"closest point {q_core} differs from brute force {q_best}"


def _bezier_dist(ctrl, p):
    return lambda t: np.hypot(*(bezier_eval(ctrl, np.atleast_1d(t)) - p).T)


def _sq_dist_curvature(ctrl, p, t, h=1e-4):
    f = lambda s: float(np.sum((bezier_eval(ctrl, np.array([min(1.0, max(0.0, s))]))[0] - p) ** 2))
    return (f(t + h) - 2 * f(t) + f(t - h)) / (h * h)


@pytest.mark.slow
@SETTINGS
@given(ctrl=bezier(), p=point)
def test_closest_point_on_segment(ctrl, p):
    p = np.array(p, dtype=np.float64)
    scale = _scale(ctrl, p)
    t_core, d_core = core.closest_point_on_segment(ctrl, (float(p[0]), float(p[1])))
    assert 0.0 <= t_core <= 1.0
    basins = _brute_closest(_bezier_dist(ctrl, p), 0.0, 1.0, 20000)
    at = lambda t: bezier_eval(ctrl, np.array([t]))[0]

    def well_conditioned(t):
        # an endpoint minimum, or an interior one where |B(t) - p|^2 curves up enough that a
        # 1e-12 error in it moves the point by well under the 1e-4 scale tolerance
        if t <= 1e-9 or t >= 1 - 1e-9:
            return True
        return _sq_dist_curvature(ctrl, p, t) >= 1e-3 * scale * scale

    _check_closest(at, basins, at(t_core), d_core, p, scale, well_conditioned)


@pytest.mark.slow
@SETTINGS
@given(ctrl=bezier())
def test_segment_bounds_hold_the_curve_tightly(ctrl):
    """The tiles bin each segment by the bounds of its curve, not of its control polygon
    (which refinement pulls far out): every curve point lies inside, and each side is
    reached by the curve."""
    ctrl = np.asarray(ctrl, np.float64)
    x0, y0, x1, y1 = core.segment_bounds(ctrl)
    curve = bezier_eval(ctrl, np.linspace(0, 1, 20001))
    scale = _scale(ctrl)
    assert curve[:, 0].min() >= x0 and curve[:, 0].max() <= x1
    assert curve[:, 1].min() >= y0 and curve[:, 1].max() <= y1
    lo, hi = curve.min(0), curve.max(0)
    assert np.allclose([x0, y0], lo, rtol=0, atol=1e-6 * scale)
    assert np.allclose([x1, y1], hi, rtol=0, atol=1e-6 * scale)


def test_segment_bounds_of_a_loop_are_inside_its_control_polygon():
    # control points pulled far out, as refinement leaves them: the curve reaches only 3/4
    ctrl = np.array([[0.0, 0.0], [40.0, 30.0], [-40.0, 30.0], [0.0, 0.0]])
    x0, y0, x1, y1 = core.segment_bounds(ctrl)
    assert y1 == pytest.approx(22.5, abs=1e-6) and x1 < 12 and x0 > -12 and y0 == pytest.approx(0, abs=1e-6)


@pytest.mark.parametrize("ctrl,p,q", [
    ([[0, 0], [10, 0]], (5, 3), (5, 0)),
    ([[0, 0], [10, 0]], (-5, 3), (0, 0)),
    ([[0, 0], [10, 0]], (15, -3), (10, 0)),
    ([[0, 0], [5, 10], [10, 0]], (5, 20), (5, 5)),      # apex of a symmetric parabola
    ([[0, 0], [0, 0], [10, 0], [10, 0]], (3, 1), (3, 0)),  # coincident end control points
    ([[0, 0], [10, 0], [0, 0]], (-2, 1), (0, 0)),       # a quadratic that doubles back
])
def test_closest_point_on_segment_known(ctrl, p, q):
    ctrl = np.array(ctrl, dtype=np.float64)
    t_core, d_core = core.closest_point_on_segment(ctrl, p)
    q = np.array(q, dtype=np.float64)
    assert float(np.hypot(*(bezier_eval(ctrl, np.array([t_core]))[0] - q))) < 1e-6
    assert d_core == pytest.approx(float(np.hypot(*(q - np.array(p)))), abs=1e-9)


def test_closest_point_on_degenerate_segment():
    ctrl = np.array([[3.0, 4.0]] * 4)
    t, d = core.closest_point_on_segment(ctrl, (0.0, 0.0))
    assert 0.0 <= t <= 1.0 and d == pytest.approx(5.0, abs=1e-12)


# ------------------------------------------------------------------------------ ellipse

@st.composite
def ellipse_case(draw):
    c = np.array(draw(point))
    A = np.array(draw(st.lists(st.floats(-5.0, 5.0, allow_nan=False), min_size=4, max_size=4)),
                 dtype=np.float64).reshape(2, 2)
    norm2 = float(np.sum(A * A))
    assume(norm2 > 1e-2 and abs(np.linalg.det(A)) >= 0.05 * norm2)  # non-singular, cond < ~40
    kind = draw(st.sampled_from(["any", "inside", "on", "centre", "near_centre", "axis"]))
    if kind == "any":
        p = np.array(draw(st.tuples(st.floats(-25, 25), st.floats(-25, 25))))
    elif kind == "centre":
        p = c.copy()
    elif kind == "near_centre":
        p = c + np.array(draw(st.tuples(st.floats(-1e-6, 1e-6), st.floats(-1e-6, 1e-6))))
    else:
        a = draw(st.floats(0.0, 2 * math.pi))
        rho = {"inside": draw(st.floats(0.0, 1.0)), "on": 1.0}.get(kind)
        if kind == "axis":  # on a principal axis (inside or outside)
            U, S, _ = np.linalg.svd(A)
            k = draw(st.integers(0, 1))
            p = c + draw(st.floats(-2.0, 2.0)) * S[k] * U[:, k]
        else:
            p = c + A @ np.array([rho * math.cos(a), rho * math.sin(a)])
    return c, A, p


@pytest.mark.slow
@SETTINGS
@given(case=ellipse_case())
def test_closest_point_on_ellipse(case):
    c, A, p = case
    scale = _scale(c, A, p)
    q_core, d_core = core.closest_point_on_ellipse((float(c[0]), float(c[1])), A,
                                                   (float(p[0]), float(p[1])))
    q_core = np.asarray(q_core, dtype=np.float64)
    # the returned point lies on the ellipse: |A^-1 (q - c)| = 1
    u = np.linalg.solve(A, q_core - c)
    assert abs(float(np.hypot(*u)) - 1.0) <= 1e-9 * np.linalg.cond(A), \
        f"returned point {q_core} is not on the ellipse: |A^-1 (q - c)| = {np.hypot(*u)}"
    at = lambda a: c + A @ np.array([math.cos(a), math.sin(a)])
    f = lambda a: np.hypot(*(c[:, None] + A @ np.stack([np.cos(a), np.sin(a)]) - p[:, None]))
    basins = _brute_closest(f, 0.0, 2 * math.pi, 20000, periodic=True)

    def well_conditioned(a):
        h = 1e-4
        g = lambda s: float(np.sum((at(s) - p) ** 2))
        return (g(a + h) - 2 * g(a) + g(a - h)) / (h * h) >= 1e-3 * scale * scale

    _check_closest(at, basins, q_core, d_core, p, scale, well_conditioned)


def test_closest_point_on_circle_and_axis_aligned_ellipse():
    q, d = core.closest_point_on_ellipse((1.0, 2.0), np.diag([3.0, 3.0]), (1.0, 7.0))
    np.testing.assert_allclose(q, [1.0, 5.0], atol=1e-12)
    assert d == pytest.approx(2.0, abs=1e-12)
    q, d = core.closest_point_on_ellipse((0.0, 0.0), np.diag([4.0, 2.0]), (0.0, 0.5))
    # a minimiser is determined to about sqrt(eps) * scale by the distance alone
    np.testing.assert_allclose(q, [0.0, 2.0], atol=1e-7)
    assert d == pytest.approx(1.5, abs=1e-9)
    # inside, near the end of the major axis: the closest point is off the axis when
    # |x| < (a^2 - b^2) / a (the evolute), here on the axis since 3.5 > 3
    q, d = core.closest_point_on_ellipse((0.0, 0.0), np.diag([4.0, 2.0]), (3.5, 0.0))
    np.testing.assert_allclose(q, [4.0, 0.0], atol=1e-7)
    assert d == pytest.approx(0.5, abs=1e-9)


# ====================================================================== winding number

@st.composite
def path_case(draw):
    """A Path layout (points, degrees, subpaths) of 1-3 subpaths, open or closed, and a point.

    Rays through vertices and along tangents are where crossing counts go wrong, and random
    floats never produce them, so: a point now and then copies the previous point's y
    (horizontal edges, horizontal end tangents of curves, as in every rounded-rect corner), and
    the query point often takes the exact y of one of the points."""
    pts, degs, subs = [], [], []
    for _ in range(draw(st.integers(1, 3))):
        n = draw(st.integers(1, 5))
        d = [draw(st.integers(1, 3)) for _ in range(n)]
        closed = draw(st.booleans())
        m = sum(d) + (0 if closed else 1)
        subs.append((len(degs), n, int(closed)))
        degs += d
        for _ in range(m):
            x, y = draw(point)
            if pts and draw(st.integers(0, 3)) == 0:
                y = pts[-1][1]
            pts.append((x, y))
    p = list(draw(st.tuples(st.floats(-12, 12), st.floats(-12, 12))))
    if draw(st.booleans()):
        p[1] = pts[draw(st.integers(0, len(pts) - 1))][1]
    return (np.array(pts, dtype=np.float64), np.array(degs, dtype=np.int32),
            np.array(subs, dtype=np.int32), np.array(p, dtype=np.float64))


def _fine_polylines(points, degrees, subpaths, pieces=20000):
    """Every subpath as a polyline, each curve cut into ``pieces`` uniform pieces. The chord
    error is at most max|B''| / (8 pieces^2) <= 6 * 40 / (8 * 4e8) < 1e-7 for points in
    [-10, 10]^2."""
    from reference_render import path_segments
    polys = []
    for segs, _closed in path_segments(points, degrees, [tuple(s) for s in subpaths]):
        parts = [segs[0][:1]]
        for ctrl in segs:
            n = 1 if len(ctrl) == 2 else pieces
            parts.append(bezier_eval(ctrl, np.linspace(0, 1, n + 1))[1:])
        polys.append(np.concatenate(parts))
    return polys


def _dist_to_polylines(polys, p):
    best = np.inf
    for poly in polys:
        a = poly
        b = np.roll(poly, -1, axis=0)  # closed implicitly, like the fill
        d = b - a
        ll = np.einsum("ij,ij->i", d, d)
        t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.where(ll > 0, ll, 1.0), 0, 1)
        best = min(best, float(np.min(np.hypot(*(a + t[:, None] * d - p).T))))
    return best


_SIGN = []


def _core_sign():
    """The core's orientation convention: +1 if a loop counter-clockwise in a y-up frame (the
    reference's convention) winds +1, -1 if it winds -1. Either is fine, if used consistently."""
    if not _SIGN:
        sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)
        w = core.winding_number(sq, np.ones(4, dtype=np.int32),
                                np.array([[0, 4, 1]], dtype=np.int32), (0.5, 0.5))
        assert w in (1, -1), f"unit square winds {w}"
        _SIGN.append(int(w))
    return _SIGN[0]


@pytest.mark.slow
@SETTINGS
@given(case=path_case())
def test_winding_number(case):
    points, degrees, subpaths, p = case
    polys = _fine_polylines(points, degrees, subpaths)
    assume(_dist_to_polylines(polys, p) > 1e-6 + 1e-7)  # not within 1e-6 of the curve
    expected = int(winding_numbers(polys, p[None, :])[0])
    got = core.winding_number(points, degrees, subpaths, (float(p[0]), float(p[1])))
    assert got == _core_sign() * expected


def test_winding_number_known():
    s = _core_sign()
    # a square traversed twice, an open triangle (closed implicitly), and a closed quadratic loop
    sq = np.array([[0, 0], [4, 0], [4, 4], [0, 4]] * 2, dtype=np.float64)
    subs = np.array([[0, 4, 1], [4, 4, 1]], dtype=np.int32)
    assert core.winding_number(sq, np.ones(8, dtype=np.int32), subs, (2.0, 2.0)) == 2 * s
    tri = np.array([[0, 0], [4, 0], [0, 4]], dtype=np.float64)
    assert core.winding_number(tri, np.ones(2, dtype=np.int32),
                               np.array([[0, 2, 0]], dtype=np.int32), (1.0, 1.0)) == s
    assert core.winding_number(tri, np.ones(2, dtype=np.int32),
                               np.array([[0, 2, 0]], dtype=np.int32), (3.0, 3.0)) == 0
    quad = np.array([[0, 0], [2, -4], [4, 0], [2, 4]], dtype=np.float64)  # two quadratics
    subs = np.array([[0, 2, 1]], dtype=np.int32)
    assert core.winding_number(quad, np.array([2, 2], dtype=np.int32), subs, (2.0, 0.0)) == s
    # rays through vertices: the reflex vertex (4, 2) of an arrowhead (both edges below the
    # ray: no crossing there), and the top vertex of a diamond (one edge above, one below)
    arrow = np.array([[0, 0], [4, 2], [8, 0], [4, 4]], dtype=np.float64)
    one = np.array([[0, 4, 1]], dtype=np.int32)
    assert core.winding_number(arrow, np.ones(4, dtype=np.int32), one, (3.0, 2.0)) == s
    assert core.winding_number(arrow, np.ones(4, dtype=np.int32), one, (1.0, 2.0)) == 0
    # a rounded-rect corner: a cubic leaving (45, 9.5) with a horizontal tangent, closed by lines;
    # the ray from (46, 9.5) runs along that tangent, 0.03 above the curve: outside
    corner = np.array([[45, 9.5], [50.5, 9.5], [55, 12.2], [55, 15.5], [45, 15.5]], dtype=np.float64)
    deg = np.array([3, 1, 1], dtype=np.int32)
    for x, w in [(46.0, 0), (49.5, 0), (56.0, 0), (40.0, 0), (50.0, None)]:
        y = 9.5 if w is not None else 12.0
        expected = s * int(winding_numbers(_fine_polylines(corner, deg, [[0, 3, 1]]),
                                           np.array([[x, y]]))[0])
        assert core.winding_number(corner, deg, np.array([[0, 3, 1]], dtype=np.int32),
                                   (x, y)) == expected, (x, y)
    diamond = np.array([[4, 0], [8, 4], [4, 8], [0, 4]], dtype=np.float64)
    assert core.winding_number(diamond, np.ones(4, dtype=np.int32), one, (2.0, 4.0)) == s
    assert core.winding_number(diamond, np.ones(4, dtype=np.int32), one, (-1.0, 4.0)) == 0


def test_winding_number_beside_curves():
    """Points a hair from a curve, on both sides: the core decides a crossing's side from a
    bracket of its root and sub-pieces' x ranges (csrc/common/bezier.h,
    monotone_crossing_within) rather than a full solve; down to 1e-6 px from the curve
    it must still tell inside from outside. Closed shapes of cubics: a circle's four arcs
    and a lopsided blob with a long flat side, along every segment, ends included."""
    k = 0.5522847498
    circle = np.array([[5, 0], [5, 5 * k], [5 * k, 5], [0, 5], [-5 * k, 5], [-5, 5 * k], [-5, 0],
                       [-5, -5 * k], [-5 * k, -5], [0, -5], [5 * k, -5], [5, -5 * k]], dtype=np.float64)
    blob = np.array([[6, 0], [6, 9], [-7, 3], [-6, 0], [-5, -2], [-1, -2.5], [1, -2.4],
                     [3, -2.3], [6, -6], [6, 0.0]], dtype=np.float64)[:-1]
    for shape, center in ((circle + [0.3, 0.2], np.array([0.3, 0.2])), (blob, np.array([0.0, 0.5]))):
        n = len(shape) // 3
        degrees = np.full(n, 3, dtype=np.int32)
        subpaths = np.array([[0, n, 1]], dtype=np.int32)
        closed = np.concatenate([shape, shape[:1]])
        for g in range(n):
            ctrl = closed[3 * g:3 * g + 4]
            for t in (1e-9, 0.01, 0.125, 0.25, 0.3, 0.5, 0.75, 0.9, 1 - 1e-9):
                b = bezier_eval(ctrl, np.array([t]))[0]
                d = bezier_eval(ctrl, np.array([t + 1e-7]))[0] - bezier_eval(ctrl, np.array([t - 1e-7]))[0]
                normal = np.array([d[1], -d[0]]) / np.hypot(*d)
                if np.dot(normal, b - center) < 0:
                    normal = -normal  # outward (both shapes are star-shaped about `center`)
                for delta in (1e-2, 1e-4, 1e-6):
                    inside = core.winding_number(shape, degrees, subpaths, tuple(b - delta * normal))
                    outside = core.winding_number(shape, degrees, subpaths, tuple(b + delta * normal))
                    assert (abs(inside), outside) == (1, 0), (g, t, delta, inside, outside)


# ==================================================================== polynomial roots
#
# Tolerance. For a simple root r of p = sum c_i t^i, perturbing the coefficients by a relative
# eps moves r by about eps * sum |c_i| |r|^i / |p'(r)| (first-order perturbation bound). A
# backward-stable solver achieves that with eps a small multiple of the unit round-off; we allow
# eps = 1e-12 (~4500 ulps), which covers any sensible solver and numpy.roots' own error, and is
# still far below the separations we require between roots (so matching is unambiguous). On top
# of that we allow 1e-8 absolute (ROOT_ABS): a solver may stop refining on an absolute step or
# residual (the core stops within ~6e-10 of the root 0.01 of 1e-6 - t^3, whose |p'| is 3e-4), and
# nothing downstream (float32 pixel coordinates) resolves t better than ~1e-7. A root
# of multiplicity m moves by about (eps * sum |c_i| |r|^i / |p^(m)(r) / m!|)^(1/m): 1e-8 for a
# double root, 1e-5 for a triple one, hence the looser tolerances on the multiple-root cases.

ROOT_ABS = 1e-8


def _root_tol(coeffs, r, eps=1e-12):
    c = np.asarray(coeffs, dtype=np.float64)
    pw = np.abs(r) ** np.arange(len(c))
    dp = float(np.polyval(np.polyder(c[::-1]), r))
    return eps * float(np.sum(np.abs(c) * pw)) / max(abs(dp), 1e-300) + ROOT_ABS


def _core_roots(coeffs, lo, hi):
    roots = core.polynomial_roots([float(x) for x in coeffs], float(lo), float(hi))
    roots = list(roots)
    assert roots == sorted(roots), "roots are not sorted"
    assert all(lo <= r <= hi for r in roots), f"root outside [{lo}, {hi}]: {roots}"
    return roots


def _match(got, expected, tols):
    got = sorted(got)
    assert len(got) == len(expected), f"roots {got}, expected {expected}"
    for g, e, t in zip(got, sorted(expected), [tols[i] for i in np.argsort(expected)]):
        assert abs(g - e) <= t, f"root {g} vs {e} (tolerance {t:.3g}); all: {got} vs {expected}"


# Coefficients are 0 or of magnitude 1e-6..10: products of coefficients below ~1e-154 underflow
# (a discriminant of 1e-187 (1 + t^2) evaluates to 0), far outside the pixel-scale geometry the
# core solves; the scale range here still spans what squared distances of tiny segments give.
coefficient = st.one_of(st.just(0.0),
                        st.builds(lambda m, e, s: s * m * 10.0 ** e, st.floats(1.0, 10.0),
                                  st.integers(-6, 0), st.sampled_from([1.0, -1.0])))


@st.composite
def random_poly(draw):
    deg = draw(st.integers(0, 5))
    c = [draw(coefficient) for _ in range(deg + 1)]
    lead_zeros = draw(st.integers(0, 5 - deg))
    lo = draw(st.sampled_from([0.0, -1.0, -3.0]))
    hi = draw(st.sampled_from([1.0, 2.0, 3.0]))
    return c + [0.0] * lead_zeros, lo, hi


@pytest.mark.slow
@SETTINGS
@given(case=random_poly())
# Newton landed on the root, and the bisections towards it ran out 2e-8 short of it
@example(case=([6e-06, 0.0, 0.0, 0.0, 0.0, -2.0], 0.0, 3.0))
def test_polynomial_roots_vs_numpy(case):
    coeffs, lo, hi = case
    c = np.trim_zeros(np.array(coeffs, dtype=np.float64), "b")
    assume(len(c) >= 2 and abs(c[-1]) > 1e-3 * np.max(np.abs(c)))  # see the degenerate tests
    z = np.roots(c[::-1])
    # well-conditioned cases only: roots (complex included) separated, nothing near-real and
    # close to the interval that might or might not be a real root, no root at an interval end
    for i in range(len(z)):
        for j in range(i + 1, len(z)):
            assume(abs(z[i] - z[j]) > 1e-3)
    real = []
    for r in z:
        near = lo - 1e-3 <= r.real <= hi + 1e-3
        if abs(r.imag) <= 1e-9 * max(1.0, abs(r)):
            tol = _root_tol(c, r.real)
            assume(abs(r.real - lo) > 10 * tol and abs(r.real - hi) > 10 * tol)
            if lo <= r.real <= hi:
                real.append(r.real)
        else:
            assume(not (near and abs(r.imag) < 1e-4))
    got = _core_roots(coeffs, lo, hi)
    _match(got, real, [_root_tol(c, r) for r in real])


@pytest.mark.slow
@SETTINGS
@given(roots=st.lists(st.floats(-1.0, 2.0), min_size=1, max_size=5),
       k=st.floats(0.01, 100.0), sign=st.sampled_from([1.0, -1.0]))
def test_polynomial_roots_known_roots(roots, k, sign):
    roots = sorted(roots)
    assume(all(b - a > 1e-2 for a, b in zip(roots, roots[1:])))
    c = (sign * k * np.poly(roots))[::-1]  # rounded coefficients: the roots move by _root_tol
    expected = [r for r in roots if 0.0 <= r <= 1.0]
    for r in roots:
        assume(abs(r) > 1e-6 and abs(r - 1.0) > 1e-6)
    got = _core_roots(c, 0.0, 1.0)
    _match(got, expected, [_root_tol(c, r) for r in expected])


def _exact_value(coeffs, t):
    return sum(Fraction(float(ci)) * Fraction(float(t)) ** i for i, ci in enumerate(coeffs))


def _double_root_exists(coeffs, t0, radius=1e-6, n=2001):
    """Whether the polynomial with these (already rounded) coefficients has a real root within
    ``radius`` of t0, decided by exact rational evaluation on a grid (a sign change or a zero)."""
    vals = [_exact_value(coeffs, t) for t in np.linspace(t0 - radius, t0 + radius, n)]
    return any(v == 0 for v in vals) or (min(vals) < 0 < max(vals))


@pytest.mark.parametrize("roots,mult_tol", [
    ([0.25, 0.5, 0.5], 1e-6),            # dyadic: exact coefficients, the double root is real
    ([0.3, 0.3, 0.7], 1e-6),             # rounded coefficients: may split or turn complex
    ([0.125, 0.125, 0.75, 0.75], 1e-6),  # two exact double roots
    ([0.5, 0.5, 0.5], 5e-5),             # triple root, exact coefficients
    ([0.2, 0.2, 0.2, 0.9, 1.7], 5e-5),
])
def test_polynomial_roots_multiple(roots, mult_tol):
    c = np.poly(roots)[::-1]
    got = _core_roots(c, 0.0, 1.0)
    distinct = sorted(set(r for r in roots if 0 <= r <= 1))
    # no spurious roots
    for g in got:
        assert min(abs(g - r) for r in distinct) <= mult_tol, f"spurious root {g}: {got}"
    for r in distinct:
        mult = roots.count(r)
        found = any(abs(g - r) <= (mult_tol if mult > 1 else 1e-9) for g in got)
        if mult == 1 or _double_root_exists(c, r, radius=mult_tol):
            assert found, f"missed the root {r} (multiplicity {mult}): {got}"


def test_polynomial_roots_near_degenerate_leading_coefficient():
    # (t - 0.25)(t - 0.8) plus a tiny cubic term: its third root is near -1e13 / ..., far away;
    # the tiny term moves the two others by about |1e-13 r^3 / p'(r)| < 1e-12.
    base = np.array([0.2, -1.05, 1.0])
    for lead in (1e-13, -1e-13, 1e-17, 1e-300):
        c = list(base) + [lead]
        got = _core_roots(c, 0.0, 1.0)
        _match(got, [0.25, 0.8], [1e-9, 1e-9])
    # quintic with tiny leading terms on top of a linear polynomial
    got = _core_roots([-0.5, 1.0, 0.0, 0.0, 1e-15, 1e-14], 0.0, 1.0)
    _match(got, [0.5], [1e-9])
    # exact leading zeros: degree 5 array holding a quadratic
    got = _core_roots([0.2, -1.05, 1.0, 0.0, 0.0, 0.0], 0.0, 1.0)
    _match(got, [0.25, 0.8], [ROOT_ABS, ROOT_ABS])


def test_polynomial_roots_trivial():
    assert _core_roots([1.0], 0.0, 1.0) == []
    assert _core_roots([0.5, -1.0], 0.0, 1.0) == pytest.approx([0.5])
    assert _core_roots([2.0, -1.0], 0.0, 1.0) == []          # root at 2: outside
    assert _core_roots([1.0, 0.0, 1.0], -10.0, 10.0) == []   # t^2 + 1: no real roots
    got = _core_roots([-0.25, 0.0, 1.0], -1.0, 1.0)           # t^2 = 1/4
    _match(got, [-0.5, 0.5], [ROOT_ABS, ROOT_ABS])
