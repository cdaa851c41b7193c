"""Cut-out boundaries laid back on the drawing's own curves.

Where two pieces of a stacked drawing meet, the boundary is the outline of one shape: the
topmost shape that covers one side and not the other (a shape's edge over what it hides).
Refitting the sampled staircase there would cost nodes and accuracy; the piece of that
shape's outline between the boundary's two ends is exact, and has the shape's own nodes
(plus the two cuts). A boundary that does not follow one outline within ``MAX_OFF`` pixels
all along (a speck given to a neighbour, an outline that runs along itself) is left to
the fit.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vecfit.scene.outline import Subpath, flattened
from vecfit.scene.segments import split_at

MAX_OFF = 0.75      # pixels: how far the sampled boundary may lie from the outline it follows
MAX_STRAY = 2.0     # pixels: how far the outline may stray from the sampled boundary
DENSITY = 4.0       # samples a pixel along an outline, for the nearest-point search
MIN_LENGTH = 1e-6   # pixels: shorter pieces of a cut segment are dropped


def closed_loops(subpaths: list[Subpath]) -> list[list[np.ndarray]]:
    """Each subpath as its segments' control points ([d + 1, 2], d 1 or 3), closed as a fill
    closes it: by a line back to the start where it does not end there."""
    loops = []
    for sp in subpaths:
        segs, a = [], sp.start
        for d, c in sp.segments:
            segs.append(np.vstack([a[None], c]))
            a = c[-1]
        if not segs:
            continue
        if np.hypot(*(a - sp.start)) > MIN_LENGTH:
            segs.append(np.vstack([a[None], sp.start[None]]))
        loops.append(segs)
    return loops


def _at(ctrl: np.ndarray, t: np.ndarray) -> np.ndarray:
    t = np.asarray(t, np.float64)[..., None]
    if len(ctrl) == 2:
        return (1 - t) * ctrl[0] + t * ctrl[1]
    u = 1 - t
    return u ** 3 * ctrl[0] + 3 * u * u * t * ctrl[1] + 3 * u * t * t * ctrl[2] + t ** 3 * ctrl[3]


def _nearest_t(ctrl: np.ndarray, p: np.ndarray, t: float) -> float:
    """The parameter of the point of segment ``ctrl`` nearest ``p``, from ``t`` by a few
    Newton steps on the squared distance (kept in [0, 1])."""
    if len(ctrl) == 2:
        d = ctrl[1] - ctrl[0]
        return float(np.clip((p - ctrl[0]) @ d / max(d @ d, 1e-18), 0, 1))
    c0, c1, c2, c3 = ctrl
    for _ in range(4):
        u = 1 - t
        b = u ** 3 * c0 + 3 * u * u * t * c1 + 3 * u * t * t * c2 + t ** 3 * c3
        d1 = 3 * (u * u * (c1 - c0) + 2 * u * t * (c2 - c1) + t * t * (c3 - c2))
        d2 = 6 * (u * (c2 - 2 * c1 + c0) + t * (c3 - 2 * c2 + c1))
        f, df = (b - p) @ d1, d1 @ d1 + (b - p) @ d2
        if abs(df) < 1e-18:
            break
        t = float(np.clip(t - f / df, 0, 1))
    return t


class OutlineFinder:
    """Nearest points on one shape's closed loops (canvas pixels)."""

    def __init__(self, loops: list[list[np.ndarray]]):
        from scipy.spatial import cKDTree

        self.loops = loops
        pts, where = [], []
        for k, segs in enumerate(loops):
            for s, c in enumerate(segs):
                n = _samples(c)
                t = np.arange(n) / n
                pts.append(_at(c, t))
                where.append(np.stack([np.full(n, k), np.full(n, s), t], 1))
        self.points = np.vstack(pts)
        self.where = np.vstack(where)
        self.tree = cKDTree(self.points)
        self._trees: dict = {}
        self._rows: dict = {}

    def nearest(self, p: np.ndarray):
        """(distance, loop, position) of the outline's point nearest each of ``p`` [n, 2]:
        position = segment index + parameter along it."""
        dist, i = self.tree.query(p)
        w = self.where[i]
        return dist, w[:, 0].astype(np.int64), w[:, 1] + w[:, 2]

    def rows(self, loop: int) -> np.ndarray:
        """The indices of loop ``loop``'s samples, in order along it."""
        if loop not in self._rows:
            self._rows[loop] = np.flatnonzero(self.where[:, 0] == loop)
        return self._rows[loop]

    def loop_tree(self, loop: int):
        """A k-d tree of loop ``loop``'s samples (indexed as ``rows(loop)``)."""
        from scipy.spatial import cKDTree

        if loop not in self._trees:
            self._trees[loop] = cKDTree(self.points[self.rows(loop)])
        return self._trees[loop]

    def nearest_on(self, loop: int, p: np.ndarray):
        """(distance, position) of the point of loop ``loop`` nearest each of ``p``."""
        dist, i = self.loop_tree(loop).query(p)
        w = self.where[self.rows(loop)[i]]
        return dist, w[:, 1] + w[:, 2]

    def exact(self, loop: int, position: float, p: np.ndarray) -> float:
        """The position of the point of the loop nearest ``p``, refined from ``position``."""
        segs = self.loops[loop]
        s = int(position) % len(segs)
        return s + _nearest_t(segs[s], p, position - int(position))


def _cut(segs: list[np.ndarray], start: float, end: float) -> list[np.ndarray]:
    """The loop's stretch from position ``start`` forwards to ``end`` (round the loop's end
    where ``end`` comes first), as segments."""
    n = len(segs)
    s0, t0 = int(start) % n, start - int(start)
    s1, t1 = int(end) % n, end - int(end)
    if t1 == 0 and (s1 != s0 or end > start):  # ending at a node: the segment before, whole
        s1, t1 = (s1 - 1) % n, 1.0
    out = []
    if s0 == s1 and t1 >= t0 and (end - start) % n <= 1:
        head = split_at(segs[s0], t0)[1] if t0 > 0 else segs[s0]
        out.append(split_at(head, (t1 - t0) / (1 - t0))[0] if t0 < 1 and t1 < 1 else head)
    else:
        out.append(split_at(segs[s0], t0)[1] if t0 > 0 else segs[s0])
        k = (s0 + 1) % n
        while k != s1:
            out.append(segs[k])
            k = (k + 1) % n
        out.append(split_at(segs[s1], t1)[0] if t1 < 1 else segs[s1])
    return [c for c in out if float(np.abs(c - c[0]).max()) > MIN_LENGTH]


def _rotated(segs: list[np.ndarray], start: float) -> list[np.ndarray]:
    """The whole loop, starting and ending at position ``start``."""
    n = len(segs)
    s0, t0 = int(start) % n, start - int(start)
    head, tail = split_at(segs[s0], t0) if 0 < t0 < 1 else (None, segs[s0])
    out = [tail] + segs[s0 + 1:] + segs[:s0] + ([head] if head is not None else [])
    return [c for c in out if float(np.abs(c - c[0]).max()) > MIN_LENGTH]


def _samples(ctrl: np.ndarray) -> int:
    """Points enough along a segment for the nearest-point search (DENSITY a pixel)."""
    length = float(np.hypot(*np.diff(ctrl, axis=0).T).sum())
    return int(min(max(np.ceil(length * DENSITY), 4), 4096))


def _close_to(a: np.ndarray, b: np.ndarray, limit: float) -> bool:
    """Whether every point of ``a`` lies within ``limit`` of some point of ``b``."""
    from scipy.spatial import cKDTree

    return bool(cKDTree(b).query(a)[0].max() <= limit)


@dataclass
class Follow:
    """A chain found to run along loop ``loop`` of a finder's outline, the ``forward`` way
    (the loop's own direction) or backwards."""
    finder: OutlineFinder
    loop: int
    forward: bool
    whole: bool = False  # the chain leaves a junction and comes back to it: all the loop

    def piece(self, start: np.ndarray, end: np.ndarray, hint: tuple[float, float]) -> list[np.ndarray]:
        """The stretch between the points of the loop nearest ``start`` and ``end`` (from
        the positions ``hint``), the found way."""
        segs = self.finder.loops[self.loop]
        a = self.finder.exact(self.loop, hint[0], start)
        if self.whole:
            ring = _rotated(segs, a)
            return ring if self.forward else [c[::-1] for c in ring[::-1]]
        b = self.finder.exact(self.loop, hint[1], end)
        if self.forward:
            return _cut(segs, a, b)
        return [c[::-1] for c in _cut(segs, b, a)[::-1]]


def on_outline(chain: np.ndarray, closed: bool, finder: OutlineFinder):
    """Where the boundary ``chain`` (points [n, 2] in pixels, in order) runs along the
    finder's outline: (the stretch as segments, in the chain's direction; a Follow, None for
    a closed chain; the positions of its ends), or None where it does not follow one loop
    of it within MAX_OFF all along."""
    # the loop most of the chain is nearest (two loops of a shape may touch), if all of
    # the chain is near it
    _, loop, _ = finder.nearest(chain)
    k = int(np.bincount(loop).argmax())
    dist, pos = finder.nearest_on(k, chain)
    if dist.max() > MAX_OFF:
        return None
    segs = finder.loops[k]
    n = len(segs)
    if closed:  # the whole loop, turned the chain's way
        area = lambda p: float(np.sum(p[:-1, 0] * p[1:, 1] - p[1:, 0] * p[:-1, 1]))  # noqa: E731
        ring = np.vstack([chain, chain[:1]])
        drawn = flattened(Subpath(segs[0][0], [(len(c) - 1, c[1:]) for c in segs], True), 0.1)
        piece = segs if (area(ring) > 0) == (area(drawn) > 0) else [c[::-1] for c in segs[::-1]]
        return (piece, None, None) if _follows(piece, chain) else None
    hint = (float(pos[0]), float(pos[-1]))
    if np.array_equal(chain[0], chain[-1]):  # from a junction round to it: the whole loop
        for forward in (True, False):
            follow = Follow(finder, k, forward, whole=True)
            piece = follow.piece(chain[0], chain[-1], hint)
            if piece and _follows(piece, chain):
                return piece, follow, hint
        return None
    start, end = finder.exact(k, hint[0], chain[0]), finder.exact(k, hint[1], chain[-1])
    # the shorter way round first; the one that follows the chain all along wins
    for forward in sorted((True, False), key=lambda f: (end - start) % n if f else (start - end) % n):
        follow = Follow(finder, k, forward)
        piece = follow.piece(chain[0], chain[-1], hint)
        if piece and _follows(piece, chain):
            return piece, follow, hint
    return None


def _follows(piece: list[np.ndarray], chain: np.ndarray) -> bool:
    """Whether every point of the chain lies within MAX_OFF of the segments, and the
    segments within MAX_STRAY of the chain (they may hold a spur too thin for the samples
    to see, which the stacked drawing drew too; the wrong way round a loop strays far)."""
    drawn = np.vstack([_at(c, np.linspace(0, 1, _samples(c))) for c in piece])
    return _close_to(chain, drawn, MAX_OFF) and _close_to(drawn, chain, MAX_STRAY)


def local_polyline(follow: Follow, near: np.ndarray, radius: float) -> np.ndarray:
    """The followed loop's sample points within ``radius`` of ``near``, in order along it
    (the nearest run of them)."""
    f = follow.finder
    pts = f.points[f.rows(follow.loop)]
    close = np.array(sorted(f.loop_tree(follow.loop).query_ball_point(near, radius)), np.int64)
    if len(close) < 2:
        return pts[close]
    # the run round the nearest sample (the loop may pass near twice)
    best = close[np.argmin(np.hypot(*(pts[close] - near).T))]
    lo = hi = best
    m = len(pts)
    wanted = set(close.tolist())
    while (lo - 1) % m in wanted and (lo - 1) % m != hi:
        lo = (lo - 1) % m
    while (hi + 1) % m in wanted and (hi + 1) % m != lo:
        hi = (hi + 1) % m
    index = np.arange(lo, lo + (hi - lo) % m + 1) % m
    return pts[index]


def crossing_near(a: np.ndarray, b: np.ndarray, near: np.ndarray) -> np.ndarray | None:
    """The crossing of polylines ``a`` and ``b`` nearest ``near``, or None."""
    if len(a) < 2 or len(b) < 2:
        return None
    p, r = a[:-1, None], (a[1:] - a[:-1])[:, None]
    q, s = b[None, :-1], (b[1:] - b[:-1])[None]
    denom = r[..., 0] * s[..., 1] - r[..., 1] * s[..., 0]
    qp = q - p
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[..., 0] * s[..., 1] - qp[..., 1] * s[..., 0]) / denom
        u = (qp[..., 0] * r[..., 1] - qp[..., 1] * r[..., 0]) / denom
    hit = (np.abs(denom) > 1e-12) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
    if not hit.any():
        return None
    i, j = np.nonzero(hit)
    points = p[i, 0] + t[i, j, None] * r[i, 0]
    return points[np.argmin(np.hypot(*(points - near).T))]


def layout(piece: list[np.ndarray]) -> tuple[np.ndarray, list[int]]:
    """Segments as the Scene's open layout: (its start, then each segment's points after its
    start; degrees)."""
    return np.vstack([piece[0][:1]] + [c[1:] for c in piece]), [len(c) - 1 for c in piece]
