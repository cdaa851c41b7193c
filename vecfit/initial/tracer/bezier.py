"""Fitting closed outlines with piecewise cubic Béziers.

Corners are found on a lightly smoothed copy of each outline (the raw outline is a pixel
staircase, where every step looks like a corner). The outline is cut at its corners (or,
without corners, in two halves) into stretches; each stretch is smoothed on its own with
its ends held, so corners stay sharp, and fitted by least squares with fixed end tangents
(after Schneider, "An algorithm for automatically fitting digitized curves", Graphics
Gems 1990), reparameterised by Newton steps and split at the worst point until the error
is within tolerance. Pieces meet with a shared tangent except at corners.

A traced image has a thousand outlines and thousands of stretches of a few dozen points
each, so everything runs on all of them at once: the outlines laid end to end (Loops)
are cleaned, smoothed and cut together, and the fitting goes one level of splitting at
a time (arrays of pieces rather than a recursion per piece): per-call overhead, not
arithmetic, is what costs here.
"""
from __future__ import annotations

import numpy as np

NEWTON_STEPS = 4
NEWTON_RANGE = 4.0  # try reparameterising only when the error is within this many tolerances
MAX_TURN = np.radians(200)  # most a single cubic may turn (a half circle is 180)
TANGENT_REACH = 2.0  # pixels either side from which a tangent is taken


# ------------------------------------------------------- all outlines, cut at corners

def _unit(v: np.ndarray) -> np.ndarray:
    n = np.hypot(v[..., 0], v[..., 1])[..., None]
    return np.where(n > 1e-12, v / np.maximum(n, 1e-12), np.array([1.0, 0.0]))


class Loops:
    """Closed polylines stored end to end (points [M, 2]), with each point's outline and
    its neighbours along it, so that per-outline work runs on all outlines at once."""

    def __init__(self, points: np.ndarray, lengths: np.ndarray):
        self.points, self.lengths = points, lengths
        self.first = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
        self.owner = np.repeat(np.arange(len(lengths)), lengths)
        self.pos = np.arange(len(points)) - self.first[self.owner]

    def shifted(self, by: int, rows=None) -> np.ndarray:
        """Index of the point `by` places further along each point's own loop (of the
        points `rows`, all by default)."""
        owner = self.owner if rows is None else self.owner[rows]
        pos = self.pos if rows is None else self.pos[rows]
        return self.first[owner] + (pos + by) % self.lengths[owner]

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


def find_corners(loops: Loops, s: np.ndarray, window: int, corner_angle: float) -> list[np.ndarray]:
    """For each loop, the indices where it turns sharper than corner_angle (degrees; 180
    is straight): the angle at s[i] between s[i - window] and s[i + window], kept where it
    is the sharpest within the window (loops under 4 windows long have none)."""
    a = s[loops.shifted(-window)] - s
    b = s[loops.shifted(window)] - s
    cos = (a * b).sum(1) / np.maximum(np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), 1e-12)
    angle = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    sharpest = angle.copy()
    for j in range(-window, window + 1):
        np.minimum(sharpest, angle[loops.shifted(j)], out=sharpest)
    long_enough = (loops.lengths >= 4 * window)[loops.owner]
    cand = np.flatnonzero((angle < corner_angle) & (angle <= sharpest) & long_enough)
    out = [[] for _ in loops.lengths]
    for i, o, p in zip(cand.tolist(), loops.owner[cand].tolist(), loops.pos[cand].tolist()):
        keep = out[o]  # of equal minima (a plateau) within a window keep the first
        if not keep or p - keep[-1] > window:
            keep.append(p)
    for o, keep in enumerate(out):
        if len(keep) > 1 and keep[-1] - keep[0] > loops.lengths[o] - window - 1:
            keep.pop()
    return [np.array(keep, int) for keep in out]


def apexes(loops: Loops, owner: np.ndarray, corners: np.ndarray, window: int) -> np.ndarray:
    """For each corner (its loop and index in it), the index of the vertex near it that
    sticks out furthest from the chord p[i - window] to p[i + window]: where the corner
    of the unsmoothed outline really is (smoothing blunts a corner, and the sharpest
    smoothed angle can sit a vertex or two off)."""
    n = loops.lengths[owner]
    local = (corners[:, None] + np.arange(-window, window + 1)) % n[:, None]  # [C, 2w+1]
    idx = loops.first[owner][:, None] + local
    p = loops.points
    a, b = p[idx[:, 0]], p[idx[:, -1]]
    d = b - a
    dist = np.abs(d[:, :1] * (p[idx, 1] - a[:, 1:]) - d[:, 1:] * (p[idx, 0] - a[:, :1]))
    return local[np.arange(len(idx)), dist.argmax(1)]


def cut_outlines(loops: Loops, sigma: float, window: int, corner_angle: float, reach: int):
    """Every outline cut into stretches. Returns the stretches' points laid end to end,
    their lengths, their outline, and their given end tangents (NaN where none is given).

    A corner end has no tangent (the stretch's own points give it); an outline without
    corners is cut in two halves joined smoothly, whose cuts take the tangent of the
    smoothed outline, shared by both sides, and the smoothed point. Corners are judged
    `reach` points either side, on a copy smoothed only half as much: smoothing rounds a
    corner, which makes it look blunter than it is (a right angle measures about 100
    degrees this way, and the right-angled tip of a 45-degree staircase about 112; a
    staircase along an edge stays above 165)."""
    p, first, lengths = loops.points, loops.first, loops.lengths
    corners = find_corners(loops, loops.smoothed(sigma / 2), reach, corner_angle)
    with_corners = np.array([len(c) > 0 for c in corners], bool)
    # corner outlines: from each apex to the next, the last one round to the first
    owner = np.repeat(np.arange(len(corners)), [len(c) for c in corners])
    at = apexes(loops, owner, np.concatenate(corners + [np.zeros(0, int)]), reach) if len(owner) else owner
    key = np.unique(first[owner] + at)            # sorted by outline, then index; distinct
    c_owner = loops.owner[key]
    c_at = key - first[c_owner]
    last_of = np.r_[c_owner[1:] != c_owner[:-1], True]
    first_of = np.r_[True, c_owner[1:] != c_owner[:-1]]
    wrap_to = np.maximum.accumulate(np.where(first_of, np.arange(len(key)), 0))  # each one's first
    c_end = np.where(last_of, c_at[wrap_to] + lengths[c_owner], np.r_[c_at[1:], 0])
    # smooth outlines: two halves
    smooth = np.flatnonzero(~with_corners)
    n = lengths[smooth]
    half = n // 2
    cs = loops.smoothed(sigma, ~with_corners)
    tw = np.maximum(1, np.minimum(window, n // 4))
    at0 = first[smooth]
    t0 = _unit(cs[at0 + tw % n] - cs[at0 + (-tw) % n])
    th = _unit(cs[at0 + (half + tw) % n] - cs[at0 + half - tw])
    # all stretches, in order of outline, then along it
    s_owner = np.concatenate([c_owner, smooth, smooth])
    s_start = np.concatenate([c_at, np.zeros_like(half), half])
    s_end = np.concatenate([c_end, half, n])
    nan = np.full((len(c_owner), 2), np.nan)
    s_t1 = np.concatenate([nan, t0, th])
    s_t2 = np.concatenate([nan, -th, -t0])
    order = np.lexsort((s_start, s_owner))
    s_owner, s_start, s_end, s_t1, s_t2 = (x[order] for x in (s_owner, s_start, s_end, s_t1, s_t2))
    s_len = s_end - s_start + 1
    offset = np.concatenate([[0], np.cumsum(s_len)[:-1]])
    stretch = np.repeat(np.arange(len(s_len)), s_len)
    local = (s_start[stretch] + np.arange(s_len.sum()) - offset[stretch]) % lengths[s_owner][stretch]
    points = p[first[s_owner][stretch] + local]
    # the cuts of a smooth outline sit at its smoothed points
    given = ~np.isnan(s_t1[:, 0])
    ends = np.concatenate([offset[given], (offset + s_len - 1)[given]])
    ends_local = np.concatenate([s_start[given], s_end[given]]) % np.tile(lengths[s_owner[given]], 2)
    points[ends] = cs[first[np.concatenate([s_owner[given], s_owner[given]])] + ends_local]
    return points, s_len, s_owner, s_t1, s_t2


# ------------------------------------------------------------ all stretches at once

class Stretches:
    """Many open polylines stored end to end: points [M, 2], and for each stretch the
    index of its first point and its length."""

    def __init__(self, points: np.ndarray, lengths: np.ndarray):
        self.lengths = lengths.astype(np.int64)
        self.first = np.concatenate([[0], np.cumsum(self.lengths)[:-1]]).astype(np.int64)
        self.points = points
        self.owner = np.repeat(np.arange(len(lengths)), self.lengths)     # stretch of each point
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


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product of [N, 2] arrays (what (a * b).sum(1) gives, without a
    reduction over an axis of 2, which costs several times the arithmetic)."""
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]


def _basis(u: np.ndarray):
    mu = 1 - u
    return mu * mu * mu, 3 * mu * mu * u, 3 * mu * u * u, u * u * u


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


def _medians(values: np.ndarray, group: np.ndarray, valid: np.ndarray, wanted: np.ndarray) -> np.ndarray:
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


def fit_outlines(outlines: list[np.ndarray], tolerance: float, corner_angle: float,
                 smoothing: float = 1.0, corner_window: float = 3.0) -> list[np.ndarray]:
    """Cubic segments [S, 4, 2] of each closed outline (each segment starts where the
    previous one ends, the last ends at the first's start). Outlines: [N, 2] points,
    evenly spaced and all alike (the tracer's have a vertex every half pixel).

    The outline is smoothed (Gaussian, sigma `smoothing` pixels) to iron out the pixel
    staircase, and the fit is to the smoothed copy, so the staircase does not eat into
    the tolerance. corner_window (pixels) is how far either side the corner angle is
    measured."""
    result = [np.zeros((0, 4, 2)) for _ in outlines]
    if not outlines:
        return result
    raw = Loops(np.concatenate(outlines).astype(float, copy=False), np.array([len(o) for o in outlines]))
    keep = np.any(raw.points != raw.points[raw.shifted(-1)], axis=1)  # outlines may touch themselves
    alike = (np.bincount(raw.owner[keep], minlength=len(outlines)) == 0) & (raw.lengths > 0)
    keep[raw.first[alike]] = True  # an outline of one point repeated: that point
    lengths = np.bincount(raw.owner[keep], minlength=len(outlines))
    cleaned = Loops(raw.points[keep], lengths)
    spacing = _medians(np.hypot(*np.diff(cleaned.points, axis=0).T), cleaned.owner[1:],
                       cleaned.pos[1:] > 0, lengths >= 3)
    step = float(np.median(spacing)) if len(spacing) else 1.0
    step = step if step > 0 else 1.0
    sigma = smoothing / step
    window = max(1, int(round(TANGENT_REACH / step)))
    reach = max(1, int(round(corner_window / step)))
    used = np.flatnonzero(lengths >= 3)
    if not len(used):
        return result
    rows = np.isin(cleaned.owner, used)
    loops = Loops(cleaned.points[rows], lengths[used])
    points, lengths, owner, given1, given2 = cut_outlines(loops, sigma, window, corner_angle, reach)
    st = Stretches(points, lengths)
    s = st.smoothed(sigma)
    tangents = st.tangents(s, window)
    # end tangents at corners look TANGENT_REACH along the stretch, past the corner's own
    # rounding; smooth cuts use the tangent they were given
    m = np.minimum(window, st.lengths - 1)
    first, last = st.first, st.first + st.lengths - 1
    given = ~np.isnan(given1[:, 0])
    t1 = np.where(given[:, None], given1, _unit(s[first + m] - s[first]))
    t2 = np.where(given[:, None], given2, _unit(s[last - m] - s[last]))
    ctrl, stretch_of = _fit_all(st, s, tangents, t1, t2, tolerance)
    outline_of = owner[stretch_of]  # sorted: stretches are in outline order
    bounds = np.searchsorted(outline_of, np.arange(len(used) + 1))
    for k, i in enumerate(used.tolist()):
        result[i] = ctrl[bounds[k]:bounds[k + 1]]
    return result


def fit_closed(points: np.ndarray, tolerance: float, corner_angle: float,
               smoothing: float = 1.0, corner_window: float = 3.0) -> np.ndarray:
    """Cubic segments [S, 4, 2] of one closed outline (see fit_outlines)."""
    return fit_outlines([points], tolerance, corner_angle, smoothing, corner_window)[0]


def bezier_at(ctrl: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Points of the cubic with control points ctrl [4, 2] at parameters u."""
    b0, b1, b2, b3 = _basis(np.asarray(u, float))
    return np.outer(b0, ctrl[0]) + np.outer(b1, ctrl[1]) + np.outer(b2, ctrl[2]) + np.outer(b3, ctrl[3])
