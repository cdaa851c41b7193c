"""Stroke dashing (``stroke-dasharray``, ``stroke-dashoffset``) as geometry: the dashes of a
Path as a new Path of open subpaths, one per dash, whose points (and per-point widths) are
torch functions of the original ones, so that gradients reach them.

Semantics are SVG 2's as resvg (tiny-skia's dash.rs) draws them: a pattern with a negative
value, a non-finite value or a zero sum draws solid (``dash_pattern`` answers None); an
odd-length pattern is repeated to even length; the offset shifts the pattern's start
(negative allowed, taken modulo the pattern's length); each subpath starts the pattern
anew; a closed subpath is dashed along its closing segment too, and a dash that runs
through its start point continues into the first dash (one dash, joined there); an
"on" interval that starts at the end of an open subpath is not drawn; a zero-length
subpath has no dashes; a zero-length dash is a zero-length subpath (the core draws it as
a dot with round caps, an axis-aligned square with square caps, nothing with butt caps,
as tiny-skia's stroker does).

Arc lengths are integrated numerically in float64 on detached values (adaptive
Gauss-Legendre, 8 nodes: a sub-interval is halved where its halves disagree with it); a
dash's ends are found by Newton's method on them and the segments split there by de
Casteljau (the blossom, in torch). Gradients: a dash end at arc length s sits at
parameter t(s) of its segment. Its value is computed detached, and then t is made
differentiable by the implicit function theorem: t - (l(t) - l(t).detach()) / |B'(t)|,
with l the arc length from the subpath's start as a linear function of the points whose
coefficients are dl/d(points) (integrated like the lengths), so a control point that
lengthens the path upstream moves the dash ends along it, as a finite difference sees.
Ends clipped to a subpath's start or end are fixed parameters (0 or 1).
"""
from __future__ import annotations

import functools
import math

from typing import TYPE_CHECKING

import numpy as np

from vecfit import limits

from . import arrays
from .model import Circle, Ellipse, Path, Rect

if TYPE_CHECKING:
    import torch



@functools.cache
def _gauss_legendre() -> tuple[np.ndarray, np.ndarray]:
    """The 8-point Gauss-Legendre rule on [0, 1]: nodes and weights (made on first use:
    numpy.polynomial is a hundredth of a second of `vecfit render`'s start-up)."""
    x, w = np.polynomial.legendre.leggauss(8)
    return (x + 1) / 2, w / 2
_MAX_HALVINGS = 12        # the shortest sub-interval: 1/4096 of a segment's parameter
_TOLERANCE = 1e-8        # per unit of parameter, relative to the control polygon's length
_NEWTON_STEPS = 12

# Degree elevation to cubics (the curve and its parametrization are unchanged).
_ELEVATE = {
    1: np.array([[1, 0], [2 / 3, 1 / 3], [1 / 3, 2 / 3], [0, 1]]),
    2: np.array([[1, 0, 0], [1 / 3, 2 / 3, 0], [0, 2 / 3, 1 / 3], [0, 0, 1]]),
    3: np.eye(4),
}


# ------------------------------------------------------------------------- pattern

def dash_pattern(array) -> tuple[float, ...] | None:
    """The pattern to dash with, even in length, or None where SVG draws the stroke solid
    (no pattern, an empty one, a negative or non-finite value, a zero sum)."""
    if array is None:
        return None
    try:
        values = [float(v) for v in array]
    except (TypeError, ValueError):
        return None
    if not values or any(not math.isfinite(v) or math.copysign(1.0, v) < 0 for v in values):
        return None  # (resvg: -0 is negative too)
    if len(values) % 2:
        values = values * 2
    total = sum(values)  # (math.fsum raises on overflow)
    if not (total > 0 and math.isfinite(total)):
        return None
    return tuple(values)


def _phase(pattern: tuple[float, ...], offset: float) -> tuple[int, float]:
    """(index of the interval the subpaths start in, what is left of it), as tiny-skia."""
    period = math.fsum(pattern)
    if offset < 0:
        offset = -offset
        if offset > period:
            offset %= period
        offset = period - offset
        if offset == period:
            offset = 0.0
    elif offset >= period:
        offset %= period
    for i, gap in enumerate(pattern):
        if offset > gap or (offset == gap and gap != 0):
            offset -= gap
        else:
            return i, gap - offset
    return 0, pattern[0]


# --------------------------------------------------------------------- segments

class _Segments:
    """A path's segments as cubics in float64 (detached), their lengths, and the table of
    sub-interval lengths used to find parameters at arc lengths."""

    def __init__(self, path: Path):
        degrees = np.asarray(path.degrees, dtype=np.int64)
        index = np.full((len(degrees), 4), -1, dtype=np.int64)
        sub_of = np.zeros(len(degrees), dtype=np.int64)
        for s, ((first, count, closed), (p0, n)) in enumerate(zip(path.subpaths, path.subpath_point_ranges())):
            d = degrees[first:first + count]
            starts = np.concatenate([[0], np.cumsum(d)[:-1]]) if count else d
            idx = starts[:, None] + np.arange(4)
            idx = p0 + (idx % max(n, 1) if closed else idx)
            index[first:first + count] = np.where(np.arange(4) <= d[:, None], idx, -1)
            sub_of[first:first + count] = s
        self.degrees = degrees
        self.index = index            # [G, 4] point indices (-1: unused)
        self.sub_of = sub_of
        pts = np.asarray(arrays.to_numpy(path.points), np.float64).reshape(-1, 2)
        cubic = np.zeros((len(degrees), 4, 2))
        for d in (1, 2, 3):
            rows = np.nonzero(degrees == d)[0]
            if len(rows):
                cubic[rows] = np.einsum("ij,sjc->sic", _ELEVATE[d], pts[index[rows, :d + 1]])
        self.cubic = cubic
        h = self.hodograph = 3 * (cubic[:, 1:] - cubic[:, :-1])  # B'(t) = a t^2 + b t + c
        a, b, c = h[:, 0] - 2 * h[:, 1] + h[:, 2], 2 * (h[:, 1] - h[:, 0]), h[:, 0]
        dot = lambda u, v: (u * v).sum(-1)  # noqa: E731
        self.quartic = np.stack([dot(a, a), 2 * dot(a, b), dot(b, b) + 2 * dot(a, c), 2 * dot(b, c), dot(c, c)], -1)
        self._lengths()

    def speed(self, seg: np.ndarray, t: np.ndarray) -> np.ndarray:
        """|B'(t)| of segments seg (an array of t's shape)."""
        return self._speed(self.quartic[seg], t)

    @staticmethod
    def _speed(q: np.ndarray, t: np.ndarray) -> np.ndarray:
        """sqrt of the quartics q [..., 5] (t^4 first) at t [...]."""
        v = q[..., 0] * t + q[..., 1]
        for j in (2, 3, 4):
            v = v * t + q[..., j]
        return np.sqrt(np.maximum(v, 0.0))

    def _gl(self, seg: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Length of segments seg over parameters [a, b] (arrays of one shape), one GL rule."""
        gl_x, gl_w = _gauss_legendre()
        t = a[..., None] + (b - a)[..., None] * gl_x
        s = self._speed(self.quartic[seg][..., None, :], t)
        return (b - a) * (s @ gl_w)

    def _lengths(self) -> None:
        """Per segment, its length and a table of sub-intervals of its parameter (sorted,
        from ``part_start[g]``, ``m[g]`` of them: ``part_lo``, ``part_hi`` and their lengths
        ``part``): adaptive quadrature, halving where the halves' sum disagrees with the
        whole (lines: one, exact)."""
        G = len(self.degrees)
        lines = np.nonzero(self.degrees == 1)[0]
        line_len = np.sqrt(((self.cubic[lines, 3] - self.cubic[lines, 0]) ** 2).sum(-1))
        done = [(lines, np.zeros(len(lines)), np.ones(len(lines)), line_len)]  # (segment, lo, hi, length)
        polygon = np.sqrt((np.diff(self.cubic, axis=1) ** 2).sum(-1)).sum(-1)
        seg = np.nonzero(self.degrees != 1)[0]
        a, b = np.zeros(len(seg)), np.ones(len(seg))
        whole = self._gl(seg, a, b)
        for depth in range(1, _MAX_HALVINGS + 1):
            if not len(seg):
                break
            mid = (a + b) / 2
            left, right = self._gl(seg, a, mid), self._gl(seg, mid, b)
            ok = np.abs(left + right - whole) <= _TOLERANCE * polygon[seg] * (b - a)
            if depth == _MAX_HALVINGS:
                ok[:] = True
            ok |= ~np.isfinite(whole)
            done.append((np.concatenate([seg[ok], seg[ok]]), np.concatenate([a[ok], mid[ok]]),
                         np.concatenate([mid[ok], b[ok]]), np.concatenate([left[ok], right[ok]])))
            no = ~ok
            seg, a, b, whole = (np.concatenate([seg[no], seg[no]]), np.concatenate([a[no], mid[no]]),
                                np.concatenate([mid[no], b[no]]), np.concatenate([left[no], right[no]]))
        part_seg, lo, hi, part = (np.concatenate(v) for v in zip(*done))
        order = np.lexsort((lo, part_seg))
        part_seg, self.part_lo, self.part_hi, self.part = part_seg[order], lo[order], hi[order], part[order]
        self.m = np.bincount(part_seg, minlength=G).astype(np.int64)
        self.part_start = np.concatenate([[0], np.cumsum(self.m)[:-1]]).astype(np.int64)
        self.part_key = part_seg + self.part_lo  # increasing: (segment, lo) in one number
        length = np.bincount(part_seg, weights=self.part, minlength=G).astype(np.float64)
        length[~np.isfinite(length)] = np.nan
        self.length = length

    def length_gradient(self, seg: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """d(length over [a, b])/d(cubic control points) of segments seg: [k, 4, 2]."""
        gl_x, gl_w = _gauss_legendre()
        t = a[:, None] + (b - a)[:, None] * gl_x           # [k, 8]
        h = self.hodograph[seg]                            # [k, 3, 2]
        u = 1 - t
        basis2 = np.stack([u * u, 2 * u * t, t * t], -1)   # [k, 8, 3]
        tangent = basis2 @ h                               # [k, 8, 2]
        norm = np.sqrt((tangent ** 2).sum(-1, keepdims=True))
        unit = np.where(norm > 0, tangent / np.where(norm > 0, norm, 1), 0.0)
        # d/dt of the cubic Bernstein basis: 3 (b2_{i-1} - b2_i)
        db = 3 * (np.concatenate([np.zeros_like(basis2[..., :1]), basis2], -1)
                  - np.concatenate([basis2, np.zeros_like(basis2[..., :1])], -1))  # [k, 8, 4]
        w = (b - a)[:, None, None] * gl_w[:, None]           # [k, 8, 1]
        return db.transpose(0, 2, 1) @ (w * unit)

    def part_at(self, seg: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Index of the sub-interval holding parameter t of segment seg."""
        k = np.searchsorted(self.part_key, seg + t, side="right") - 1
        return np.clip(k, self.part_start[seg], self.part_start[seg] + self.m[seg] - 1)

    def parameters(self, seg: np.ndarray, s: np.ndarray) -> np.ndarray:
        """Parameters t in [0, 1] at arc lengths s (in [0, length]) along segments seg."""
        seg = np.asarray(seg, dtype=np.int64)
        s = np.clip(np.asarray(s, dtype=np.float64), 0, self.length[seg])
        # The sub-interval holding s: by the running sum of all sub-intervals' lengths.
        running = np.concatenate([[0.0], np.cumsum(self.part)])
        base = running[self.part_start[seg]]
        at = np.searchsorted(running, base + s, side="left") - 1
        at = np.clip(at, self.part_start[seg], self.part_start[seg] + self.m[seg] - 1)
        goal = s - (running[at] - base)
        piece = self.part[at]
        lo, hi = self.part_lo[at], self.part_hi[at]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = lo + (hi - lo) * np.where(piece > 0, np.clip(goal / piece, 0, 1), 0.0)
        curved = np.nonzero(self.degrees[seg] != 1)[0]  # lines: t is proportional to s
        if len(curved):
            c = curved
            g, origin, goal, tc = seg[c], lo[c], goal[c], t[c]
            a, b = lo[c].copy(), hi[c].copy()  # a bracket: the length grows with t
            for _ in range(_NEWTON_STEPS):
                f = self._gl(g, origin, tc) - goal
                a = np.where(f < 0, tc, a)
                b = np.where(f > 0, tc, b)
                v = self.speed(g, tc)
                with np.errstate(divide="ignore", invalid="ignore"):
                    step = tc - f / v
                inside = np.isfinite(step) & (step >= a) & (step <= b)
                tc = np.where(inside, step, (a + b) / 2)
            t[c] = tc
        return np.clip(t, 0.0, 1.0)


# ------------------------------------------------------------------------- dashing

def outline_path(geometry) -> Path | None:
    """The geometry as the path its stroke follows (rects from (x + rx, y), circles and
    ellipses from (cx + rx, cy), clockwise on the screen, as SVG 2 defines); None when it
    has no outline (a zero-size rect, a radius not above 0)."""
    from .geometry import ellipse_as_path, rect_as_path  # (torch: made as tensors)
    if isinstance(geometry, Rect):
        return rect_as_path(geometry)
    if isinstance(geometry, (Circle, Ellipse)):
        return ellipse_as_path(geometry)
    return geometry


def dash_count(path: Path, pattern: tuple[float, ...], width: float = 0.0) -> float:
    """What the pattern's dashes along the path count against limits.MAX_DASHES: about how
    many dashes it makes (as tiny-skia estimates, plus the pattern's length per subpath:
    the work of starting it anew), times max(1, width / the pattern's length). Dashes
    closer than the stroke is wide overlap that many neighbours, and the backward pass's
    work grows with the product (2 x 10^4 dashes each overlapping 2,000: 5 minutes)."""
    return _estimate(_Segments(path), path, pattern, width)


class DashBudget:
    """The dashes one scene may have, limits.MAX_DASHES, counted shape after shape as
    dash_count counts them: the one count that the SVG reader (which leaves a pattern out
    and notes it) and the packer (which draws it solid, with a warning, for a Scene made
    otherwise) both take from."""

    def __init__(self):
        self.left = float(limits.MAX_DASHES)

    def take(self, path: Path, pattern: tuple[float, ...], width: float = 0.0) -> bool:
        """Whether the pattern's dashes along ``path`` (a stroke ``width`` wide) fit in
        what is left; if they do, they are taken from it."""
        return self.spend(dash_count(path, pattern, width))

    def spend(self, count: float) -> bool:
        if not count <= self.left:  # (a non-finite count never fits)
            return False
        self.left -= count
        return True


def _estimate(segs: _Segments, path: Path, pattern: tuple[float, ...], width: float) -> float:
    total = float(np.nansum(segs.length))
    period = math.fsum(pattern)
    overlap = max(1.0, width / period) if math.isfinite(width) else math.inf
    if not math.isfinite(total):
        return math.inf
    return (total * (len(pattern) // 2) / period + len(pattern) * len(path.subpaths)) * overlap


def _intervals(length: float, closed: bool, pattern: tuple[float, ...], first_index: int,
               first_len: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The dashes of one subpath of this length: ranges of arc length (a, b) and the dash
    each belongs to (a closed subpath's last dash may run on into its first: two ranges)."""
    n = len(pattern)
    period = math.fsum(pattern)
    cycles = int(length // period) + 2
    rest = [pattern[(first_index + 1 + k) % n] for k in range(n)]
    lens = np.concatenate([[first_len], np.tile(rest, cycles)])
    kinds = (first_index + np.arange(len(lens))) % n
    starts = np.concatenate([[0.0], np.cumsum(lens)[:-1]])
    keep = starts < length
    starts, lens, kinds = starts[keep], lens[keep], kinds[keep]
    on = kinds % 2 == 0
    if closed:
        on[0] = False  # the first dash comes at the end, joined to the last when they meet
    a, b = starts[on], np.minimum(starts + lens, length)[on]
    dash = np.arange(len(a))
    if closed and first_index % 2 == 0:
        head = min(first_len, length)
        joined = on[-1] and len(on) > 1
        if not joined or head > 0:
            a, b = np.append(a, 0.0), np.append(b, head)
            dash = np.append(dash, len(dash) - 1 if joined else len(dash))
    return a, b, dash


def dash_path(path: Path, pattern, offset: float = 0.0, budget: DashBudget | None = None,
              width: float = 0.0) -> Path | None:
    """The dashes of ``path`` for ``pattern`` (a dash_pattern) and ``offset``, both in the
    path's own units, as open subpaths; None where the stroke is drawn solid: an invalid
    pattern or offset, or a dash_count (for a stroke ``width`` wide) that the scene's
    ``budget`` (a new one by default: limits.MAX_DASHES) has no room for."""
    import torch

    pattern = dash_pattern(pattern)
    offset = float(offset)
    if pattern is None or not math.isfinite(offset):
        return None
    segs = _Segments(path)
    if not (DashBudget() if budget is None else budget).spend(_estimate(segs, path, pattern, width)):
        return None
    first_index, first_len = _phase(pattern, offset)

    # Ranges of arc length per dash, per subpath.
    seg_start = np.zeros(len(segs.degrees))   # arc length where each segment starts in its subpath
    parts = []  # per subpath: (a, b, dash, subpath length)
    dashes = 0
    for first, count, closed in path.subpaths:
        if count == 0:
            continue
        lengths = segs.length[first:first + count]
        L = float(lengths.sum())
        if not (L > 0 and math.isfinite(L)):
            continue  # a zero-length subpath has no dashes (resvg)
        seg_start[first:first + count] = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
        a, b, dash = _intervals(L, bool(closed), pattern, first_index, first_len)
        parts.append((a, b, dash + dashes, np.full(len(a), L), np.full(len(a), first), np.full(len(a), count)))
        dashes += int(dash.max()) + 1 if len(dash) else 0
    if not dashes:
        return Path(points=path.points[:0], degrees=np.zeros(0, dtype=np.int64), subpaths=[],
                    widths=None if path.widths is None else path.widths[:0])
    r_a, r_b, r_dash, r_len, r_first, r_count = (np.concatenate(v) for v in zip(*parts))
    r_dash = r_dash.astype(np.int64)
    r_first, r_count = r_first.astype(np.int64), r_count.astype(np.int64)

    # The segment and parameter of each range's ends: a start at a segment boundary is in
    # the next segment (t = 0), an end in the previous one (t = 1).
    last = r_first + r_count - 1
    seg_end = seg_start + segs.length
    seg_a = _search(seg_end, r_first, last, r_a, right=True)
    seg_b = _search(seg_end, r_first, last, r_b, right=False)
    point = r_a == r_b
    seg_b[point] = seg_a[point]
    t_a = segs.parameters(seg_a, r_a - seg_start[seg_a])
    t_b = segs.parameters(seg_b, r_b - seg_start[seg_b])
    t_b[point] = t_a[point]
    # ends clipped to the subpath's start or end: fixed parameters
    t_a[r_a <= 0] = 0.0
    t_b[r_b >= r_len] = 1.0

    # Pieces: per range, the segments it covers, with their parameter intervals.
    n_pieces = np.where(point, 1, seg_b - seg_a + 1)
    p_range = np.repeat(np.arange(len(r_a)), n_pieces)
    p_seg = seg_a[p_range] + (np.arange(len(p_range)) - np.repeat(np.cumsum(n_pieces) - n_pieces, n_pieces))
    p_first = np.concatenate([[True], p_range[1:] != p_range[:-1]])
    p_last = np.concatenate([p_range[1:] != p_range[:-1], [True]])
    p_point = point[p_range]

    # Differentiable parameters at the ends that are not clipped.
    needs_grad = path.points.requires_grad
    t_a_t = torch.from_numpy(t_a)
    t_b_t = torch.from_numpy(t_b)
    if needs_grad:
        free_a = (r_a > 0) & (r_a < r_len)
        free_b = (r_b > 0) & (r_b < r_len) & ~point
        ends_seg = np.concatenate([seg_a[free_a], seg_b[free_b]])
        ends_t = np.concatenate([t_a[free_a], t_b[free_b]])
        if len(ends_seg):
            shift = _implicit_shift(path, segs, ends_seg, ends_t)
            na = int(free_a.sum())
            t_a_t = t_a_t.index_put((torch.from_numpy(np.nonzero(free_a)[0]),), t_a_t[free_a] + shift[:na])
            t_b_t = t_b_t.index_put((torch.from_numpy(np.nonzero(free_b)[0]),), t_b_t[free_b] + shift[na:])
            t_b_t = torch.where(torch.from_numpy(point), t_a_t, t_b_t)
    t0 = torch.where(torch.from_numpy(p_first), t_a_t[p_range], torch.zeros(len(p_range), dtype=torch.float64))
    t1 = torch.where(torch.from_numpy(p_last), t_b_t[p_range], torch.ones(len(p_range), dtype=torch.float64))

    # Control points (and widths as a third column) of every piece, by degree.
    values = path.points.reshape(-1, 2)
    if path.widths is not None:
        values = torch.cat([values, path.widths.reshape(-1, 1).to(values.dtype)], dim=1)
    values = values.double()
    p_deg = np.where(p_point, 1, segs.degrees[p_seg])
    sizes = p_deg + 1
    row_of_piece = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    chunks, order = [], []
    for d in (1, 2, 3):
        for is_point in (False, True):
            sel = np.nonzero((segs.degrees[p_seg] == d) & (p_point == is_point))[0]
            if not len(sel):
                continue
            ctrl = values[torch.from_numpy(segs.index[p_seg[sel], :d + 1])]  # [k, d+1, C]
            a, b = t0[sel], t1[sel]
            if is_point:
                q = _blossom(ctrl, [a] * d)
                chunks.append(torch.stack([q, q], dim=1).reshape(-1, values.shape[1]))
                order.append(row_of_piece[sel][:, None] + np.arange(2))
            else:
                sub = [_blossom(ctrl, [b] * i + [a] * (d - i)) for i in range(d + 1)]
                chunks.append(torch.stack(sub, dim=1).reshape(-1, values.shape[1]))
                order.append(row_of_piece[sel][:, None] + np.arange(d + 1))
    rows_all = torch.cat(chunks)
    position = np.empty(int(sizes.sum()), dtype=np.int64)
    position[np.concatenate([o.reshape(-1) for o in order])] = np.arange(len(position))
    # A dash's points: its first piece whole, then each later piece without its start.
    p_dash_first = np.concatenate([[True], r_dash[p_range[1:]] != r_dash[p_range[:-1]]])
    keep = np.ones(len(position), dtype=bool)
    keep[row_of_piece[~p_dash_first]] = False
    out = rows_all[torch.from_numpy(position[keep])]
    points = out[:, :2].to(path.points.dtype)
    widths = out[:, 2].to(path.widths.dtype) if path.widths is not None else None

    # Subpaths: one open subpath per dash.
    p_dash = r_dash[p_range]
    counts = np.bincount(p_dash, minlength=dashes)
    counts = counts[counts > 0]
    firsts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    subpaths = [(int(f), int(c), False) for f, c in zip(firsts, counts)]
    return Path(points=points, degrees=p_deg.astype(np.int64), subpaths=subpaths, widths=widths)


def _search(seg_end: np.ndarray, first: np.ndarray, last: np.ndarray, s: np.ndarray, right: bool) -> np.ndarray:
    """Per query, the segment in [first, last] holding arc length s of its subpath: the
    first whose end is past s (right) or at or past s (not right), the last one if none."""
    lo, hi = first.copy(), last.copy()
    while True:  # a bisection of all queries at once (segment ends increase in a subpath)
        open_ = lo < hi
        if not open_.any():
            return lo
        mid = (lo + hi) // 2
        end = seg_end[mid]
        past = end > s if right else end >= s
        hi = np.where(open_ & past, mid, hi)
        lo = np.where(open_ & ~past, mid + 1, lo)


def _blossom(ctrl: torch.Tensor, args: list[torch.Tensor]) -> torch.Tensor:
    """The blossom of the Béziers ctrl [k, d+1, C] at arguments (d tensors [k])."""
    q = ctrl
    for u in args:
        u = u[:, None, None]
        q = (1 - u) * q[:, :-1] + u * q[:, 1:]
    return q[:, 0]


def _implicit_shift(path: Path, segs: _Segments, seg: np.ndarray, t: np.ndarray) -> torch.Tensor:
    """Zero-valued tensors whose gradient is dt/d(points) for the ends at parameters t of
    segments seg that sit at fixed arc lengths: -(dl/d points) / |B'(t)|, with l the arc
    length from the subpath's start to the end.

    dl/dC of a cubic's control points C over [a, b] is the integral of u(t) b_i'(t), u the
    unit tangent and b_i the Bernstein basis (same quadrature as the lengths, in numpy);
    torch then only sees linear functions of the points with those coefficients (their
    values are subtracted out), so the graph stays small."""
    import torch

    G = len(segs.degrees)
    # Coefficients per sub-interval, summed per segment and per end.
    part_coef = segs.length_gradient(np.repeat(np.arange(G), segs.m), segs.part_lo, segs.part_hi)  # [P, 4, 2]
    running = np.concatenate([np.zeros((1, 4, 2)), np.cumsum(part_coef, axis=0)])
    seg_coef = running[segs.part_start + segs.m] - running[segs.part_start]
    at = segs.part_at(seg, t)
    end_coef = running[at] - running[segs.part_start[seg]] + segs.length_gradient(seg, segs.part_lo[at], t)
    pts = path.points.reshape(-1, 2).double()

    def linear(coef: np.ndarray, g: np.ndarray) -> torch.Tensor:
        """sum of coef (on the cubic's control points) times the segments' own points."""
        out = torch.zeros(len(g), dtype=torch.float64)
        for d in (1, 2, 3):
            rows = np.nonzero(segs.degrees[g] == d)[0]
            if len(rows):
                c = np.einsum("ji,sjc->sic", _ELEVATE[d], coef[rows])  # to the degree-d points
                p = pts[torch.from_numpy(segs.index[g[rows], :d + 1])]
                out = out.index_put((torch.from_numpy(rows),), (torch.from_numpy(c) * p).sum((1, 2)))
        return out

    seg_len = linear(seg_coef, np.arange(G))
    csum = torch.cumsum(seg_len, 0) - seg_len  # the lengths before each segment ...
    first_of = np.array([path.subpaths[s][0] for s in range(len(path.subpaths))], dtype=np.int64)[segs.sub_of]
    before = csum - csum[torch.from_numpy(first_of)]  # ... in its subpath
    ell = before[torch.from_numpy(seg)] + linear(end_coef, seg)
    v = segs.speed(seg, t)
    inv = torch.from_numpy(np.where(v > 1e-12 * np.maximum(segs.length[seg], 1e-300), 1 / np.maximum(v, 1e-300), 0.0))
    return -(ell - ell.detach()) * inv
