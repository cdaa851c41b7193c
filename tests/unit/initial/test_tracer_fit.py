"""The tracer's Bézier fit in the compiled core (csrc/trace/fit.cpp) gives, bit for bit,
what the NumPy fit it replaced gave (kept here as the reference): on the outlines of a
photo's colour regions, raw and moved off the pixel grid, at several tolerances, and on
smooth and sharp synthetic curves; likewise the stretches' smoothing and tangents and
the loops' smoothing, the sliding minimum of corner angles and the spacing medians; and
bad input is refused."""
from __future__ import annotations

import numpy as np
import pytest
import skimage.data

from vecfit import _core
from vecfit.initial.tracer import bezier
from vecfit.initial.tracer.bezier import (MAX_TURN, NEWTON_RANGE, NEWTON_STEPS, Loops, Stretches, _medians,
                                          _unit, fit_outlines)
from vecfit.initial.tracer.outlines import crack_outlines
from vecfit.initial.tracer.quantize import quantize_colors

from helpers import slow_unless


# ----------------------------------------------- the NumPy fit, as bezier.py had it

def _basis(u):
    mu = 1 - u
    return mu * mu * mu, 3 * mu * mu * u, 3 * mu * u * u, u * u * u


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product of [N, 2] arrays (what (a * b).sum(1) gives, without a
    reduction over an axis of 2, which costs several times the arithmetic)."""
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]


class _Pieces:
    """The pieces being fitted: index ranges [a, b] into the stretch points P with their
    end tangents, and for each point of every piece (pieces laid end to end) its index
    into the points and the piece it belongs to. What every fitting step reads per point
    (the point, its piece's ends and tangents) is gathered once here."""

    def __init__(self, P, a, b, t1, t2):
        self.a, self.b, self.t1, self.t2 = a, b, t1, t2
        n = b - a + 1
        self.piece = np.repeat(np.arange(len(a)), n)
        self.starts = np.concatenate([[0], np.cumsum(n)[:-1]]).astype(np.int64)
        self.idx = a[self.piece] + np.arange(len(self.piece)) - self.starts[self.piece]
        i = self.piece
        self.p0, self.p3 = P[a], P[b]
        self.points = P[self.idx]
        self.p0_at, self.p3_at = self.p0[i], self.p3[i]
        self.t1_at, self.t2_at = t1[i], t2[i]
        self.first = self.idx == a[i]
        self.end = self.first | (self.idx == b[i])

    def sums(self, v: np.ndarray) -> np.ndarray:
        return np.add.reduceat(v, self.starts, axis=0)


def _least_squares(pc: _Pieces, basis, length):
    """For each piece, the cubic from its first to its last point along its end tangents
    whose handle lengths best fit its points at parameters u (basis: the Bernstein basis
    at u); wild solutions (handles backwards or far out, which make loops) fall back to
    thirds of the chord."""
    p0, p3 = pc.p0, pc.p3
    b0, b1, b2, b3 = basis
    rest = pc.points - (b0 + b1)[:, None] * pc.p0_at - (b2 + b3)[:, None] * pc.p3_at
    c11, c22 = pc.sums(b1 * b1), pc.sums(b2 * b2)
    c12 = pc.sums(b1 * b2) * (pc.t1 * pc.t2).sum(1)
    x1 = pc.sums(b1 * _dot(rest, pc.t1_at))
    x2 = pc.sums(b2 * _dot(rest, pc.t2_at))
    det = c11 * c22 - c12 * c12
    ok = np.abs(det) > 1e-12
    safe = np.where(ok, det, 1.0)
    al1 = np.where(ok, (x1 * c22 - x2 * c12) / safe, -1.0)
    al2 = np.where(ok, (c11 * x2 - c12 * x1) / safe, -1.0)
    chord = np.hypot(*(p3 - p0).T)
    low, high = 1e-3 * np.maximum(chord, 1e-9), np.maximum(2 * chord, length)
    wild = ~((low < al1) & (al1 < high) & (low < al2) & (al2 < high))
    al1 = np.where(wild, chord / 3, al1)
    al2 = np.where(wild, chord / 3, al2)
    return np.stack([p0, p0 + al1[:, None] * pc.t1, p3 + al2[:, None] * pc.t2, p3], 1)


def _errors(pc: _Pieces, basis, ctrl):
    c = ctrl[pc.piece]
    b0, b1, b2, b3 = basis
    at = b0[:, None] * c[:, 0] + b1[:, None] * c[:, 1] + b2[:, None] * c[:, 2] + b3[:, None] * c[:, 3]
    d = at - pc.points
    return _dot(d, d), at


def _newton(pc: _Pieces, u, ctrl, at):
    """One Newton step per point towards the parameter of its closest curve point."""
    c = ctrl[pc.piece]
    d1 = 3 * (c[:, 1:] - c[:, :-1])
    d2 = 2 * (d1[:, 1:] - d1[:, :-1])
    mu = (1 - u)[:, None]
    uu = u[:, None]
    q1 = mu * mu * d1[:, 0] + 2 * mu * uu * d1[:, 1] + uu * uu * d1[:, 2]
    q2 = mu * d2[:, 0] + uu * d2[:, 1]
    diff = at - pc.points
    num = _dot(diff, q1)
    den = _dot(q1, q1) + _dot(diff, q2)
    ok = np.abs(den) > 1e-12
    u = np.clip(u - np.where(ok, num / np.where(ok, den, 1.0), 0.0), 0, 1)
    return np.where(pc.end, np.where(pc.first, 0.0, 1.0), u)


def _fit_level(P, heading, cum, a, b, t1, t2, tol):
    """Fit every piece once (P: the points, heading: unwrapped tangent angle at each,
    cum: arc length up to each). Returns (accepted: mask, control points [K, 4, 2],
    where to split each piece that was not accepted)."""
    pc = _Pieces(P, a, b, t1, t2)
    n = b - a + 1
    length = cum[b] - cum[a]
    u = (cum[pc.idx] - cum[a][pc.piece]) / np.maximum(length, 1e-12)[pc.piece]
    basis = _basis(u)
    ctrl = _least_squares(pc, basis, length)
    err, at = _errors(pc, basis, ctrl)
    tol2 = tol * tol
    worst = np.maximum.reduceat(err, pc.starts)
    retry = (worst > tol2) & (worst < NEWTON_RANGE ** 2 * tol2)
    if retry.any():
        # reparameterise only the pieces close to the tolerance, keeping improvements
        sub = _Pieces(P, a[retry], b[retry], t1[retry], t2[retry])
        pts = retry[pc.piece]
        su, serr, sat = u[pts], err[pts], at[pts]
        sctrl, sworst, slen = ctrl[retry], worst[retry], length[retry]
        for _ in range(NEWTON_STEPS):
            u2 = _newton(sub, su, sctrl, sat)
            basis2 = _basis(u2)
            ctrl2 = _least_squares(sub, basis2, slen)
            err2, at2 = _errors(sub, basis2, ctrl2)
            worst2 = np.maximum.reduceat(err2, sub.starts)
            better = worst2 < sworst
            bp = better[sub.piece]
            su, serr = np.where(bp, u2, su), np.where(bp, err2, serr)
            sat = np.where(bp[:, None], at2, sat)
            sctrl[better], sworst[better] = ctrl2[better], worst2[better]
            if (sworst <= tol2).all():
                break
        err[pts], ctrl[retry], worst[retry] = serr, sctrl, sworst
    # a piece that turns too far is split halfway through its turn without being judged
    turn = heading[b] - heading[a]
    looping = (np.abs(turn) > MAX_TURN) & (n > 3)
    accepted = ((worst <= tol2) | (n <= 3)) & ~looping
    # split points: the worst inner point, or the middle of the turn
    inner = (pc.idx != a[pc.piece]) & (pc.idx != b[pc.piece])
    score = np.where(inner, err, -1.0)
    half_turn = np.abs(heading[pc.idx] - heading[a][pc.piece] - turn[pc.piece] / 2)
    score = np.where(looping[pc.piece], np.where(inner, -half_turn, -np.inf), score)
    # per piece, its first point of the highest score
    best = score == np.maximum.reduceat(score, pc.starts)[pc.piece]
    first_best = np.minimum.reduceat(np.where(best, np.arange(len(score)), len(score)), pc.starts)
    split = np.clip(pc.idx[first_best], a + 1, np.maximum(b - 1, a + 1))
    return accepted, ctrl, split


def _fit_all(st: Stretches, s: np.ndarray, tangents: np.ndarray, t1, t2, tol: float):
    """Cubic segments [K, 4, 2] of all stretches, fitted to their points in s (laid out as
    in st) with end tangents t1 (leaving the first point) and t2 (arriving at the last,
    pointing back into the stretch); tangents: the forward tangent at every point, used
    where a stretch is split. Each level fits all open pieces at once, keeps those within
    tolerance and splits the others in two for the next level. Returns the segments in
    order of stretch and along it, and each one's stretch."""
    count = len(st.lengths)
    heading = np.unwrap(np.arctan2(tangents[:, 1], tangents[:, 0]))
    steps = np.hypot(*np.diff(s, axis=0).T) if len(s) > 1 else np.zeros(0)
    cum = np.concatenate([[0.0], np.cumsum(steps)])
    a, b = st.first.copy(), st.first + st.lengths - 1
    owner = np.arange(count)
    done_ctrl, done_start, done_owner = [], [], []
    # two-point pieces are lines; the rest go through the levels of splitting
    while len(a):
        line = b - a < 2
        if line.any():
            p0, p3 = s[a[line]], s[b[line]]
            done_ctrl.append(np.stack([p0, p0 + (p3 - p0) / 3, p3 + (p0 - p3) / 3, p3], 1))
            done_start.append(a[line])
            done_owner.append(owner[line])
            a, b, t1, t2, owner = a[~line], b[~line], t1[~line], t2[~line], owner[~line]
            if not len(a):
                break
        accepted, ctrl, split = _fit_level(s, heading, cum, a, b, t1, t2, tol)
        done_ctrl.append(ctrl[accepted])
        done_start.append(a[accepted])
        done_owner.append(owner[accepted])
        r = ~accepted
        k, tk = split[r], tangents[split[r]]
        a = np.concatenate([a[r], k])
        b = np.concatenate([k, b[r]])
        t1 = np.concatenate([t1[r], tk])
        t2 = np.concatenate([-tk, t2[r]])
        owner = np.concatenate([owner[r], owner[r]])
    if not done_ctrl:
        return np.zeros((0, 4, 2)), np.zeros(0, np.int64)
    ctrl = np.concatenate(done_ctrl)
    start = np.concatenate(done_start)
    own = np.concatenate(done_owner)
    order = np.lexsort((start, own))
    return ctrl[order], own[order]


class ReferenceStretches:
    """bezier.Stretches' smoothing and tangents as NumPy computed them."""

    def __init__(self, points, lengths):
        self.lengths = lengths.astype(np.int64)
        self.first = np.concatenate([[0], np.cumsum(self.lengths)[:-1]]).astype(np.int64)
        self.points = points
        self.owner = np.repeat(np.arange(len(lengths)), self.lengths)
        self.pos = np.arange(len(self.points)) - self.first[self.owner]

    def smoothed(self, sigma: float) -> np.ndarray:
        """Gaussian smoothing of each stretch, its ends held and the stretch extended past
        them by point reflection (which keeps a straight run into a corner straight)."""
        p = self.points
        if sigma <= 0 or len(p) == 0:
            return p.copy()
        r = int(3 * sigma + 1)
        k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
        k /= k.sum()
        # every stretch extended by r points at each end, all laid end to end
        n = self.lengths
        ext_len = n + 2 * r
        ext_first = np.concatenate([[0], np.cumsum(ext_len)[:-1]])
        owner = np.repeat(np.arange(len(n)), ext_len)
        q = np.arange(ext_len.sum()) - ext_first[owner] - r  # index within the stretch
        m = n[owner]
        before, after = q < 0, q >= m
        src = np.clip(np.where(before, -q, np.where(after, 2 * (m - 1) - q, q)), 0, m - 1)
        start = self.first[owner]
        ext = p[start + src]
        ext[before] = 2 * p[start[before]] - ext[before]
        ext[after] = 2 * p[start[after] + m[after] - 1] - ext[after]
        # the weighted sums over every window of ext (contiguous slices), then each
        # point's own window: where it begins in ext
        windows = len(ext) - 2 * r
        acc = np.zeros((windows, 2))
        for j, w in enumerate(k):
            acc += w * ext[j:j + windows]
        out = acc[ext_first[self.owner] + self.pos]
        ends = (self.pos == 0) | (self.pos == n[self.owner] - 1)
        out[ends] = p[ends]
        return out

    def tangents(self, s: np.ndarray, window: int) -> np.ndarray:
        """Unit forward tangent at each point, from the points `window` away along its
        stretch (one-sided near the ends)."""
        n = self.lengths[self.owner]
        start = self.first[self.owner]
        ahead = start + np.minimum(self.pos + window, n - 1)
        behind = start + np.maximum(self.pos - window, 0)
        return _unit(s[ahead] - s[behind])


def reference_medians(values: np.ndarray, group: np.ndarray, valid: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """np.median of the valid values of each group in `wanted` (a mask over the groups),
    in group order, for groups with at least one value."""
    values, group = values[valid], group[valid]
    order = np.lexsort((values, group))
    values, group = values[order], group[order]
    count = np.bincount(group, minlength=len(wanted))
    start = np.concatenate([[0], np.cumsum(count)[:-1]])
    ids = np.flatnonzero(wanted & (count > 0))
    lo = values[start[ids] + (count[ids] - 1) // 2]
    hi = values[start[ids] + count[ids] // 2]
    return np.where(count[ids] % 2 == 1, lo, (lo + hi) / 2)


class ReferenceLoops(Loops):
    """bezier.Loops' smoothing as NumPy computed it."""

    def smoothed(self, sigma: float, which=None) -> np.ndarray:
        """Gaussian smoothing of each loop (sigma in samples; the kernel reaches at most
        half way round, and loops under 5 points stay as they are); of the loops
        `which` (a mask) only, the others left as they are."""
        out = self.points.copy()
        if sigma <= 0:
            return out
        reach = np.minimum(int(3 * sigma + 1), (self.lengths - 1) // 2)
        reach[self.lengths < 5] = 0
        if which is not None:
            reach[~which] = 0
        for r in np.unique(reach[reach > 0]).tolist():
            loops = np.flatnonzero(reach == r)
            k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
            k /= k.sum()
            # the loops, each extended by r points at either end round itself, end to end:
            # every window is then a contiguous slice
            n = self.lengths[loops]
            ext_n = n + 2 * r
            ext_first = np.concatenate([[0], np.cumsum(ext_n)[:-1]])
            which = np.repeat(np.arange(len(loops)), ext_n)
            t = np.arange(ext_n.sum()) - ext_first[which] - r
            ext = self.points[self.first[loops][which] + t % n[which]]
            windows = len(ext) - 2 * r
            acc = np.zeros((windows, 2))
            for j, weight in enumerate(k):
                acc += weight * ext[j:j + windows]
            inside = t >= 0
            inside[t >= n[which]] = False
            rows = self.first[loops][which[inside]] + t[inside]
            out[rows] = acc[np.flatnonzero(inside) - r]
        return out


def reference_window_min(loops, values, window):
    sharpest = values.copy()
    for j in range(-window, window + 1):
        np.minimum(sharpest, values[loops.shifted(j)], out=sharpest)
    return sharpest


# ------------------------------------------------------------------------- the tests

def outlines_of_a_photo(classes=24, crop=(slice(40, 200), slice(100, 300))):
    """The outer outlines of each colour class's regions in a crop of chelsea: pixel
    staircases with a vertex every half pixel, as the tracer fits them."""
    rgb = skimage.data.chelsea()[crop].astype(np.float32) / 255
    labels = quantize_colors(rgb, np.ones(rgb.shape[:2], bool), classes, 0)
    return [o for c in range(classes) for o in crack_outlines(labels == c)]


def fits_with(fit_all, outlines, **settings):
    saved = bezier._fit_all
    bezier._fit_all = fit_all
    try:
        return fit_outlines(outlines, **settings)
    finally:
        bezier._fit_all = saved


def assert_same_fits(outlines, **settings):
    expected = fits_with(_fit_all, outlines, **settings)
    got = fit_outlines(outlines, **settings)
    assert sum(len(c) for c in got) == sum(len(c) for c in expected) > 0
    for g, e in zip(got, expected):
        np.testing.assert_array_equal(g, e)


@pytest.mark.slow
@pytest.mark.parametrize("tolerance", [0.3, 1.0, 2.5])
def test_the_fit_of_a_photos_outlines_is_the_numpy_fits(tolerance):
    outlines = outlines_of_a_photo()
    assert len(outlines) > 200
    assert_same_fits(outlines, tolerance=tolerance, corner_angle=135.0)


@pytest.mark.parametrize("seed", slow_unless(range(3), [0]))
def test_the_fit_of_outlines_off_the_grid_is_the_numpy_fits(seed):
    """Outlines moved by up to half a pixel (as the sub-pixel placement moves them)."""
    rng = np.random.default_rng(seed)
    outlines = [o + rng.uniform(-0.5, 0.5, o.shape) * (rng.random() < 0.7) for o in outlines_of_a_photo(12)]
    assert_same_fits(outlines, tolerance=float(rng.uniform(0.5, 1.5)), corner_angle=float(rng.uniform(100, 170)),
                     smoothing=float(rng.uniform(0, 2)))


def test_the_fit_of_smooth_and_sharp_curves_is_the_numpy_fits():
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)[:, None]
    circle = 50 + 40 * np.hstack([np.cos(t), np.sin(t)])
    spiral_loop = 60 + (20 + 10 * np.sin(5 * t)) * np.hstack([np.cos(t), np.sin(t)])  # turns far
    square = np.concatenate([np.stack([np.arange(0, 20, 0.5), np.zeros(40)], 1),
                             np.stack([np.full(40, 20.0), np.arange(0, 20, 0.5)], 1),
                             np.stack([np.arange(20, 0, -0.5), np.full(40, 20.0)], 1),
                             np.stack([np.zeros(40), np.arange(20, 0, -0.5)], 1)])
    tiny = np.array([[0.0, 0.0], [0.5, 0.0], [0.5, 0.5]])
    assert_same_fits([circle, spiral_loop, square, tiny], tolerance=0.5, corner_angle=135.0)


def test_bad_input_is_refused():
    p = np.zeros((3, 2))
    args = dict(points=p, tangents=p, heading=np.zeros(3), arc=np.zeros(3), t1=np.zeros((1, 2)),
                t2=np.zeros((1, 2)), options=_core.FitOptions(tolerance=1.0, max_turn=float(MAX_TURN),
                                                               newton_range=NEWTON_RANGE, newton_steps=NEWTON_STEPS))
    with pytest.raises(ValueError, match="outside the points"):
        _core.fit_stretches(first=np.array([1]), lengths=np.array([3]), **args)
    with pytest.raises(ValueError, match="expected"):
        _core.fit_stretches(first=np.array([0, 1]), lengths=np.array([3]), **args)


@pytest.mark.parametrize("sigma", [0.5, 2.0, 5.0])
def test_stretch_smoothing_and_tangents_are_numpys(sigma):
    rng = np.random.default_rng(int(sigma * 10))
    lengths = rng.integers(1, 60, 300)
    lengths[:5] = [1, 2, 3, 1, 2]  # stretches shorter than the kernel
    points = np.cumsum(rng.normal(0, 0.5, (lengths.sum(), 2)), 0)
    got, expected = Stretches(points, lengths), ReferenceStretches(points, lengths)
    s = got.smoothed(sigma)
    np.testing.assert_array_equal(s, expected.smoothed(sigma))
    assert np.abs(s - points).max() > 0.1
    for window in (1, 4):
        np.testing.assert_array_equal(got.tangents(s, window), expected.tangents(s, window))


def test_group_medians_are_numpys():
    rng = np.random.default_rng(5)
    group = np.sort(rng.integers(0, 400, 5000))
    values = np.round(rng.normal(0.5, 0.2, 5000), 2)  # ties
    valid, wanted = rng.random(5000) < 0.8, rng.random(400) < 0.7
    got = _medians(values, group, valid, wanted)
    np.testing.assert_array_equal(got, reference_medians(values, group, valid, wanted))
    assert len(got) > 200


@pytest.mark.parametrize("sigma", [0.5, 2.0, 6.0])
def test_loop_smoothing_and_window_minimum_are_numpys(sigma):
    rng = np.random.default_rng(int(sigma * 10))
    lengths = rng.integers(3, 80, 300)
    lengths[:4] = [3, 4, 5, 6]  # under 5 points: left alone; short ones: the kernel reaches half way
    points = np.cumsum(rng.normal(0, 0.5, (lengths.sum(), 2)), 0)
    which = rng.random(300) < 0.6
    got, expected = Loops(points, lengths), ReferenceLoops(points, lengths)
    for mask in (None, which):
        s = got.smoothed(sigma, mask)
        np.testing.assert_array_equal(s, expected.smoothed(sigma, mask))
        assert np.abs(s - points).max() > 0.1
    values = np.round(rng.normal(size=lengths.sum()), 1)
    values[7] = np.nan
    for window in (1, 3, 50):  # 50: round loops shorter than the window
        np.testing.assert_array_equal(_core.loop_window_min(values, got.first, lengths, window),
                                      reference_window_min(got, values, window))
