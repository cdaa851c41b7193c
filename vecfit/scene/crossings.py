"""Where a closed outline crosses itself: an exact test on the outline flattened within a
tolerance, mapped back to the curves.

A designer's crossing is where the outline passes from one side of itself to the other
(the bow tie, the loop a refined cubic throws); a touch is not one. The test:

1. Flatten. Each segment becomes a polyline within ``tolerance``: linear interpolation over
   a parameter step h is off the curve by at most h² max|B''| / 8, and max|B''| is bounded
   by the control polygon's second differences (d(d-1) times the largest), so n pieces of
   equal parameter length do with n = ceil(sqrt(max|B''| / (8 tolerance))), at most
   ``MAX_PIECES``. Lines are one piece. Piece ends at t = 0 and 1 are the stored points
   themselves, so consecutive segments share their vertex bit for bit; zero-length pieces
   (a ``Z`` back to where the outline already is) are dropped.
2. Prune. Pairs of pieces of the same subpath whose boxes overlap, by one sort-and-sweep
   over all subpaths at once (pieces sorted by subpath, then by left edge; NumPy).
   Adjacent pieces (one after the other, the last and the first of a closed subpath) are
   never a pair: they meet at their shared vertex, which is no crossing.
3. Decide exactly. Each pair is tested with the four orientation signs of its ends. The
   orientations are computed in float64 with Shewchuk's error bound for that expression
   ((3 + 16ε)ε of |left| + |right|) and recomputed exactly with fractions.Fraction (every
   float is a rational) when the bound cannot vouch for the sign, so the signs are exact.
   Interiors crossing at one point (strict signs) are a crossing, except that two of them
   on the same two stretches (pieces next to each other on both), turning opposite ways
   and closer than the tolerance, are a graze (a curve resting on another, flattened or
   rounded into a dip across it) and count as none. A pair that touches (an
   end on the other piece, a shared vertex, a collinear overlap) is decided by the sides:
   the touching pieces are split at the contact points, so the contacts are vertices the
   outline passes more than once, and where two passes run together (a collinear overlap,
   several pieces long) they are followed to where they part; the passes cross when one
   comes in on one side of the other and leaves on the other side, and merely touch when
   it comes and goes on the same side (the keyhole's slit, a vertex grazing an edge, two
   corners kissing). An outline that runs over itself all the way round (a square drawn
   twice) never passes to the other side: no crossing. A pass that turns back on itself
   (a spike) decides nothing. Such crossings are reported at the contact vertex (the
   first of a run).
4. Map back. A crossing of pieces lies at parameters interpolated within the pieces'
   parameter ranges; a few Newton steps on B_a(t) = B_b(u) then put it on the curves
   (accepted where they converge to within 1e-9 px near where they started). A subpath
   with a crossing the curves do not confirm (Newton finds no crossing of the curves
   there: two parts of the outline closer than the tolerance, whose pieces cross where
   the curves do not) is flattened again at a sixteenth of the tolerance, up to three
   times; what the last flattening says stands, at the polyline's point where unconfirmed.

So the answer is exact for the polyline, and the polyline is within ``tolerance`` of the
curves (down to 1/4096 of it where that was needed): parts of the outline closer together
than that may still be taken to touch or cross, and two crossings closer together than
that may be missed.
A cubic's own loop is found like any other (two pieces of one segment; ``seg_a == seg_b``).
NumPy only (no torch): the Scene's floats may be tensors or arrays (arrays.to_numpy).
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

import numpy as np

from .arrays import to_numpy
from .model import Path
from .placement import pixel_scales

MAX_PIECES = 1024          # per segment: a wild control polygon is flattened less finely
_EPS = 2.0 ** -53
_ORIENT_BOUND = (3 + 16 * _EPS) * _EPS  # Shewchuk's ccwerrboundA
_PAIR_CHUNK = 1 << 22      # candidate pairs made at once (memory)
_NEWTON_STEPS = 5
_CONVERGED = 1e-9          # px: a refined crossing's two curve points this close
_ON_BOTH = 1e-12           # px: a crossing already this close to both curves is left as it is
_FINER, _FINER_STEP = 3, 16  # unconfirmed crossings: flattened again at tolerance / 16, / 256, / 4096


@dataclass(frozen=True)
class Crossing:
    """Where a subpath crosses itself: segment ``seg_a`` at parameter ``t_a`` and segment
    ``seg_b`` at ``t_b`` (indices within the subpath, (seg_a, t_a) before (seg_b, t_b)),
    at ``point``."""
    seg_a: int
    t_a: float
    seg_b: int
    t_b: float
    point: tuple[float, float]


def subpath_crossings(points: np.ndarray, degrees: Sequence[int], closed: bool,
                      tolerance: float = 0.01) -> list[Crossing]:
    """Where one subpath crosses itself, in the order of (seg_a, t_a).

    points: [n, 2], the subpath's stored points in the Scene's layout (start point, then
    ``degree`` points per segment; a closed subpath does not store its start again).
    degrees: 1, 2 or 3 per segment. tolerance: how far the flattened outline may stray
    from the curves (in the points' units). Raises ValueError for points that do not fit
    the degrees, degrees outside 1-3, non-finite points or a tolerance <= 0."""
    return _crossings_many([(points, degrees, closed, tolerance)])[0]


def many_subpath_crossings(jobs) -> list[list[Crossing]]:
    """subpath_crossings of each (points, degrees, closed, tolerance) in ``jobs``, in one
    batch (a call per subpath costs milliseconds of NumPy set-up each)."""
    return _crossings_many(list(jobs))


def path_crossings(path, tolerance: float = 0.01) -> list[tuple[int, list[Crossing]]]:
    """(subpath index, its crossings) for each closed subpath of a vecfit.scene.Path that
    crosses itself (open subpaths are strokes: a stroke crossing itself is a drawing)."""
    return [(index, found) for index, found in zip(*_closed_subpath_crossings([path], [tolerance])) if found]


def crossed_outlines(scene, tolerance: float = 0.01) -> int:
    """How many closed subpaths of the Scene's filled paths cross themselves (circles,
    ellipses and rects never do). ``tolerance`` is in canvas pixels at the Scene's size:
    each shape's is divided by its matrix's scale."""
    return len(crossed_subpaths(scene, tolerance))


def crossed_subpaths(scene, tolerance: float = 0.01) -> set[tuple[int, int]]:
    """(shape index, subpath index) of each closed subpath of the Scene's filled paths
    that crosses itself; ``tolerance`` as in crossed_outlines. One batch for the Scene."""
    shapes = [(i, s) for i, s in enumerate(scene.shapes) if s.fill is not None and isinstance(s.geometry, Path)]
    if not shapes:
        return set()
    every = pixel_scales(scene)
    scales = [every[i] for i, _ in shapes]
    tolerances = [tolerance / s if s > 0 else tolerance for s in scales]
    owners = [i for i, s in shapes for _, _, closed in s.geometry.subpaths if closed]
    indices, found = _closed_subpath_crossings([s.geometry for _, s in shapes], tolerances)
    return {(owner, k) for owner, k, f in zip(owners, indices, found) if f}


# ------------------------------------------------------------------------ inputs

def _closed_subpath_crossings(paths, tolerances):
    """(subpath indices, crossings) over the closed subpaths of ``paths``, each path with its
    tolerance."""
    jobs, indices = [], []
    for path, tol in zip(paths, tolerances):
        points = np.asarray(to_numpy(path.points), dtype=np.float64).reshape(-1, 2)
        degrees = np.asarray(path.degrees)
        for k, ((first, count, closed), (p, n)) in enumerate(zip(path.subpaths, path.subpath_point_ranges())):
            if closed:
                jobs.append((points[p:p + n], degrees[first:first + count], True, tol))
                indices.append(k)
    return indices, _crossings_many(jobs)


# ---------------------------------------------------------------------- flattening

@dataclass
class _Outlines:
    """Subpaths flattened, all in one set of arrays (vertices and pieces ordered by
    subpath)."""
    controls: np.ndarray     # [G, 4, 2] every segment as a cubic (degree-elevated)
    pieces: np.ndarray       # [G] pieces per segment
    seg_first: np.ndarray    # [S] each subpath's first segment
    closed: np.ndarray       # [S] bool
    xy: np.ndarray           # [V, 2] vertices
    seg: np.ndarray          # [V] global segment of each vertex
    t: np.ndarray            # [V] its parameter on that segment
    v_start: np.ndarray      # [S] each subpath's first vertex
    v_count: np.ndarray      # [S]
    # pieces: vertex a -> vertex b
    a: np.ndarray            # [E] start vertex
    b: np.ndarray            # [E] end vertex
    sub: np.ndarray          # [E] subpath
    local: np.ndarray        # [E] index within the subpath (its start vertex's)
    t0: np.ndarray           # [E] parameter range on segment seg[a]
    t1: np.ndarray
    piece_count: np.ndarray  # [S] pieces per subpath
    tolerance: np.ndarray    # [S]


def _check(points, degrees, closed, tolerance):
    pts = np.asarray(to_numpy(points), dtype=np.float64)
    deg = np.asarray(degrees, dtype=np.int64).reshape(-1)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points must be [n, 2], got shape {list(pts.shape)}")
    if deg.size and (deg.min() < 1 or deg.max() > 3):
        raise ValueError("segment degrees must be 1, 2 or 3")
    stored = int(deg.sum()) + (0 if closed else 1)
    if deg.size and len(pts) != stored:
        raise ValueError(f"{len(deg)} segments of degrees summing to {int(deg.sum())} store {stored} points "
                         f"({'closed' if closed else 'open'}), got {len(pts)}")
    if not np.isfinite(pts).all():
        raise ValueError("points must be finite")
    if not tolerance > 0:
        raise ValueError(f"tolerance must be > 0, got {tolerance}")
    if deg.size and closed:
        pts = np.concatenate([pts, pts[:1]])  # the closing segment ends at the start
    return pts, deg, bool(closed), float(tolerance)


def _as_cubics(pts, starts, deg):
    """[G, 4, 2]: each segment's control points, degree-elevated to a cubic (the same
    curve with the same parameter)."""
    last = len(pts) - 1
    p = [pts[np.minimum(starts + k, last)] for k in range(4)]
    line = (deg == 1)[:, None]
    quad = (deg == 2)[:, None]
    c1 = np.where(line, (2 * p[0] + p[1]) / 3, np.where(quad, (p[0] + 2 * p[1]) / 3, p[1]))
    c2 = np.where(line, (p[0] + 2 * p[1]) / 3, np.where(quad, (2 * p[1] + p[2]) / 3, p[2]))
    c3 = np.where(line, p[1], np.where(quad, p[2], p[3]))
    return np.stack([p[0], c1, c2, c3], axis=1)


def _bezier(c: np.ndarray, t: np.ndarray) -> np.ndarray:
    s = 1 - t
    w = np.stack([s * s * s, 3 * s * s * t, 3 * s * t * t, t * t * t], axis=1)
    return np.einsum("nk,nkd->nd", w, c)


def _bezier_derivative(c: np.ndarray, t: np.ndarray) -> np.ndarray:
    s = 1 - t
    d = np.diff(c, axis=1)
    w = np.stack([s * s, 2 * s * t, t * t], axis=1)
    return 3 * np.einsum("nk,nkd->nd", w, d)


def _flatten(jobs) -> _Outlines:
    checked = [_check(*job) for job in jobs]
    n_sub = len(checked)
    closed = np.array([c for _, _, c, _ in checked], dtype=bool)
    seg_count = np.array([len(d) for _, d, _, _ in checked], dtype=np.int64)
    seg_first = np.concatenate([[0], np.cumsum(seg_count)[:-1]]).astype(np.int64)
    point_count = np.array([len(p) for p, _, _, _ in checked], dtype=np.int64)
    point_first = np.concatenate([[0], np.cumsum(point_count)[:-1]]).astype(np.int64)
    pts = np.concatenate([p for p, _, _, _ in checked]) if n_sub else np.zeros((0, 2))
    deg = np.concatenate([d for _, d, _, _ in checked]) if n_sub else np.zeros(0, np.int64)
    seg_sub = np.repeat(np.arange(n_sub), seg_count)
    within = np.concatenate([np.concatenate([[0], np.cumsum(d)[:-1]]) for _, d, _, _ in checked if len(d)]
                            or [np.zeros(0, np.int64)]).astype(np.int64)
    starts = point_first[seg_sub] + within
    controls = _as_cubics(pts, starts, deg) if len(deg) else np.zeros((0, 4, 2))

    tol = np.array([tolerance for _, _, _, tolerance in checked])[seg_sub]
    second = np.maximum(np.linalg.norm(controls[:, 0] - 2 * controls[:, 1] + controls[:, 2], axis=1),
                        np.linalg.norm(controls[:, 1] - 2 * controls[:, 2] + controls[:, 3], axis=1))
    pieces = np.ceil(np.sqrt(6 * second / (8 * tol)))
    pieces = np.where(deg == 1, 1, np.clip(pieces, 1, MAX_PIECES)).astype(np.int64)

    # vertices at t = k / n for k < n; an open subpath's last segment also gives its end (k = n)
    last_of_open = np.zeros(len(deg), bool)
    has = seg_count > 0
    last_of_open[(seg_first + seg_count - 1)[has & ~closed]] = True
    per_seg = pieces + last_of_open
    v_seg = np.repeat(np.arange(len(deg)), per_seg)
    k = np.arange(len(v_seg)) - np.repeat(np.cumsum(per_seg) - per_seg, per_seg)
    n = pieces[v_seg]
    t = k / n
    xy = _bezier(controls[v_seg], t)
    xy[k == 0] = controls[v_seg[k == 0], 0]
    xy[k == n] = controls[v_seg[k == n], 3]
    v_sub = seg_sub[v_seg]

    # drop a vertex equal to the next one (zero-length pieces): the later one is kept, so a
    # piece always lies on its start vertex's segment
    v_counts = np.bincount(v_sub, minlength=n_sub)
    v_first = np.concatenate([[0], np.cumsum(v_counts)[:-1]]).astype(np.int64)
    nxt = np.arange(len(v_seg)) + 1
    is_last = np.zeros(len(v_seg), bool)
    is_last[(v_first + v_counts - 1)[v_counts > 0]] = True
    nxt[is_last] = np.where(closed[v_sub[is_last]], v_first[v_sub[is_last]], -1)
    same = np.zeros(len(v_seg), bool)
    linked = nxt >= 0
    same[linked] = (xy[linked] == xy[nxt[linked]]).all(axis=1)
    keep = ~same
    # a closed subpath whose vertices are all one point keeps none: it has no pieces
    xy, v_seg, t, v_sub = xy[keep], v_seg[keep], t[keep], v_sub[keep]

    v_count = np.bincount(v_sub, minlength=n_sub).astype(np.int64)
    v_start = np.concatenate([[0], np.cumsum(v_count)[:-1]]).astype(np.int64)
    local_v = np.arange(len(v_sub)) - v_start[v_sub]
    # pieces: each vertex to the next; a closed subpath's last vertex to its first
    last_v = local_v == v_count[v_sub] - 1
    starts_piece = ~last_v | (closed[v_sub] & (v_count[v_sub] > 1))
    a = np.flatnonzero(starts_piece)
    b = np.where(last_v[a], v_start[v_sub[a]], a + 1)
    same_seg = v_seg[b] == v_seg[a]
    t1 = np.where(same_seg & (t[b] > t[a]), t[b], 1.0)
    return _Outlines(controls=controls, pieces=pieces, seg_first=seg_first, closed=closed, xy=xy, seg=v_seg, t=t,
                     v_start=v_start, v_count=v_count, a=a, b=b, sub=v_sub[a], local=local_v[a],
                     t0=t[a], t1=t1, piece_count=np.bincount(v_sub[a], minlength=n_sub),
                     tolerance=np.array([tolerance for _, _, _, tolerance in checked]))


# ------------------------------------------------------------------- candidate pairs

def _candidate_pairs(o: _Outlines):
    """(i, j) piece pairs of one subpath whose boxes overlap, adjacent pieces left out."""
    if len(o.a) < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    p, q = o.xy[o.a], o.xy[o.b]
    lo, hi = np.minimum(p, q), np.maximum(p, q)
    n_pieces = o.piece_count
    first = np.concatenate([[0], np.cumsum(n_pieces)[:-1]])
    nonempty = n_pieces > 0
    base = np.zeros(len(o.closed))
    base[nonempty] = np.minimum.reduceat(lo[:, 0], first[nonempty])
    width = np.zeros(len(o.closed))
    width[nonempty] = np.maximum.reduceat(hi[:, 0], first[nonempty]) - base[nonempty]
    # one key per subpath range, wide enough that ranges never meet; rounding is monotone,
    # so the sweep finds every pair whose x ranges overlap (the exact test follows)
    span = float(width.max()) + 1.0
    key_lo = o.sub * span + (lo[:, 0] - base[o.sub])
    key_hi = o.sub * span + (hi[:, 0] - base[o.sub])
    order = np.argsort(key_lo, kind="stable")
    ends = np.searchsorted(key_lo[order], key_hi[order], side="right")
    counts = np.maximum(ends - np.arange(len(order)) - 1, 0)
    out_i, out_j = [], []
    cum = np.cumsum(counts)
    start = 0
    while start < len(order):
        stop = int(np.searchsorted(cum, (cum[start - 1] if start else 0) + _PAIR_CHUNK, side="right"))
        stop = max(stop, start + 1)
        c = counts[start:stop]
        total = int(c.sum())
        if total:
            ii = np.repeat(np.arange(start, stop), c)
            jj = ii + 1 + np.arange(total) - np.repeat(np.cumsum(c) - c, c)
            i, j = order[ii], order[jj]
            i, j = np.minimum(i, j), np.maximum(i, j)
            overlap = ((lo[j] <= hi[i]) & (lo[i] <= hi[j])).all(axis=1)
            adjacent = (j - i == 1) | (o.closed[o.sub[i]] & (o.local[i] == 0)
                                       & (o.local[j] == n_pieces[o.sub[j]] - 1))
            keep = overlap & ~adjacent
            out_i.append(i[keep])
            out_j.append(j[keep])
        start = stop
    if not out_i:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate(out_i), np.concatenate(out_j)


# ------------------------------------------------------------------ exact predicates

def _orient_exact(a, b, c) -> int:
    """Sign of the orientation of points a, b, c (tuples of floats), exactly."""
    ax, ay, bx, by, cx, cy = (Fraction(v) for v in (*a, *b, *c))
    det = (ax - cx) * (by - cy) - (ay - cy) * (bx - cx)
    return (det > 0) - (det < 0)


def _orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(exact signs, float64 values) of the orientations of rows a, b, c: [N, 2] each."""
    left = (a[:, 0] - c[:, 0]) * (b[:, 1] - c[:, 1])
    right = (a[:, 1] - c[:, 1]) * (b[:, 0] - c[:, 0])
    det = left - right
    sign = np.sign(det).astype(np.int64)
    for k in np.flatnonzero(~(np.abs(det) > _ORIENT_BOUND * (np.abs(left) + np.abs(right)))):
        sign[k] = _orient_exact(tuple(a[k]), tuple(b[k]), tuple(c[k]))
    return sign, det


def _within(p, lo, hi) -> np.ndarray:
    return ((lo <= p) & (p <= hi)).all(axis=1)


# ------------------------------------------------------------------------ crossings

def _crossings_many(jobs) -> list[list[Crossing]]:
    """The crossings of each (points, degrees, closed, tolerance) in ``jobs``; a subpath
    with a crossing that the curves do not confirm (Newton found no crossing of the curves
    there) is flattened again, finer, up to ``_FINER`` times."""
    out: list[list] = [[] for _ in jobs]
    todo = list(range(len(jobs)))
    for finer in range(_FINER + 1):
        scale = _FINER_STEP ** finer
        found, unsure = _crossings_flattened([(*jobs[k][:3], jobs[k][3] / scale) for k in todo])
        for k, crossings in zip(todo, found):
            out[k] = crossings
        todo = [k for k, u in zip(todo, unsure) if u]
        if not todo:
            break
    return out


def _crossings_flattened(jobs) -> tuple[list[list[Crossing]], list[bool]]:
    """The crossings of each job at its tolerance, and whether any of them is unsure (not
    confirmed on the curves)."""
    o = _flatten(jobs)
    out: list[list] = [[] for _ in jobs]
    unsure = [False] * len(jobs)
    i, j = _candidate_pairs(o)
    found = []  # (subpath, seg_a, t_a, seg_b, t_b, point) with global segments
    if len(i):
        pa, pb, qa, qb = o.xy[o.a[i]], o.xy[o.b[i]], o.xy[o.a[j]], o.xy[o.b[j]]
        s1, d1 = _orient(pa, pb, qa)
        s2, d2 = _orient(pa, pb, qb)
        s3, d3 = _orient(qa, qb, pa)
        s4, d4 = _orient(qa, qb, pb)
        proper = (s1 * s2 < 0) & (s3 * s4 < 0)
        touching = ~proper & (s1 * s2 <= 0) & (s3 * s4 <= 0)
        k = np.flatnonzero(proper)
        if len(k):
            alpha = np.clip(d3[k] / (d3[k] - d4[k]), 0, 1)  # along piece i
            beta = np.clip(d1[k] / (d1[k] - d2[k]), 0, 1)   # along piece j
            point = pa[k] + alpha[:, None] * (pb[k] - pa[k])
            ii, jj = i[k], j[k]
            u, v = pb[k] - pa[k], qb[k] - qa[k]
            kept = ~_grazes(o, ii, jj, np.sign(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]), point)
            alpha, beta, point, ii, jj = alpha[kept], beta[kept], point[kept], ii[kept], jj[kept]
            found.append((o.sub[ii], o.seg[o.a[ii]], o.t0[ii] + alpha * (o.t1[ii] - o.t0[ii]),
                          o.seg[o.a[jj]], o.t0[jj] + beta * (o.t1[jj] - o.t0[jj]), point))
        k = np.flatnonzero(touching)
        if len(k):
            found.append(_touch_crossings(o, i[k], j[k], s1[k], s2[k], s3[k], s4[k]))
    found = [f for f in found if len(f[0])]
    if not found:
        return out, unsure
    sub, seg_a, t_a, seg_b, t_b, point = (np.concatenate(x) for x in zip(*found))
    t_a, t_b, point, confirmed = _refine(o, seg_a, t_a, seg_b, t_b, point)
    for s, ga, ta, gb, tb, p, sure in zip(sub.tolist(), seg_a.tolist(), t_a.tolist(), seg_b.tolist(),
                                          t_b.tolist(), point.tolist(), confirmed.tolist()):
        unsure[s] |= not sure
        first = int(o.seg_first[s])
        ends = sorted([(ga - first, ta), (gb - first, tb)])
        out[s].append(Crossing(ends[0][0], ends[0][1], ends[1][0], ends[1][1], (p[0], p[1])))
    for crossings in out:
        crossings.sort(key=lambda c: (c.seg_a, c.t_a, c.seg_b, c.t_b))
    return out, unsure


def _grazes(o: _Outlines, i, j, turn, point) -> np.ndarray:
    """Which proper crossings (pieces i and j, ``turn`` the sign of one's direction across
    the other's, at ``point``) come in pairs that are a graze: two crossings of the same two
    stretches (pieces next to each other on both) of opposite turns and closer than the
    tolerance, as a curve touching another is flattened, or rounded, into a dip across it."""
    gone = np.zeros(len(i), bool)
    if len(i) < 2:
        return gone
    n = len(o.a)
    keys = i * n + j
    order = np.argsort(keys)
    sorted_keys = keys[order]
    found = []
    for da in (-1, 0, 1):
        for db in (-1, 0, 1):
            if da == db == 0:
                continue
            (a, ok_a), (b, ok_b) = _next_piece(o, i, da), _next_piece(o, j, db)
            wanted = np.minimum(a, b) * n + np.maximum(a, b)
            at = np.minimum(np.searchsorted(sorted_keys, wanted), len(keys) - 1)
            other = order[at]
            hit = (ok_a & ok_b & (sorted_keys[at] == wanted) & (turn != 0) & (turn[other] == -turn)
                   & (np.linalg.norm(point[other] - point, axis=1) <= o.tolerance[o.sub[i]]))
            found += zip(np.flatnonzero(hit).tolist(), other[hit].tolist())
    for k, other in sorted(found):  # few: pair them off in order
        if not gone[k] and not gone[other]:
            gone[k] = gone[other] = True
    return gone


def _next_piece(o: _Outlines, piece, step):
    """(the piece ``step`` along from each of ``piece``, whether there is one): round a
    closed subpath, not past an open one's ends."""
    local = o.local[piece] + step
    count = o.piece_count[o.sub[piece]]
    closed = o.closed[o.sub[piece]]
    local = np.where(closed, local % np.maximum(count, 1), local)
    return piece - o.local[piece] + local, closed | ((local >= 0) & (local < count))


def _touch_crossings(o: _Outlines, i, j, s1, s2, s3, s4):
    """Crossings where pieces touch (see the module's docstring, step 3): the contacts of
    the pairs (i, j), each subpath followed around its contact vertices."""
    pa, pb, qa, qb = o.xy[o.a[i]], o.xy[o.b[i]], o.xy[o.a[j]], o.xy[o.b[j]]
    lo_p, hi_p = np.minimum(pa, pb), np.maximum(pa, pb)
    lo_q, hi_q = np.minimum(qa, qb), np.maximum(qa, qb)
    # (piece, point) for each end of one piece that lies on the other
    on = [(s1 == 0) & _within(qa, lo_p, hi_p), (s2 == 0) & _within(qb, lo_p, hi_p),
          (s3 == 0) & _within(pa, lo_q, hi_q), (s4 == 0) & _within(pb, lo_q, hi_q)]
    contacts: dict[int, tuple[set, dict]] = {}  # subpath -> (contact points, piece -> split points)
    for mask, host, point in ((on[0], i, qa), (on[1], i, qb), (on[2], j, pa), (on[3], j, pb)):
        for h, p in zip(host[mask].tolist(), point[mask].tolist()):
            points, splits = contacts.setdefault(int(o.sub[h]), (set(), {}))
            p = (p[0], p[1])
            points.add(p)
            if p != tuple(o.xy[o.a[h]]) and p != tuple(o.xy[o.b[h]]):
                splits.setdefault(int(o.local[h]), set()).add(p)
    rows = []
    for s, (points, splits) in contacts.items():
        for row in _passes_crossing(o, s, points, splits):
            rows.append((s, *row))
    if not rows:
        empty = np.zeros(0)
        return np.zeros(0, np.int64), np.zeros(0, np.int64), empty, np.zeros(0, np.int64), empty, np.zeros((0, 2))
    sub, seg_a, t_a, seg_b, t_b, x, y = (np.array(c) for c in zip(*rows))
    return sub, seg_a, t_a, seg_b, t_b, np.stack([x, y], axis=1).astype(np.float64)


def _split_vertices(o: _Outlines, s: int, splits: dict):
    """Subpath ``s``'s vertices (points, segments, parameters, whether inserted), with the
    split points inserted into their pieces in order along them."""
    v0, n = int(o.v_start[s]), int(o.v_count[s])
    xy, seg, t = o.xy[v0:v0 + n].tolist(), o.seg[v0:v0 + n].tolist(), o.t[v0:v0 + n].tolist()
    out_xy, out_seg, out_t, inserted = [], [], [], []
    for k in range(n):
        out_xy.append(tuple(xy[k]))
        out_seg.append(seg[k])
        out_t.append(t[k])
        inserted.append(False)
        if k not in splits:
            continue
        (ax, ay), (bx, by) = xy[k], xy[(k + 1) % n]
        t0 = t[k]
        t1 = t[(k + 1) % n] if seg[(k + 1) % n] == seg[k] and t[(k + 1) % n] > t0 else 1.0
        # the points lie exactly on the piece: ordered by a coordinate that changes along
        # it, their order is exact
        if abs(bx - ax) >= abs(by - ay):
            along = sorted(splits[k], key=lambda p: p[0] if bx > ax else -p[0])
            fraction = [(p[0] - ax) / (bx - ax) for p in along]
        else:
            along = sorted(splits[k], key=lambda p: p[1] if by > ay else -p[1])
            fraction = [(p[1] - ay) / (by - ay) for p in along]
        for p, f in zip(along, fraction):
            out_xy.append(p)
            out_seg.append(seg[k])
            out_t.append(t0 + f * (t1 - t0))
            inserted.append(True)
    return out_xy, out_seg, out_t, inserted


def _passes_crossing(o: _Outlines, s: int, points: set, splits: dict):
    """(seg_a, t_a, seg_b, t_b, x, y) of each crossing at the contact vertices of subpath
    ``s``: for each two passes through a contact point, followed along any stretch they
    share, whether one comes in on one side of the other and leaves on the other side."""
    xy, seg, t, inserted = _split_vertices(o, s, splits)
    m, closed = len(xy), bool(o.closed[s])

    def at(index, step):
        k = index + step
        if closed:
            return k % m
        return k if 0 <= k < m else None

    def pos(index):
        return None if index is None else xy[index]

    visits: dict = {}
    for k, p in enumerate(xy):
        if p in points:
            visits.setdefault(p, []).append(k)
    rows = []
    for p, ks in visits.items():
        for i in ks:
            for j in ks:
                if i == j:
                    continue
                p_prev, p_next = pos(at(i, -1)), pos(at(i, 1))
                q_prev, q_next = pos(at(j, -1)), pos(at(j, 1))
                if p_prev is not None and p_prev in (q_prev, q_next):
                    continue  # not where the shared stretch starts along pass i
                direction = 1 if p_next is not None and p_next == q_next else (
                    -1 if p_next is not None and p_next == q_prev else 0)
                run = 0
                if direction:
                    run = _shared_run(at, pos, i, j, direction, m)
                    if run is None:
                        continue  # the passes meet (a spike) or run together all round
                if not direction and inserted[i] and inserted[j]:
                    continue  # two pieces' interiors crossing: a proper crossing, found already
                # each stretch starts along each of its two passes: decide it once, from the
                # pass whose start has the lower index
                other_start = (j - run) % m if direction < 0 else j
                if i > other_start:
                    continue
                step = direction or 1
                end_p, end_q = at(i, run), at(j, step * run)
                came = _left_of(xy[i], p_prev, p_next, pos(at(j, -step)))
                went = _left_of(xy[end_p], pos(at(end_p, -1)), pos(at(end_p, 1)), pos(at(end_q, step)))
                if came is not None and went is not None and came != went:
                    rows.append((seg[i], t[i], seg[j], t[j], p[0], p[1]))
    return rows


def _shared_run(at, pos, i, j, direction, m):
    """How many pieces passes i and j (the second in ``direction``) share from their common
    vertex on; None when they meet at one vertex (a spike) or share everything."""
    run = 0
    while True:
        a, b = at(i, run + 1), at(j, direction * (run + 1))
        if a is None or b is None or pos(a) != pos(b):
            return run
        if a == b or run > m:
            return None
        run += 1


def _left_of(x, a, b, w):
    """Whether w lies strictly left of the outline coming from a to x and leaving to b (in
    the sector turned counter-clockwise from ray x->b to ray x->a); None where that is
    undefined: an end of an open outline, w along either ray, the outline turning back."""
    if a is None or b is None or w is None:
        return None
    o_ba, o_bw, o_wa = _orient_exact(x, b, a), _orient_exact(x, b, w), _orient_exact(x, w, a)
    if (o_bw == 0 and _same_ray(x, b, w)) or (o_wa == 0 and _same_ray(x, a, w)):
        return None
    if o_ba > 0:
        return o_bw > 0 and o_wa > 0
    if o_ba < 0:
        return o_bw > 0 or o_wa > 0
    if _same_ray(x, a, b):
        return None
    return o_bw > 0  # straight through x: the left half-plane


def _same_ray(x, a, b) -> bool:
    """For a, b collinear with x: whether they lie on the same side of x (exactly)."""
    fx, fy = Fraction(x[0]), Fraction(x[1])
    return (Fraction(a[0]) - fx) * (Fraction(b[0]) - fx) + (Fraction(a[1]) - fy) * (Fraction(b[1]) - fy) > 0


# ----------------------------------------------------------------------- refinement

def _refine(o: _Outlines, seg_a, t_a, seg_b, t_b, point):
    """Newton steps on B_a(t) = B_b(u) from the polyline's crossing; kept where they
    converge near their start (within two pieces), else the polyline's. Also returns
    whether each crossing is confirmed on the curves (converged, or exact already)."""
    ca, cb = o.controls[seg_a], o.controls[seg_b]
    pieces = 1 / np.minimum(o.pieces[seg_a], o.pieces[seg_b])  # the longer piece's parameter length
    t, u = t_a.astype(np.float64).copy(), t_b.astype(np.float64).copy()
    exact = np.linalg.norm(_bezier(ca, t) - _bezier(cb, u), axis=1) <= _ON_BOTH  # a vertex on both curves
    for _ in range(_NEWTON_STEPS):
        r = _bezier(ca, t) - _bezier(cb, u)
        da, db = _bezier_derivative(ca, t), _bezier_derivative(cb, u)
        det = db[:, 0] * da[:, 1] - da[:, 0] * db[:, 1]  # of [da, -db]
        ok = np.abs(det) > 1e-12 * np.linalg.norm(da, axis=1) * np.linalg.norm(db, axis=1)
        safe = np.where(ok, det, 1.0)
        dt = (r[:, 0] * db[:, 1] - db[:, 0] * r[:, 1]) / safe
        du = (r[:, 0] * da[:, 1] - da[:, 0] * r[:, 1]) / safe
        t = np.clip(np.where(ok, t + dt, t), 0, 1)
        u = np.clip(np.where(ok, u + du, u), 0, 1)
    pa, pb = _bezier(ca, t), _bezier(cb, u)
    converged = ~exact & ((np.linalg.norm(pa - pb, axis=1) <= _CONVERGED)
                 & (np.abs(t - t_a) <= 2 * pieces) & (np.abs(u - t_b) <= 2 * pieces)
                 & ((seg_a != seg_b) | (np.abs(t - u) > pieces)))  # not the trivial t = u
    out_point = np.where(converged[:, None], (pa + pb) / 2, point)
    return np.where(converged, t, t_a), np.where(converged, u, t_b), out_point, converged | exact
