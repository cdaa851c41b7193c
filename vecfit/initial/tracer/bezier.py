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
are cleaned, smoothed and cut together; the fitting itself, a few dozen points a piece,
runs in the compiled core (csrc/trace/fit.cpp), where NumPy's per-call overhead does not
dominate (it computes what the NumPy version did, bit for bit).
"""
from __future__ import annotations

import numpy as np

from vecfit import _core

NEWTON_STEPS = 4
NEWTON_RANGE = 4.0  # try reparameterising only when the error is within this many tolerances
MAX_TURN = np.radians(200)  # most a single cubic may turn (a half circle is 180)
TANGENT_REACH = 2.0  # pixels either side from which a tangent is taken
EDGE_REACH = 0.5  # an outline with a point this close to the canvas's edge (pixels) touches it
EDGE_TOLERANCE = 0.5  # an outline without corners that touches the canvas's edge is fitted this much closer


# ------------------------------------------------------- all outlines, cut at corners

def _unit(v: np.ndarray) -> np.ndarray:
    n = np.hypot(v[..., 0], v[..., 1])[..., None]
    return np.where(n > 1e-12, v / np.maximum(n, 1e-12), np.array([1.0, 0.0]))


def gaussian_kernel(reach: int, sigma: float) -> np.ndarray:
    """Normalised Gaussian weights of offsets -reach..reach (sigma in samples)."""
    k = np.exp(-0.5 * (np.arange(-reach, reach + 1) / sigma) ** 2)
    return k / k.sum()


class Loops:
    """Closed polylines stored end to end (points [M, 2]), with each point's outline and
    its neighbours along it, so that per-outline work runs on all outlines at once."""

    def __init__(self, points: np.ndarray, lengths: np.ndarray):
        self.points, self.lengths = points, lengths
        self.first = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
        self.owner = np.repeat(np.arange(len(lengths)), lengths)
        self.pos = np.arange(len(points)) - self.first[self.owner]
        # each point's loop's first point and length (shifted is called dozens of times)
        self.start = self.first[self.owner]
        self.size = self.lengths[self.owner]

    def shifted(self, by: int, rows=None) -> np.ndarray:
        """Index of the point `by` places further along each point's own loop (of the
        points `rows`, all by default)."""
        if rows is None:
            return self.start + (self.pos + by) % self.size
        return self.start[rows] + (self.pos[rows] + by) % self.size[rows]

    def smoothed(self, sigma: float, which=None) -> np.ndarray:
        """Gaussian smoothing of each loop (sigma in samples; the kernel reaches at most
        half way round, and loops under 5 points stay as they are); of the loops
        `which` (a mask) only, the others left as they are."""
        if sigma <= 0:
            return self.points.copy()
        reach = np.minimum(int(3 * sigma + 1), (self.lengths - 1) // 2)
        reach[self.lengths < 5] = 0
        if which is not None:
            reach[~which] = 0
        # the kernel of each reach, end to end
        kernels, kernel_at = [np.zeros(0)], np.full(max(int(reach.max(initial=0)), 0) + 1, -1, np.int64)
        at = 0
        for r in np.unique(reach[reach > 0]).tolist():
            k = gaussian_kernel(r, sigma)
            kernels.append(k)
            kernel_at[r] = at
            at += len(k)
        return _core.smooth_loops(np.ascontiguousarray(self.points, np.float64), self.first,
                                  np.asarray(self.lengths, np.int64), np.asarray(reach, np.int64),
                                  np.concatenate(kernels), kernel_at)


def find_corners(loops: Loops, s: np.ndarray, window: int, corner_angle: float) -> list[np.ndarray]:
    """For each loop, the indices where it turns sharper than corner_angle (degrees; 180
    is straight): the angle at s[i] between s[i - window] and s[i + window], kept where it
    is the sharpest within the window (loops under 4 windows long have none)."""
    a = s[loops.shifted(-window)] - s
    b = s[loops.shifted(window)] - s
    # (np.linalg.norm's and .sum(1)'s arithmetic, without their overhead on rows of two)
    norms = np.sqrt(a[:, 0] * a[:, 0] + a[:, 1] * a[:, 1]) * np.sqrt(b[:, 0] * b[:, 0] + b[:, 1] * b[:, 1])
    cos = (a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]) / np.maximum(norms, 1e-12)
    angle = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    sharpest = _core.loop_window_min(np.ascontiguousarray(angle, np.float64), loops.first,
                                     np.asarray(loops.lengths, np.int64), int(window))
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

    def smoothed(self, sigma: float) -> np.ndarray:
        """Gaussian smoothing of each stretch, its ends held and the stretch extended past
        them by point reflection (which keeps a straight run into a corner straight)."""
        p = self.points
        if sigma <= 0 or len(p) == 0:
            return p.copy()
        k = gaussian_kernel(int(3 * sigma + 1), sigma)
        return _core.smooth_stretches(np.ascontiguousarray(p, np.float64), self.first, self.lengths, k)

    def tangents(self, s: np.ndarray, window: int) -> np.ndarray:
        """Unit forward tangent at each point, from the points `window` away along its
        stretch (one-sided near the ends)."""
        return _core.stretch_tangents(np.ascontiguousarray(s, np.float64), self.first, self.lengths, int(window))


def _basis(u: np.ndarray):
    mu = 1 - u
    return mu * mu * mu, 3 * mu * mu * u, 3 * mu * u * u, u * u * u


def _fit_all(st: Stretches, s: np.ndarray, tangents: np.ndarray, t1, t2, tol: float):
    """Cubic segments [K, 4, 2] of all stretches, fitted to their points in s (laid out as
    in st) with end tangents t1 (leaving the first point) and t2 (arriving at the last,
    pointing back into the stretch); tangents: the forward tangent at every point, used
    where a stretch is split. Returns the segments in order of stretch and along it, and
    each one's stretch.

    The fit runs in the compiled core (csrc/trace/fit.cpp), one level of splitting at a
    time: every open piece is fitted by least squares with its end tangents fixed, the
    parameters of those within NEWTON_RANGE tolerances refined by up to NEWTON_STEPS
    Newton steps (keeping improvements), and pieces still over tolerance, or turning
    more than MAX_TURN, split in two (at their worst inner point, or halfway through
    the turn) for the next level. Two-point pieces are straight lines."""
    heading = np.unwrap(np.arctan2(tangents[:, 1], tangents[:, 0]))
    steps = np.hypot(*np.diff(s, axis=0).T) if len(s) > 1 else np.zeros(0)
    cum = np.concatenate([[0.0], np.cumsum(steps)])
    f64 = lambda a: np.ascontiguousarray(a, np.float64)  # noqa: E731
    i64 = lambda a: np.ascontiguousarray(a, np.int64)  # noqa: E731
    options = _core.FitOptions(tolerance=float(tol), max_turn=float(MAX_TURN), newton_range=float(NEWTON_RANGE),
                               newton_steps=int(NEWTON_STEPS))
    return _core.fit_stretches(f64(s), f64(tangents), f64(heading), f64(cum), i64(st.first), i64(st.lengths),
                               f64(t1), f64(t2), options)


def _fit_closer(st: Stretches, s: np.ndarray, tangents: np.ndarray, t1, t2, tol: float, closer: np.ndarray,
                closer_tol: float):
    """_fit_all of every stretch within tol, then of the stretches `closer` (a mask) within
    closer_tol in place of theirs (the others' cubics are those of the fit of all, bit for
    bit: a fit of fewer stretches rounds their arc lengths differently)."""
    ctrl, stretch_of = _fit_all(st, s, tangents, t1, t2, tol)
    k = np.flatnonzero(closer)
    rows = np.flatnonzero(np.repeat(closer, st.lengths))
    ctrl2, of2 = _fit_all(Stretches(s[rows], st.lengths[k]), s[rows], tangents[rows], t1[k], t2[k], closer_tol)
    keep = ~closer[stretch_of]
    stretch_of = np.concatenate([stretch_of[keep], k[of2]])
    order = np.argsort(stretch_of, kind="stable")
    return np.concatenate([ctrl[keep], ctrl2])[order], stretch_of[order]


def _medians(values: np.ndarray, group: np.ndarray, valid: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """np.median of the valid values of each group in `wanted` (a mask over the groups),
    in group order, for groups with at least one value."""
    return _core.group_medians(np.ascontiguousarray(values, np.float64), np.ascontiguousarray(group, np.int64),
                               np.ascontiguousarray(valid, bool), np.ascontiguousarray(wanted, bool))


def fit_outlines(outlines: list[np.ndarray], tolerance: float, corner_angle: float,
                 smoothing: float = 1.0, corner_window: float = 3.0,
                 canvas: tuple[float, float] | None = None) -> list[np.ndarray]:
    """Cubic segments [S, 4, 2] of each closed outline (each segment starts where the
    previous one ends, the last ends at the first's start). Outlines: [N, 2] points,
    evenly spaced and all alike (the tracer's have a vertex every half pixel).

    The outline is smoothed (Gaussian, sigma `smoothing` pixels) to iron out the pixel
    staircase, and the fit is to the smoothed copy, so the staircase does not eat into
    the tolerance. corner_window (pixels) is how far either side the corner angle is
    measured.

    canvas: the canvas's size (w, h). An outline without corners that touches its edge
    (a logo tangent to it) is fitted within EDGE_TOLERANCE times the tolerance: over a
    page, the page's pieces between it and the edge cut it at the tangent points into
    stretches with corners, each fitted on its own; without them (the page removed, a
    transparent image) its two halves took fewer cubics, too few for the refinement,
    which adds no nodes, to follow where its arcs meet its straight runs. None: no
    canvas, the tolerance for all."""
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
    edge = np.zeros(len(used), bool)
    if canvas is not None:
        p = loops.points
        near = np.minimum(np.minimum(p[:, 0], canvas[0] - p[:, 0]), np.minimum(p[:, 1], canvas[1] - p[:, 1]))
        edge = np.bincount(loops.owner[near <= EDGE_REACH], minlength=len(used)) > 0
    edge = edge[owner] & given  # (only an outline without corners has given tangents)
    if edge.any():
        ctrl, stretch_of = _fit_closer(st, s, tangents, t1, t2, tolerance, edge, EDGE_TOLERANCE * tolerance)
    else:
        ctrl, stretch_of = _fit_all(st, s, tangents, t1, t2, tolerance)
    outline_of = owner[stretch_of]  # sorted: stretches are in outline order
    bounds = np.searchsorted(outline_of, np.arange(len(used) + 1))
    for k, i in enumerate(used.tolist()):
        result[i] = ctrl[bounds[k]:bounds[k + 1]]
    return result


def open_corners(points: np.ndarray, corner_angle: float, reach: int) -> list[int]:
    """Indices where an open polyline turns sharper than corner_angle (degrees), judged
    `reach` points either side, the sharpest within the reach."""
    n = len(points)
    if n < 2 * reach + 1:
        return []
    i = np.arange(reach, n - reach)
    a, b = points[i - reach] - points[i], points[i + reach] - points[i]
    cos = (a * b).sum(1) / np.maximum(np.hypot(*a.T) * np.hypot(*b.T), 1e-12)
    angle = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    corners: list[int] = []
    for k in np.argsort(angle, kind="stable").tolist():
        if angle[k] >= corner_angle:
            break
        if all(abs(k - c) > reach for c in corners):
            corners.append(k)
    return sorted(c + reach for c in corners)


def fit_pieces(pieces: list[np.ndarray], owner: list[int], count: int, sigma: float, window: int,
               tolerance: float) -> list[np.ndarray]:
    """Cubic segments [S, 4, 2] of ``count`` open polylines given as their pieces between
    corners (``owner``: each piece's polyline, in order): each piece smoothed with its ends
    held (sigma in points) and fitted with the end tangents of its own points (``window``
    points along), as fit_outlines fits a closed outline's stretches."""
    st = Stretches(np.concatenate(pieces), np.array([len(q) for q in pieces]))
    s = st.smoothed(sigma)
    tangents = st.tangents(s, window)
    m = np.minimum(window, st.lengths - 1)
    first, last = st.first, st.first + st.lengths - 1
    t1, t2 = _unit(s[first + m] - s[first]), _unit(s[last - m] - s[last])
    ctrl, stretch_of = _fit_all(st, s, tangents, t1, t2, tolerance)
    line_of = np.asarray(owner)[stretch_of]
    bounds = np.searchsorted(line_of, np.arange(count + 1))
    return [ctrl[bounds[k]:bounds[k + 1]] for k in range(count)]


def fit_closed(points: np.ndarray, tolerance: float, corner_angle: float,
               smoothing: float = 1.0, corner_window: float = 3.0) -> np.ndarray:
    """Cubic segments [S, 4, 2] of one closed outline (see fit_outlines)."""
    return fit_outlines([points], tolerance, corner_angle, smoothing, corner_window)[0]


def bezier_at(ctrl: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Points of the cubic with control points ctrl [4, 2] at parameters u."""
    b0, b1, b2, b3 = _basis(np.asarray(u, float))
    return np.outer(b0, ctrl[0]) + np.outer(b1, ctrl[1]) + np.outer(b2, ctrl[2]) + np.outer(b3, ctrl[3])
