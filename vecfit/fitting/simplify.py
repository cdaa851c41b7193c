"""Fewer nodes after the refinement: two segments joined into one where the picture cannot
tell, then a brief refinement.

Every node between two segments of a path (not a subpath's start) is a candidate, but for
corners (turning more than CORNER degrees) between segments longer than twice the error
allowed. The two segments (lines and quadratics raised to cubics) are sampled and one cubic
from the first segment's start to the second's end is fitted to the samples (Schneider's
fit: the inner control points on the outer tangents, so the joins to the neighbours keep
their directions; the samples' parameters from the split point that fits best, then two
Newton reparameterisations). A fit whose control points lie within ``lines`` pixels of its
chord is a line, and two lines join only into a line. A candidate is kept when its samples
are within ``max_error`` pixels of the new curve (0.5 px: at 1.5, Noto emoji lost 0.23 dB
as resvg draws them where vecfit's renders measured 0.07), and priced by the squared error
it would add: the area between the curves (mean distance times length) times the squared
contrast across the edge in the current render (its colour 1.5 px to either side).

Candidates are taken cheapest first, a node only where neither of its segments was changed
this round; how many is decided on the picture itself: the longest prefix whose render
stays within the budget is found by bisection, a few renders a round. The budget is a share
(``budget_db``) of the squared error less the renderer's sampling noise (estimated from a
second render with another seed). A second round joins what the first made. Then the loop
runs a few dozen iterations on the geometry (the colours kept) at half the rate the fit
ended at, and is undone if it measured worse: the pass never leaves the picture more than
``budget_db`` below where it found it, as measured by the same renders.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from vecfit.scene.arrays import floats_torch, is_tensor, to_numpy
from vecfit.scene.model import Path
from vecfit.scene.placement import shape_matrices
from vecfit.scene.segments import layout_of, segments_of

SAMPLES = 12      # per segment of a pair
REPARAM = 2       # Newton reparameterisations after the split's search
CONTRAST_PX = 1.5  # where the edge's two sides are read, pixels from it
BRIEF_RATE = 0.05  # the brief refinement's rates: this share of the fit's (half where the fit ended)
CORNER = 90.0     # degrees: a node turning more than this is a corner (kept unless its segments are short)


def _cubic(ctrl: np.ndarray) -> np.ndarray:
    """A line, quadratic or cubic as a cubic's 4 control points."""
    d = len(ctrl) - 1
    if d == 3:
        return ctrl
    if d == 1:
        return np.stack([ctrl[0], (2 * ctrl[0] + ctrl[1]) / 3, (ctrl[0] + 2 * ctrl[1]) / 3, ctrl[1]])
    return np.stack([ctrl[0], (ctrl[0] + 2 * ctrl[1]) / 3, (2 * ctrl[1] + ctrl[2]) / 3, ctrl[2]])


def _bernstein(u: np.ndarray) -> np.ndarray:
    """[..., 4] cubic Bernstein weights at u."""
    v = 1 - u
    return np.stack([v ** 3, 3 * v * v * u, 3 * v * u * u, u ** 3], -1)


def _eval(c: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Cubics c [N, 4, 2] at parameters u [N, M]: [N, M, 2]."""
    return np.matmul(_bernstein(u), c)


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(n > 1e-12, v / np.maximum(n, 1e-12), 0.0)


def _tangents(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The first segment's start direction and the second's end direction (backwards),
    from the first control point that differs from the end."""
    t1 = _unit(a[:, 1] - a[:, 0])
    for k in (2, 3):
        t1 = np.where((np.linalg.norm(t1, axis=-1) > 0)[:, None], t1, _unit(a[:, k] - a[:, 0]))
    t2 = _unit(b[:, 2] - b[:, 3])
    for k in (1, 0):
        t2 = np.where((np.linalg.norm(t2, axis=-1) > 0)[:, None], t2, _unit(b[:, k] - b[:, 3]))
    return t1, t2


def fit_pairs(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, ...]:
    """One cubic for each pair of consecutive cubics a[i], b[i] ([N, 4, 2], b[i] starting
    where a[i] ends): (the cubics [N, 4, 2], the largest distance of the pair's samples from
    it [N], their mean distance [N], the pair's length [N]; samples [N, M, 2]).

    The samples' parameters on the new cubic are taken as each segment's own, scaled into
    [0, s] and [s, 1] (exact where the pair is one cubic split at s); s is searched on a
    grid, then refined, then the parameters polished by Newton steps."""
    n = len(a)
    t = np.linspace(0.0, 1.0, SAMPLES + 1)
    pts = np.concatenate([_eval(a, np.broadcast_to(t, (n, len(t)))),
                          _eval(b, np.broadcast_to(t[1:], (n, len(t) - 1)))], 1)
    steps = np.linalg.norm(np.diff(pts, axis=1), axis=-1)
    length = steps.sum(1)
    p0, p3 = pts[:, 0], pts[:, -1]
    t1, t2 = _tangents(a, b)
    chord = np.linalg.norm(p3 - p0, axis=-1)

    def fit_at(u):
        bern = _bernstein(u)  # [N, M, 4]
        rest = pts - (bern[..., 0:1] + bern[..., 1:2]) * p0[:, None] - (bern[..., 2:3] + bern[..., 3:4]) * p3[:, None]
        b1, b2 = bern[..., 1], bern[..., 2]  # t1 and t2 are unit vectors
        c11 = (b1 * b1).sum(1)
        c12 = (b1 * b2).sum(1) * (t1 * t2).sum(-1)
        c22 = (b2 * b2).sum(1)
        x1 = (b1 * (rest * t1[:, None]).sum(-1)).sum(1)
        x2 = (b2 * (rest * t2[:, None]).sum(-1)).sum(1)
        det = c11 * c22 - c12 * c12
        ok = np.abs(det) > 1e-12 * np.maximum(c11 * c22, 1e-30)
        alpha1 = np.where(ok, (x1 * c22 - x2 * c12) / np.where(ok, det, 1.0), chord / 3)
        alpha2 = np.where(ok, (c11 * x2 - c12 * x1) / np.where(ok, det, 1.0), chord / 3)
        bad = (alpha1 < 1e-6 * chord) | (alpha2 < 1e-6 * chord)
        alpha1 = np.where(bad, chord / 3, alpha1)
        alpha2 = np.where(bad, chord / 3, alpha2)
        c = np.stack([p0, p0 + alpha1[:, None] * t1, p3 + alpha2[:, None] * t2, p3], 1)
        return c, ((_eval(c, u) - pts) ** 2).sum((1, 2))

    def at_share(share):
        share = share[:, None]
        return np.concatenate([share * t, share + (1 - share) * t[1:]], 1)

    def newton(c, u):
        # each sample's parameter moved to its nearest point: (Q(u) - d) . Q'(u) = 0
        q = _eval(c, u)
        d1 = 3 * np.diff(c, axis=1)  # [N, 3, 2]
        d2 = 2 * np.diff(d1, axis=1)  # [N, 2, 2]
        v = 1 - u
        q1 = np.matmul(np.stack([v * v, 2 * v * u, u * u], -1), d1)
        q2 = np.matmul(np.stack([v, u], -1), d2)
        diff = q - pts
        num = (diff * q1).sum(-1)
        den = (q1 * q1).sum(-1) + (diff * q2).sum(-1)
        step = np.where(np.abs(den) > 1e-12, num / np.where(np.abs(den) > 1e-12, den, 1.0), 0.0)
        u = np.clip(u - step, 0.0, 1.0)
        u[:, 0], u[:, -1] = 0.0, 1.0
        return u

    best_s = steps[:, :SAMPLES].sum(1) / np.maximum(length, 1e-12)
    best_c, best_r = fit_at(at_share(best_s))
    for grid in (np.linspace(0.1, 0.9, 8), np.linspace(-0.06, 0.06, 5), np.linspace(-0.02, 0.02, 5),
                 np.linspace(-0.006, 0.006, 5)):
        centre = best_s.copy() if grid[0] < 0 else np.zeros(n)
        for g in grid:
            s = np.clip(centre + g, 0.01, 0.99)
            c, r = fit_at(at_share(s))
            better = r < best_r
            best_s, best_r = np.where(better, s, best_s), np.where(better, r, best_r)
            best_c = np.where(better[:, None, None], c, best_c)
    u, c = at_share(best_s), best_c
    for _ in range(REPARAM):
        u = newton(c, u)
        c2, r = fit_at(u)
        c = c2
    for _ in range(2):  # the distances: to each sample's nearest point of the fit
        u = newton(c, u)
    dist = np.linalg.norm(_eval(c, u) - pts, axis=-1)
    return c, dist.max(1), dist.mean(1), length, pts


def _straight(c: np.ndarray, tolerance: np.ndarray) -> np.ndarray:
    """Whether each cubic's inner control points lie within ``tolerance`` of its chord,
    between its ends."""
    p0, p3 = c[:, 0], c[:, 3]
    d = p3 - p0
    ll = (d * d).sum(-1)
    ok = ll > 1e-18
    out = ok.copy()
    for k in (1, 2):
        w = c[:, k] - p0
        s = (w * d).sum(-1) / np.where(ok, ll, 1.0)
        cross = np.abs(w[:, 0] * d[:, 1] - w[:, 1] * d[:, 0]) / np.sqrt(np.where(ok, ll, 1.0))
        out &= (cross <= tolerance) & (s >= 0) & (s <= 1)
    return out


@dataclasses.dataclass
class _Candidate:
    shape: int
    subpath: int
    node: int        # the segment index (in the subpath) whose end is dropped
    ctrl: np.ndarray  # the joined segment's control points, shape units
    cost: float


def _subpath_segments(path: Path) -> list[tuple[list[np.ndarray], bool]]:
    pts = np.asarray(to_numpy(path.points), np.float64)
    out = []
    for (first, count, closed), (p0, n) in zip(path.subpaths, path.subpath_point_ranges()):
        degs = [int(d) for d in path.degrees[first:first + count]]
        out.append((segments_of(pts[p0:p0 + n], degs, closed) if count else [], bool(closed)))
    return out


def _with_segments(path: Path, subs: list[tuple[list[np.ndarray], bool]]) -> Path:
    points, degrees, table = [], [], []
    for segs, closed in subs:
        if not segs:
            continue
        p, d = layout_of(segs, closed)
        table.append((len(degrees), len(d), closed))
        points.append(p)
        degrees += d
    flat = np.concatenate(points).astype(np.float32)
    return Path(points=floats_torch(flat) if is_tensor(path.points) else flat,
                degrees=np.array(degrees, np.int64), subpaths=table)


def _sample(image: np.ndarray, xy: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    x = np.clip(np.rint(xy[..., 0] - 0.5).astype(np.int64), 0, w - 1)
    y = np.clip(np.rint(xy[..., 1] - 0.5).astype(np.int64), 0, h - 1)
    return image[y, x]


def candidates(scene, shapes: dict[int, list], image: np.ndarray, size: tuple[int, int], max_error: float,
               lines: float, changed: dict[int, set] | None = None) -> list[_Candidate]:
    """Every node of the paths ``shapes`` (shape index -> _subpath_segments) that can go,
    priced; with ``changed`` ((shape, subpath) -> segment indices made last round), only
    nodes next to those."""
    mats = np.asarray(to_numpy(shape_matrices(scene, size[0], size[1])), np.float64)
    rows = []  # (shape, subpath, node)
    firsts, seconds = [], []
    for s, subs in shapes.items():
        for j, (segs, closed) in enumerate(subs):
            near = None if changed is None else changed.get((s, j))
            if changed is not None and not near:
                continue
            for k in range(len(segs) - 1):
                if near is not None and k not in near and k + 1 not in near:
                    continue
                rows.append((s, j, k))
                firsts.append(segs[k])
                seconds.append(segs[k + 1])
    if not rows:
        return []
    lines_both = np.array([len(x) == 2 and len(y) == 2 for x, y in zip(firsts, seconds)])
    a = np.stack([_cubic(x) for x in firsts])
    b = np.stack([_cubic(y) for y in seconds])
    shape_of = np.array([r[0] for r in rows])
    m = mats[shape_of]  # [N, 3, 3]: shape units -> image pixels
    to_px = lambda p: np.einsum("nij,n...j->n...i", m[:, :2, :2], p) + m[:, None, :2, 2]  # noqa: E731
    a_px, b_px = to_px(a), to_px(b)
    # a corner (the tangents turning by more than CORNER) between segments longer than
    # max_error cannot be joined within it: not fitted
    out_dir, back = _tangents(b_px, a_px)  # b's start direction; a's end direction, backwards
    turn = (out_dir * -back).sum(-1)
    span = np.minimum(np.linalg.norm(a_px[:, 3] - a_px[:, 0], axis=-1), np.linalg.norm(b_px[:, 3] - b_px[:, 0], axis=-1))
    fit = (turn >= np.cos(np.radians(CORNER))) | (span <= 2 * max_error)
    rows = [r for r, f in zip(rows, fit) if f]
    firsts = [x for x, f in zip(firsts, fit) if f]
    seconds = [x for x, f in zip(seconds, fit) if f]
    if not rows:
        return []
    a_px, b_px, m, lines_both = a_px[fit], b_px[fit], m[fit], lines_both[fit]
    c_px, err, mean, length, pts = fit_pairs(a_px, b_px)
    straight = _straight(c_px, np.full(len(rows), lines))
    # two lines join only into a line; a join close to its chord is written as one
    keep = (err <= max_error) & (~lines_both | straight)
    # contrast across the pair: the render 1.5 px either side of its samples
    normal = np.diff(pts, axis=1)
    normal = _unit(np.stack([-normal[..., 1], normal[..., 0]], -1))
    mid = 0.5 * (pts[:, 1:] + pts[:, :-1])
    jump = _sample(image, mid + CONTRAST_PX * normal) - _sample(image, mid - CONTRAST_PX * normal)
    contrast = (jump ** 2).sum(-1).mean(1)
    cost = mean * length * contrast
    inverse = np.linalg.inv(m)
    out = []
    for i in np.flatnonzero(keep):
        c = c_px[i]
        if straight[i]:
            c = c[[0, 3]]
        c = c @ inverse[i][:2, :2].T + inverse[i][:2, 2]
        s, j, k = rows[i]
        c[0], c[-1] = firsts[i][0], seconds[i][-1]  # the ends exactly as they were
        out.append(_Candidate(s, j, k, c, float(cost[i])))
    out.sort(key=lambda x: x.cost)
    return out


def _disjoint(cands: list[_Candidate]) -> list[_Candidate]:
    """Cheapest first, the candidates that touch no segment an earlier one changes."""
    used, out = set(), []
    for c in cands:
        key = (c.shape, c.subpath)
        mine = {(key, c.node), (key, c.node + 1)}  # its two segments
        if mine & used:
            continue
        used |= mine
        out.append(c)
    return out


def _apply(shapes: dict[int, list], chosen: list[_Candidate]):
    """New per-shape subpath segments with ``chosen`` joins made; and the (shape, subpath)
    -> indices of the joined segments (in the new numbering)."""
    by: dict[tuple[int, int], list[_Candidate]] = {}
    for c in chosen:
        by.setdefault((c.shape, c.subpath), []).append(c)
    new, made = {}, {}
    for (s, j), cs in by.items():
        subs = new.setdefault(s, list(shapes[s]))
        segs, closed = subs[j]
        segs = list(segs)
        idx = []
        for c in sorted(cs, key=lambda c: -c.node):
            segs[c.node:c.node + 2] = [c.ctrl]
            idx = [x - 1 for x in idx] + [c.node]
        subs[j] = (segs, closed)
        made[(s, j)] = set(idx)
    return new, made


def reduce_nodes(scene, measure, image: np.ndarray, size: tuple[int, int], budget_db: float = 0.1,
                 max_error: float = 0.5, lines: float = 0.25, rounds: int = 2, noise: float = 0.0) -> dict:
    """Join segments of ``scene``'s paths (in place) while ``measure(scene)`` (the MSE of
    its render against the target) stays within ``budget_db`` of where it started.
    ``image``: the current render, RGB [H, W, 3] at ``size`` (width, height). ``noise``:
    the part of the MSE that is the renderer's sampling noise, not the picture's error
    (the budget is a share of the rest: at 45 dB, the noise of 16 Monte Carlo samples a
    pixel is a fifth of what they measure, and of 4 two thirds). Returns counts."""
    started = time.perf_counter()
    base = measure(scene)
    limit = base + max(base - noise, 0.0) * (10 ** (budget_db / 10) - 1)
    shapes = {i: _subpath_segments(sh.geometry) for i, sh in enumerate(scene.shapes)
              if isinstance(sh.geometry, Path) and sh.geometry.widths is None}
    before = sum(len(segs) for subs in shapes.values() for segs, _ in subs)
    renders, joined, mse = 1, 0, base
    originals = {i: scene.shapes[i].geometry for i in shapes}
    changed = None
    for _ in range(rounds):
        chosen = _disjoint(candidates(scene, shapes, image, size, max_error, lines, changed))
        if not chosen:
            break

        def trial(k):
            new, made = _apply(shapes, chosen[:k])
            for s, subs in new.items():
                scene.shapes[s].geometry = _with_segments(originals[s], subs)
            value = measure(scene)
            for s in new:  # back as it was
                scene.shapes[s].geometry = originals[s]
            return value, new, made

        lo, hi, best = 0, len(chosen), None
        value, new, made = trial(hi)
        renders += 1
        if value <= limit:
            lo, best = hi, (value, new, made)
        while hi - lo > max(1, len(chosen) // 64):
            mid = (lo + hi + 1) // 2
            value, new, made = trial(mid)
            renders += 1
            if value <= limit:
                lo, best = mid, (value, new, made)
            else:
                hi = mid - 1
        if best is None or lo == 0:
            break
        mse, new, made = best
        shapes.update(new)
        for s in new:
            scene.shapes[s].geometry = _with_segments(originals[s], shapes[s])
            originals[s] = scene.shapes[s].geometry
        joined += lo
        changed = made
    after = sum(len(segs) for subs in shapes.values() for segs, _ in subs)
    return {"segments_before": before, "segments_after": after, "joined": joined, "renders": renders,
            "mse_before": base, "mse_after": mse, "seconds": time.perf_counter() - started}


def simplify_fitted(scene, goal, settings, render_rgb, target_rgb: np.ndarray, budget_db: float = 0.1,
                    iterations: int = 30, hooks=(), keep_alpha=(), max_error: float = 0.5,
                    lines: float = 0.25) -> dict:
    """The pass after a fit: ``reduce_nodes`` against ``target_rgb`` (RGB [H, W, 3], the
    size ``render_rgb(scene, seed=0)`` renders at; seed: added to the renderer's), then ``iterations`` of the loop (``settings``
    but for the count, at a fifth of its rates, the colours kept) on ``goal``; the brief
    run is undone where it measured worse. Returns reduce_nodes' counts with the brief
    run's ("mse_refined", "seconds_refine")."""
    import copy

    from .loop import optimize

    def measure(s):
        return float(((render_rgb(s) - target_rgb) ** 2).mean())

    image = render_rgb(scene)
    h, w = image.shape[:2]
    # the sampling noise's share of the MSE: half the mean squared difference of two renders
    # with different seeds
    noise = 0.5 * float(((render_rgb(scene, 1) - image) ** 2).mean())
    stats = reduce_nodes(scene, measure, image, (w, h), budget_db, max_error, lines, noise=noise)
    stats["noise"] = noise
    stats["mse_refined"] = stats["mse_after"]
    stats["seconds_refine"] = 0.0
    if iterations > 0 and stats["joined"] > 0:
        started = time.perf_counter()
        saved = [copy.deepcopy(sh.geometry) for sh in scene.shapes]
        lr = {k: (0.0 if k in ("colors", "opacities") else float(v) * BRIEF_RATE) for k, v in settings.lr.items()}
        brief = dataclasses.replace(settings, iterations=int(iterations), lr_warmup=0, lr_decay=0.5, coarse=0.0,
                                    lr=lr)
        optimize(scene, goal, brief, hooks=hooks, keep_alpha=keep_alpha)
        refined = measure(scene)
        if refined > stats["mse_after"]:
            for sh, g in zip(scene.shapes, saved):
                sh.geometry = g
        else:
            stats["mse_refined"] = refined
        stats["seconds_refine"] = time.perf_counter() - started
    stats["seconds"] += stats["seconds_refine"]
    return stats
