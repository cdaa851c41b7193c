"""Fitting closed outlines with piecewise cubic Béziers.

Corners are found on a lightly smoothed copy of each outline (the raw outline is a pixel
staircase, where every step looks like a corner). The outline is cut at its corners (or,
without corners, in two halves) into stretches; each stretch is smoothed on its own with
its ends held, so corners stay sharp, and fitted by least squares with fixed end tangents
(after Schneider, "An algorithm for automatically fitting digitized curves", Graphics
Gems 1990), reparameterised by Newton steps and split at the worst point until the error
is within tolerance. Pieces meet with a shared tangent except at corners.

A traced image has thousands of stretches of a few dozen points each, so the fitting
runs on all of them at once, one level of splitting at a time (arrays of pieces rather
than a recursion per piece): per-call overhead, not arithmetic, is what costs here.
"""
from __future__ import annotations

import numpy as np
from scipy.ndimage import minimum_filter1d

NEWTON_STEPS = 4
NEWTON_RANGE = 4.0  # try reparameterising only when the error is within this many tolerances
MAX_TURN = np.radians(200)  # most a single cubic may turn (a half circle is 180)
TANGENT_REACH = 2.0  # pixels either side from which a tangent is taken


# ------------------------------------------------------------------ one outline at a time

def smooth_closed(p: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian smoothing of a closed polyline, sigma in samples."""
    if sigma <= 0 or len(p) < 5:
        return p.copy()
    r = int(min(3 * sigma + 1, (len(p) - 1) // 2))
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    k /= k.sum()
    ext = np.concatenate([p[-r:], p, p[:r]]) if r else p
    return np.stack([np.convolve(ext[:, d], k, mode="valid") for d in range(2)], 1)


def find_corners(s: np.ndarray, window: int, corner_angle: float) -> np.ndarray:
    """Indices where the outline turns sharper than corner_angle (degrees; 180 is
    straight): the angle at s[i] between s[i - window] and s[i + window], kept where it
    is the sharpest within the window."""
    n = len(s)
    if n < 4 * window:
        return np.zeros(0, int)
    a = np.roll(s, window, 0) - s
    b = np.roll(s, -window, 0) - s
    cos = (a * b).sum(1) / np.maximum(np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), 1e-12)
    angle = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    sharpest = minimum_filter1d(angle, 2 * window + 1, mode="wrap")
    cand = np.flatnonzero((angle < corner_angle) & (angle <= sharpest))
    keep = []
    for i in cand:  # of equal minima (a plateau) within a window keep the first
        if not keep or i - keep[-1] > window:
            keep.append(i)
    if len(keep) > 1 and keep[-1] - keep[0] > n - window - 1:
        keep.pop()
    return np.array(keep, int)


def apexes(p: np.ndarray, corners: np.ndarray, window: int) -> np.ndarray:
    """For each corner index i, the vertex near it that sticks out furthest from the
    chord p[i - window] to p[i + window]: where the corner of the unsmoothed outline
    really is (smoothing blunts a corner, and the sharpest smoothed angle can sit a
    vertex or two off)."""
    idx = (corners[:, None] + np.arange(-window, window + 1)) % len(p)  # [C, 2w+1]
    a, b = p[idx[:, 0]], p[idx[:, -1]]
    d = b - a
    dist = np.abs(d[:, :1] * (p[idx, 1] - a[:, 1:]) - d[:, 1:] * (p[idx, 0] - a[:, :1]))
    return idx[np.arange(len(idx)), dist.argmax(1)]


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.hypot(v[..., 0], v[..., 1])[..., None]
    return np.where(n > 1e-12, v / np.maximum(n, 1e-12), np.array([1.0, 0.0]))


def cut_outline(p: np.ndarray, sigma: float, window: int, corner_angle: float, reach: int):
    """An outline cut into stretches: a list of (points, start tangent or None, end
    tangent or None). A corner end has no tangent (the stretch's own points give it);
    a smooth cut gives the tangent of the smoothed outline, shared by both sides, and
    its point is the smoothed one. Corners are judged `reach` points either side, on a
    copy smoothed only half as much: smoothing rounds a corner, which makes it look
    blunter than it is (a right angle measures about 100 degrees this way, and the
    right-angled tip of a 45-degree staircase about 112; a staircase along an edge
    stays above 165)."""
    n = len(p)
    closed_s = smooth_closed(p, sigma)
    corners = find_corners(smooth_closed(p, sigma / 2), reach, corner_angle)
    if len(corners):
        corners = np.unique(apexes(p, corners, reach))
        bounds = np.append(corners, corners[0] + n)
        return [(p[np.arange(a, b + 1) % n], None, None) for a, b in zip(bounds[:-1], bounds[1:])]
    # no corner: two halves joined smoothly
    tw = max(1, min(window, n // 4))
    half = n // 2
    t0 = _unit(closed_s[tw % n] - closed_s[-tw % n])
    th = _unit(closed_s[(half + tw) % n] - closed_s[half - tw])
    out = []
    for a, b, ta, tb in ((0, half, t0, th), (half, n, th, t0)):
        raw = p[np.arange(a, b + 1) % n].copy()
        raw[0], raw[-1] = closed_s[a % n], closed_s[b % n]
        out.append((raw, ta, -tb))
    return out


# ------------------------------------------------------------ all stretches at once

class Stretches:
    """Many open polylines stored end to end: points [M, 2], and for each stretch the
    index of its first point and its length."""

    def __init__(self, parts: list[np.ndarray]):
        self.lengths = np.array([len(q) for q in parts], np.int64)
        self.first = np.concatenate([[0], np.cumsum(self.lengths)[:-1]]).astype(np.int64)
        self.points = np.concatenate(parts) if parts else np.zeros((0, 2))
        self.owner = np.repeat(np.arange(len(parts)), self.lengths)      # stretch of each point
        self.pos = np.arange(len(self.points)) - self.first[self.owner]  # index within it

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
        base = ext_first[self.owner] + self.pos  # where each point's window begins in ext
        out = np.zeros_like(p)
        for j, w in enumerate(k):
            out += w * ext[base + j]
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


def _basis(u: np.ndarray):
    mu = 1 - u
    return mu * mu * mu, 3 * mu * mu * u, 3 * mu * u * u, u * u * u


class _Pieces:
    """The pieces being fitted: index ranges [a, b] into the stretch points with their
    end tangents, and for each point of every piece (pieces laid end to end) its index
    into the points and the piece it belongs to."""

    def __init__(self, a, b, t1, t2):
        self.a, self.b, self.t1, self.t2 = a, b, t1, t2
        n = b - a + 1
        self.piece = np.repeat(np.arange(len(a)), n)
        self.starts = np.concatenate([[0], np.cumsum(n)[:-1]]).astype(np.int64)
        self.idx = a[self.piece] + np.arange(len(self.piece)) - self.starts[self.piece]

    def sums(self, v: np.ndarray) -> np.ndarray:
        return np.add.reduceat(v, self.starts, axis=0)


def _least_squares(P, pc: _Pieces, u, length):
    """For each piece, the cubic from its first to its last point along its end tangents
    whose handle lengths best fit its points at parameters u; wild solutions (handles
    backwards or far out, which make loops) fall back to thirds of the chord."""
    p0, p3 = P[pc.a], P[pc.b]
    i = pc.piece
    b0, b1, b2, b3 = _basis(u)
    rest = P[pc.idx] - (b0 + b1)[:, None] * p0[i] - (b2 + b3)[:, None] * p3[i]
    c11, c22 = pc.sums(b1 * b1), pc.sums(b2 * b2)
    c12 = pc.sums(b1 * b2) * (pc.t1 * pc.t2).sum(1)
    x1 = pc.sums(b1 * (rest * pc.t1[i]).sum(1))
    x2 = pc.sums(b2 * (rest * pc.t2[i]).sum(1))
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


def _errors(P, pc: _Pieces, u, ctrl):
    c = ctrl[pc.piece]
    b0, b1, b2, b3 = _basis(u)
    at = b0[:, None] * c[:, 0] + b1[:, None] * c[:, 1] + b2[:, None] * c[:, 2] + b3[:, None] * c[:, 3]
    return ((at - P[pc.idx]) ** 2).sum(1), at


def _newton(P, pc: _Pieces, u, ctrl, at):
    """One Newton step per point towards the parameter of its closest curve point."""
    c = ctrl[pc.piece]
    d1 = 3 * (c[:, 1:] - c[:, :-1])
    d2 = 2 * (d1[:, 1:] - d1[:, :-1])
    mu = (1 - u)[:, None]
    uu = u[:, None]
    q1 = mu * mu * d1[:, 0] + 2 * mu * uu * d1[:, 1] + uu * uu * d1[:, 2]
    q2 = mu * d2[:, 0] + uu * d2[:, 1]
    diff = at - P[pc.idx]
    num = (diff * q1).sum(1)
    den = (q1 * q1).sum(1) + (diff * q2).sum(1)
    ok = np.abs(den) > 1e-12
    u = np.clip(u - np.where(ok, num / np.where(ok, den, 1.0), 0.0), 0, 1)
    ends = (pc.idx == pc.a[pc.piece]) | (pc.idx == pc.b[pc.piece])
    return np.where(ends, np.where(pc.idx == pc.a[pc.piece], 0.0, 1.0), u)


def _fit_level(P, heading, cum, a, b, t1, t2, tol):
    """Fit every piece once (P: the points, heading: unwrapped tangent angle at each,
    cum: arc length up to each). Returns (accepted: mask, control points [K, 4, 2],
    where to split each piece that was not accepted)."""
    pc = _Pieces(a, b, t1, t2)
    n = b - a + 1
    length = cum[b] - cum[a]
    u = (cum[pc.idx] - cum[a][pc.piece]) / np.maximum(length, 1e-12)[pc.piece]
    ctrl = _least_squares(P, pc, u, length)
    err, at = _errors(P, pc, u, ctrl)
    tol2 = tol * tol
    worst = np.maximum.reduceat(err, pc.starts)
    retry = (worst > tol2) & (worst < NEWTON_RANGE ** 2 * tol2)
    if retry.any():
        # reparameterise only the pieces close to the tolerance, keeping improvements
        sub = _Pieces(a[retry], b[retry], t1[retry], t2[retry])
        pts = retry[pc.piece]
        su, serr, sat = u[pts], err[pts], at[pts]
        sctrl, sworst, slen = ctrl[retry], worst[retry], length[retry]
        for _ in range(NEWTON_STEPS):
            u2 = _newton(P, sub, su, sctrl, sat)
            ctrl2 = _least_squares(P, sub, u2, slen)
            err2, at2 = _errors(P, sub, u2, ctrl2)
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
    best_first = np.lexsort((-score, pc.piece))  # per piece, its best point first
    split = np.clip(pc.idx[best_first[pc.starts]], a + 1, np.maximum(b - 1, a + 1))
    return accepted, ctrl, split


def fit_stretches(st: Stretches, s: np.ndarray, tangents: np.ndarray, t1, t2,
                  tol: float) -> list[np.ndarray]:
    """Cubic segments [K, 4, 2] for each stretch, fitted to its points in s (laid out as
    in st) with end tangents t1 (leaving the first point) and t2 (arriving at the last,
    pointing back into the stretch); tangents: the forward tangent at every point, used
    where a stretch is split. Each level fits all open pieces at once, keeps those within
    tolerance and splits the others in two for the next level."""
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
        return [np.zeros((0, 4, 2)) for _ in range(count)]
    ctrl = np.concatenate(done_ctrl)
    start = np.concatenate(done_start)
    own = np.concatenate(done_owner)
    order = np.lexsort((start, own))
    ctrl, own = ctrl[order], own[order]
    bounds = np.searchsorted(own, np.arange(count + 1))
    return [ctrl[bounds[i]:bounds[i + 1]] for i in range(count)]


def fit_outlines(outlines: list[np.ndarray], tolerance: float, corner_angle: float,
                 smoothing: float = 1.0, corner_window: float = 3.0) -> list[np.ndarray]:
    """Cubic segments [S, 4, 2] of each closed outline (each segment starts where the
    previous one ends, the last ends at the first's start). Outlines: [N, 2] points,
    evenly spaced and all alike (the tracer's have a vertex every half pixel).

    The outline is smoothed (Gaussian, sigma `smoothing` pixels) to iron out the pixel
    staircase, and the fit is to the smoothed copy, so the staircase does not eat into
    the tolerance. corner_window (pixels) is how far either side the corner angle is
    measured."""
    cleaned = []
    for points in outlines:
        keep = np.any(points != np.roll(points, 1, 0), axis=1)  # outlines may touch themselves
        cleaned.append(points[keep] if keep.any() else points[:1])
    spacing = [np.median(np.hypot(*np.diff(p, axis=0).T)) for p in cleaned if len(p) >= 3]
    step = float(np.median(spacing)) if spacing else 1.0
    step = step if step > 0 else 1.0
    sigma = smoothing / step
    window = max(1, int(round(TANGENT_REACH / step)))
    reach = max(1, int(round(corner_window / step)))
    parts, given1, given2, owner = [], [], [], []
    for i, p in enumerate(cleaned):
        if len(p) < 3:
            continue
        for q, ta, tb in cut_outline(p, sigma, window, corner_angle, reach):
            parts.append(q)
            given1.append(ta)
            given2.append(tb)
            owner.append(i)
    result = [np.zeros((0, 4, 2)) for _ in outlines]
    if not parts:
        return result
    st = Stretches(parts)
    s = st.smoothed(sigma)
    tangents = st.tangents(s, window)
    # end tangents at corners look TANGENT_REACH along the stretch, past the corner's own
    # rounding; smooth cuts use the tangent they were given
    m = np.minimum(window, st.lengths - 1)
    first, last = st.first, st.first + st.lengths - 1
    t1 = _unit(s[first + m] - s[first])
    t2 = _unit(s[last - m] - s[last])
    for j, (ta, tb) in enumerate(zip(given1, given2)):
        if ta is not None:
            t1[j], t2[j] = ta, tb
    fitted = fit_stretches(st, s, tangents, t1, t2, tolerance)
    for j, segs in enumerate(fitted):
        i = owner[j]
        result[i] = np.concatenate([result[i], segs])
    return result


def fit_closed(points: np.ndarray, tolerance: float, corner_angle: float,
               smoothing: float = 1.0, corner_window: float = 3.0) -> np.ndarray:
    """Cubic segments [S, 4, 2] of one closed outline (see fit_outlines)."""
    return fit_outlines([points], tolerance, corner_angle, smoothing, corner_window)[0]


def bezier_at(ctrl: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Points of the cubic with control points ctrl [4, 2] at parameters u."""
    b0, b1, b2, b3 = _basis(np.asarray(u, float))
    return np.outer(b0, ctrl[0]) + np.outer(b1, ctrl[1]) + np.outer(b2, ctrl[2]) + np.outer(b3, ctrl[3])
