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

Strokes (line art's centerlines) are tried bolder first: each run of segments that lies
within STRAIGHT_RUN of one line joined into that line, and the joins within
STROKE_JOINS_DB, then the brief refinement, which must bring the picture back within
``budget_db``; else the pass is done again as above.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from vecfit.fitting.fillets import half_width, round_corners, stroked
from vecfit.scene.arrays import is_tensor, to_numpy
from vecfit.scene.model import Path
from vecfit.scene.placement import shape_matrices
from vecfit.scene.segments import path_segments, subpath_segments, with_segments

SAMPLES = 12      # per segment of a pair
REPARAM = 2       # Newton reparameterisations after the split's search
CONTRAST_PX = 1.5  # where the edge's two sides are read, pixels from it
BRIEF_RATE = 0.05  # the brief refinement's rates: this share of the fit's (half where the fit ended)
CORNER = 90.0     # degrees: a node turning more than this is a corner (kept unless its segments are short)
HIDDEN_JUMP = 1e-4  # squared colour difference across an edge below which it does not show
TIDY_DB = 0.02     # dB: what tidy (after the brief refinement) may cost
HIDDEN_ERROR = 3.0  # px: how far a join may stray from a pair that shows nowhere, itself showing nowhere
# dB: what a scene with strokes may lose to its joins before the brief refinement, which
# must bring it back within the pass's budget (on 30 Tabler icons 3 dB joined 1% more
# segments, for no more PSNR; see simplify_fitted)
STROKE_JOINS_DB = 1.0


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


def _limit(base: float, noise: float, budget_db: float) -> float:
    """The MSE a pass may reach from ``base``: ``budget_db`` of the part that is not the
    renderer's sampling noise."""
    return base + max(base - noise, 0.0) * (10 ** (budget_db / 10) - 1)


def _sample(image: np.ndarray, xy: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    x = np.clip(np.rint(xy[..., 0] - 0.5).astype(np.int64), 0, w - 1)
    y = np.clip(np.rint(xy[..., 1] - 0.5).astype(np.int64), 0, h - 1)
    return image[y, x]


def _jumps(image: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """[N, M-1] the squared colour difference of the render ``image`` CONTRAST_PX either
    side of each piece of the polylines ``pts`` [N, M, 2] (pixels)."""
    normal = np.diff(pts, axis=1)
    normal = _unit(np.stack([-normal[..., 1], normal[..., 0]], -1))
    mid = 0.5 * (pts[:, 1:] + pts[:, :-1])
    jump = _sample(image, mid + CONTRAST_PX * normal) - _sample(image, mid - CONTRAST_PX * normal)
    return (jump ** 2).sum(-1)


def candidates(scene, shapes: dict[int, list], image: np.ndarray, size: tuple[int, int], max_error: float,
               lines: float, changed: dict[int, set] | None = None, hidden_error: float = 0.0) -> list[_Candidate]:
    """Every node of the paths ``shapes`` (shape index -> scene.segments.subpath_segments) that can go,
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
    # contrast across the pair: the render 1.5 px either side of its samples
    jumps = _jumps(image, pts)
    contrast = jumps.mean(1)
    # an edge that shows nowhere (under a later shape) may be replaced by one up to
    # ``hidden_error`` from it, where that one shows nowhere either
    new_pts = _eval(c_px, np.broadcast_to(np.linspace(0.0, 1.0, 2 * SAMPLES + 1), (len(c_px), 2 * SAMPLES + 1)))
    hidden = (jumps.max(1) <= HIDDEN_JUMP) & (_jumps(image, new_pts).max(1) <= HIDDEN_JUMP)
    # two lines join only into a line; a join close to its chord is written as one
    keep = ((err <= max_error) | (hidden & (err <= hidden_error))) & (~lines_both | straight)
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
                 max_error: float = 0.5, lines: float = 0.25, rounds: int = 2, noise: float = 0.0,
                 base: float | None = None, hidden_error: float = 0.0, current: float | None = None) -> dict:
    """Join segments of ``scene``'s paths (in place) while ``measure(scene)`` (the MSE of
    its render against the target) stays within ``budget_db`` of where it started.
    ``image``: the current render, RGB [H, W, 3] at ``size`` (width, height). ``noise``:
    the part of the MSE that is the renderer's sampling noise, not the picture's error
    (the budget is a share of the rest: at 45 dB, the noise of 16 Monte Carlo samples a
    pixel is a fifth of what they measure, and of 4 two thirds). ``base``: the MSE the
    budget is counted from, where it is not the scene's now (a pass before this one spent
    some of it). ``hidden_error``: how far (px) a join may stray from a pair that shows
    nowhere in ``image`` (nor does the join): under a later shape. ``current``: the
    scene's MSE now where the caller has it (``image``'s: no render to measure it again).
    Returns counts."""
    started = time.perf_counter()
    now = measure(scene) if current is None else current
    base = now if base is None else base
    limit = _limit(base, noise, budget_db)
    shapes = path_segments(scene)
    before = sum(len(segs) for subs in shapes.values() for segs, _ in subs)
    renders, joined, mse = int(current is None), 0, now
    originals = {i: scene.shapes[i].geometry for i in shapes}
    changed = None
    for _ in range(rounds):
        chosen = _disjoint(candidates(scene, shapes, image, size, max_error, lines, changed, hidden_error))
        if not chosen:
            break

        def trial(k):
            new, made = _apply(shapes, chosen[:k])
            for s, subs in new.items():
                scene.shapes[s].geometry = with_segments(originals[s], subs)
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
            scene.shapes[s].geometry = with_segments(originals[s], shapes[s])
            originals[s] = scene.shapes[s].geometry
        joined += lo
        changed = made
    after = sum(len(segs) for subs in shapes.values() for segs, _ in subs)
    return {"segments_before": before, "segments_after": after, "joined": joined, "renders": renders,
            "mse_before": base, "mse_after": mse, "seconds": time.perf_counter() - started}


def simplify_fitted(scene, goal, settings, render_rgb, target_rgb: np.ndarray, budget_db: float = 0.1,
                    iterations: int = 30, hooks=(), keep_alpha=(), max_error: float = 0.5,
                    lines: float = 0.25, rendered: tuple | None = None) -> dict:
    """The pass after a fit: ``reduce_nodes`` against ``target_rgb`` (RGB [H, W, 3], the
    size ``render_rgb(scene, seed=0)`` renders at; seed: added to the renderer's), then
    ``iterations`` of the loop (``settings`` but for the count, at a fifth of its rates, the
    colours kept) on ``goal``; the brief run is undone where it measured worse.

    A scene with strokes is first tried bolder: its strokes' straight runs as one line each
    (join_straight_runs) and the joins within STROKE_JOINS_DB, then the brief run; where
    that ends more than ``budget_db`` below where the pass started, the scene goes back as
    it was and the pass is done as above. (Each join moves a refined stroke by a hair, which
    its render tells at once, and the joins' budget of 0.1 dB was gone after a join or two:
    the brief run puts the strokes back.)

    ``rendered``: (``render_rgb(scene)``, the sampling noise) where the caller has them
    (jobs/scoring.judging_samples measured both), else rendered here.

    Returns reduce_nodes' counts with the runs' ("straight_runs"; "undone" where the bolder
    try was) and the brief run's ("mse_refined", "seconds_refine")."""
    import copy

    from .loop import optimize

    def measure(s):
        return float(((render_rgb(s) - target_rgb) ** 2).mean())

    if rendered is None:
        image = render_rgb(scene)
        # the sampling noise's share of the MSE: half the mean squared difference of two
        # renders with different seeds
        rendered = image, 0.5 * float(((render_rgb(scene, 1) - image) ** 2).mean())
    image, noise = rendered
    h, w = image.shape[:2]
    base = float(((image - target_rgb) ** 2).mean())

    def joined_and_refined(bolder: bool) -> dict:
        runs, now = {"candidates": 0, "joined": 0, "segments_removed": 0}, image
        if bolder:
            runs = join_straight_runs(scene, (w, h))
            if runs["joined"]:
                now = render_rgb(scene)
        stats = reduce_nodes(scene, measure, now, (w, h), STROKE_JOINS_DB if bolder else budget_db, max_error,
                             lines, noise=noise, base=base, current=float(((now - target_rgb) ** 2).mean()))
        stats["straight_runs"] = runs
        stats["mse_refined"] = stats["mse_after"]
        stats["seconds_refine"] = 0.0
        if iterations > 0 and stats["joined"] + runs["joined"] > 0:
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

    rounded = None
    if any(stroked(sh) for sh in scene.shapes):
        rounded, image = round_corners(scene, render_rgb, target_rgb, (w, h), image)
        if rounded["rounded"]:
            base = float(((image - target_rgb) ** 2).mean())
        fitted = [(copy.deepcopy(sh.geometry), copy.deepcopy(sh.stroke_width)) for sh in scene.shapes]
        stats = joined_and_refined(bolder=True)
        if stats["mse_refined"] > _limit(base, noise, budget_db):
            for sh, (g, width) in zip(scene.shapes, fitted):  # (the brief run moved the widths too)
                sh.geometry, sh.stroke_width = g, width
            tried = stats["straight_runs"]
            stats = joined_and_refined(bolder=False)
            stats["straight_runs"] = {**tried, "undone": True}
    else:
        stats = joined_and_refined(bolder=False)
    stats["noise"] = noise
    if rounded is not None:
        stats["rounded_corners"] = rounded
    stats["tidied"] = tidy(scene, measure, render_rgb, (w, h), noise, max_error, lines)
    return stats


def tidy(scene, measure, render_rgb, size: tuple[int, int], noise: float, max_error: float = 0.5,
         lines: float = 0.25, budget_db: float = TIDY_DB) -> dict:
    """After the brief refinement (which it leaves as it went): all but straight cubics
    written as lines (straighten), then one round of joins (reduce_nodes) that also joins
    lines going on in one direction and pairs under a later shape (up to HIDDEN_ERROR px
    from where they were); ``budget_db`` for both, measured as reduce_nodes measures."""
    base = measure(scene)
    limit = _limit(base, noise, budget_db)
    ends = tidy_stroke_ends(scene, measure, limit)
    straight = straighten(scene, measure, size, limit, lines)
    joins = reduce_nodes(scene, measure, render_rgb(scene), size, budget_db, max_error, lines, rounds=1,
                         noise=noise, base=base, hidden_error=HIDDEN_ERROR)
    return {"hooks": ends["hooks"], "dots": ends["dots"], "straightened": straight["straightened"],
            "joined": joins["joined"], "mse_before": base, "mse_after": joins["mse_after"]}


HOOK_TURN = 120.0  # degrees: a stroke's end segment turning back more than this ...
HOOK_LENGTH = 1.0  # ... and no longer than this many half widths lies under its cap: a hook
DOT_LENGTH = 0.25  # px: a stroke that is one line shorter than this is a dot (zero length)


def _end_hooks(segs: list[np.ndarray], hw: float) -> list[int]:
    """Indices of an open subpath's end segments that are hooks (HOOK_TURN, HOOK_LENGTH):
    the fit folds a line's last few pixels back under its round cap, where nothing shows
    them but the file."""
    found = []
    if len(segs) < 2:
        return found
    for k, nb, at_end in ((0, 1, False), (len(segs) - 1, len(segs) - 2, True)):
        c, n = segs[k], segs[nb]
        chord = (c[-1] - c[0]) if at_end else (c[0] - c[-1])  # away from the rest of the line
        length = float(np.hypot(*chord))
        if length > HOOK_LENGTH * hw:
            continue
        onward = (n[-1] - n[-2]) if at_end else (n[0] - n[1])  # the line's direction into the end
        norm = float(np.hypot(*onward))
        if norm <= 0:
            continue
        # the hook's whole course: its control polygon's steps against the line's direction
        steps = np.diff(c if at_end else c[::-1], axis=0)
        steps = steps[np.hypot(*steps.T) > 1e-9]
        if len(steps) == 0:
            continue
        cos = (steps @ onward) / (np.hypot(*steps.T) * norm)
        if cos.min() <= np.cos(np.radians(HOOK_TURN)):
            found.append(k)
    return sorted(set(found), reverse=True)


def tidy_stroke_ends(scene, measure, limit: float) -> dict:
    """Strokes' ends cleaned, in place, where ``measure(scene)`` stays within ``limit``:
    end segments that are hooks (_end_hooks) dropped, and a stroke that is one line
    shorter than DOT_LENGTH made a dot of no length at its middle (written `h0`, as the
    trace writes dots, not `l.01-.11`). All at once, else none. Returns counts."""
    shapes = path_segments(scene)
    stats = {"hooks": 0, "dots": 0}
    new: dict[int, list] = {}
    for s, subs in shapes.items():
        sh = scene.shapes[s]
        if not stroked(sh) or sh.linecap != "round":
            continue
        hw = half_width(sh)
        changed = False
        out = []
        for segs, closed in subs:
            segs = list(segs)
            if not closed:
                for k in _end_hooks(segs, hw):
                    del segs[k]
                    stats["hooks"] += 1
                    changed = True
                if len(segs) == 1 and len(segs[0]) == 2 and 0 < np.hypot(*(segs[0][1] - segs[0][0])) < DOT_LENGTH:
                    middle = segs[0].mean(0)
                    segs = [np.stack([middle, middle])]
                    stats["dots"] += 1
                    changed = True
            out.append((segs, closed))
        if changed:
            new[s] = out
    if not new:
        return stats
    originals = {s: scene.shapes[s].geometry for s in new}
    for s, subs in new.items():
        scene.shapes[s].geometry = with_segments(originals[s], subs)
    if measure(scene) > limit:
        for s, g in originals.items():
            scene.shapes[s].geometry = g
        return {"hooks": 0, "dots": 0}
    return stats


def _largest_within(count: int, within, coarse: int = 0) -> int:
    """The largest k of 0..count for which ``within(k)`` holds (k = 0 is taken to, and not
    asked): ``count`` first, then by bisection, which stops once its bounds are ``coarse``
    apart or less and takes the lower (each ask is a render)."""
    if count == 0 or within(count):
        return count
    lo, hi = 0, count - 1
    while hi - lo > coarse:
        mid = (lo + hi + 1) // 2
        if within(mid):
            lo = mid
        else:
            hi = mid - 1
    return lo


STRAIGHT = 0.25  # px: a cubic that strays no further than this from its chord is tried as a line


def straight_candidates(scene, shapes: dict[int, list], size: tuple[int, int],
                        tolerance: float = STRAIGHT) -> list[tuple[float, int, int, int]]:
    """(area between the curve and its chord in px², shape, subpath, segment) of every cubic
    of ``shapes`` (shape index -> scene.segments.subpath_segments) whose points all lie within ``tolerance``
    pixels of its chord (the segment between its ends: a flat cubic whose control points run
    past an end, drawing a hair's overshoot, counts by how far it goes), cheapest first."""
    mats = np.asarray(to_numpy(shape_matrices(scene, size[0], size[1])), np.float64)
    rows, ctrls = [], []
    for s, subs in shapes.items():
        for j, (segs, _) in enumerate(subs):
            for k, c in enumerate(segs):
                if len(c) == 4:
                    rows.append((s, j, k))
                    ctrls.append(c)
    if not rows:
        return []
    m = mats[np.array([r[0] for r in rows])]
    c = np.einsum("nij,nkj->nki", m[:, :2, :2], np.stack(ctrls)) + m[:, None, :2, 2]
    u = np.broadcast_to(np.linspace(0.0, 1.0, 17), (len(c), 17))
    pts = _eval(c, u)
    a, d = c[:, None, 0], (c[:, 3] - c[:, 0])[:, None]
    ll = (d * d).sum(-1)
    along = np.clip(((pts - a) * d).sum(-1) / np.maximum(ll, 1e-18), 0.0, 1.0)
    dist = np.linalg.norm(pts - a - along[..., None] * d, axis=-1)
    length = np.sqrt(ll[:, 0])
    ok = (dist.max(1) <= tolerance) & (length > 1e-6)
    out = [(float(dist[i].mean() * length[i]), *rows[i]) for i in np.flatnonzero(ok)]
    out.sort()
    return out


def straighten(scene, measure, size: tuple[int, int], limit: float, tolerance: float = STRAIGHT) -> dict:
    """The cubics of ``scene``'s paths that are all but straight (straight_candidates)
    written as lines (their ends kept), in place, as many as keep ``measure(scene)`` (the
    MSE of a render, the same samples every call) within ``limit``, cheapest first (by
    bisection). A line is four numbers fewer in the file, and lines that go on in one
    direction join into one (reduce_nodes). Returns counts."""
    shapes = path_segments(scene)
    found = straight_candidates(scene, shapes, size, tolerance)
    stats = {"candidates": len(found), "straightened": 0, "renders": 0}
    if not found:
        return stats
    originals = {s: scene.shapes[s].geometry for _, s, _, _ in found}

    def made(k):
        new: dict[int, list] = {}
        for _, s, j, i in found[:k]:
            subs = new.setdefault(s, [(list(segs), closed) for segs, closed in shapes[s]])
            c = subs[j][0][i]
            subs[j][0][i] = c[[0, 3]]
        for s, subs in new.items():
            scene.shapes[s].geometry = with_segments(originals[s], subs)

    def within(k):
        made(k)
        value = measure(scene)
        for s, g in originals.items():
            scene.shapes[s].geometry = g
        stats["renders"] += 1
        return value <= limit

    lo = _largest_within(len(found), within, coarse=max(1, len(found) // 64))
    made(lo)
    stats["straightened"] = lo
    return stats


STRAIGHT_RUN = 0.5  # px: a stroke's run of segments within this of its chord is tried as one line


def straight_run_candidates(scene, shapes: dict[int, list], size: tuple[int, int],
                            tolerance: float = STRAIGHT_RUN) -> list[tuple[float, int, int, int, int]]:
    """(area between the run and its chord in px², shape, subpath, first segment, last
    segment) of the longest runs of two or more consecutive segments (or a cubic alone,
    within STRAIGHT of its chord) of stroked, unfilled paths (``shapes``: shape index ->
    scene.segments.subpath_segments) whose points all lie within ``tolerance`` pixels of
    the chord from the run's start to its end, and go along it
    (each point's place on the chord no further back than the last's, less the tolerance:
    no spike doubling back); cheapest first. Runs do not overlap (each the longest from
    where the last ended)."""
    mats = np.asarray(to_numpy(shape_matrices(scene, size[0], size[1])), np.float64)
    u = np.linspace(0.0, 1.0, 17)
    out = []
    for s, subs in shapes.items():
        if not stroked(scene.shapes[s]):
            continue
        m = mats[s]
        for j, (segs, _) in enumerate(subs):
            if not segs:
                continue
            px = np.stack([_cubic(c) for c in segs]) @ m[:2, :2].T + m[:2, 2]
            pts = _eval(px, np.broadcast_to(u, (len(px), len(u))))  # [S, 17, 2]

            def off_chord(a: int, b: int):
                """(The largest distance of segments a..b from their chord, the mean), or None
                where the run doubles back or has no length."""
                q = pts[a:b + 1].reshape(-1, 2)
                start, d = q[0], q[-1] - q[0]
                length = float(np.hypot(*d))
                if length < 1e-6:
                    return None
                along = (q - start) @ d / length
                if (np.diff(along) < -tolerance).any() or along.min() < -tolerance or along.max() > length + tolerance:
                    return None
                across = np.abs((q - start) @ np.array([-d[1], d[0]])) / length
                return float(across.max()), float(across.mean()) * length
            a = 0
            while a < len(segs):
                best = None
                for b in range(a + 1, len(segs)):
                    found = off_chord(a, b)
                    if found is None or found[0] > tolerance:
                        break
                    best = (b, found[1])
                if best is None:
                    # one cubic alone, within STRAIGHT: a line (a curve at 0.5 px could be a
                    # tight round corner, which a line makes sharp)
                    found = off_chord(a, a) if len(segs[a]) == 4 else None
                    if found is not None and found[0] <= min(tolerance, STRAIGHT):
                        out.append((found[1], s, j, a, a))
                    a += 1
                    continue
                out.append((best[1], s, j, a, best[0]))
                a = best[0] + 1
    out.sort()
    return out


def join_straight_runs(scene, size: tuple[int, int], tolerance: float = STRAIGHT_RUN) -> dict:
    """The straight runs of ``scene``'s strokes (straight_run_candidates) written as one
    line each (the run's ends kept), in place. Where lines cross or meet, a traced
    centerline comes back from the fit as several segments along one line (the slash of an
    "-off" icon), which pairwise joins leave: each moves the line by a hair, which its
    render tells. Returns counts."""
    shapes = path_segments(scene)
    found = straight_run_candidates(scene, shapes, size, tolerance)
    new: dict[int, list] = {}
    for _, s, j, a, b in sorted(found, key=lambda r: -r[3]):  # later runs first: the indices hold
        subs = new.setdefault(s, [(list(segs), closed) for segs, closed in shapes[s]])
        segs = subs[j][0]
        segs[a:b + 1] = [np.stack([segs[a][0], segs[b][-1]])]
    for s, subs in new.items():
        scene.shapes[s].geometry = with_segments(scene.shapes[s].geometry, subs)
    return {"candidates": len(found), "joined": len(found), "segments_removed": sum(b - a for _, _, _, a, b in found)}


MAX_UNSEEN_CHECKS = 200  # subpaths checked by drop_unseen, the smallest first
UNSEEN_MARGIN = 2        # px around a subpath's box that its check renders


def _unseen_candidates(scene, size: tuple[int, int]) -> list[tuple[float, int, int, tuple]]:
    """(area in px², shape, subpath, its box in pixels grown by UNSEEN_MARGIN) of every
    closed subpath of an opaque, filled, unstroked path but its largest (the path stays a
    path), smallest first, at most MAX_UNSEEN_CHECKS."""
    from vecfit.scene.untangle import loop_area

    w, h = size
    mats = np.asarray(to_numpy(shape_matrices(scene, w, h)), np.float64)
    out = []
    for s, shape in enumerate(scene.shapes):
        g = shape.geometry
        if (not isinstance(g, Path) or g.widths is not None or shape.fill is None or shape.stroke is not None
                or len(g.subpaths) < 2 or float(to_numpy(shape.opacity)) < 1 or float(to_numpy(shape.fill_opacity)) < 1):
            continue
        m = mats[s]
        subs = subpath_segments(g)
        areas = []
        for segs, closed in subs:
            if not (closed and segs):
                areas.append(np.inf)
                continue
            px = [c @ m[:2, :2].T + m[:2, 2] for c in segs]
            areas.append(abs(loop_area(px)))
        largest = int(np.argmax(areas))
        for j, ((segs, _), area) in enumerate(zip(subs, areas)):
            if j == largest or not np.isfinite(area):
                continue
            pts = np.concatenate(segs) @ m[:2, :2].T + m[:2, 2]
            x0, y0 = np.floor(pts.min(0)).astype(int) - UNSEEN_MARGIN
            x1, y1 = np.ceil(pts.max(0)).astype(int) + UNSEEN_MARGIN
            box = (max(x0, 0), max(y0, 0), min(x1, w), min(y1, h))
            if box[2] > box[0] and box[3] > box[1]:
                out.append((area, s, j, box))
    out.sort(key=lambda r: r[:3])
    return out[:MAX_UNSEEN_CHECKS]


def _apart(found: list) -> list[list]:
    """The candidates in groups whose boxes (x0, y0, x1, y1) do not meet, first fit in the
    candidates' order."""
    groups: list[list] = []
    for cand in found:
        x0, y0, x1, y1 = cand[3]
        for g in groups:
            if all(x1 <= b[0] or b[2] <= x0 or y1 <= b[1] or b[3] <= y0 for b in (c[3] for c in g)):
                g.append(cand)
                break
        else:
            groups.append([cand])
    return groups


def drop_unseen(scene, render, target_rgb: np.ndarray, budget_db: float = 0.01) -> dict:
    """Closed subpaths of filled paths that the picture does not need, removed from
    ``scene`` (in place): the slivers an outline the refinement crossed leaves when it is
    cut into simple loops (a designer deletes them), and pieces wholly under the shapes
    drawn over them (a trace's piece grown under a later one). Each subpath (the smallest
    first, _unseen_candidates) is judged in its box, rendered with and without it
    (``render(scene, width, height)``: RGB, the same samples every call), against the
    target there (``target_rgb``, RGB [H, W, 3]); those that cost least go while the
    squared error they add stays within ``budget_db``, and a render of the whole picture
    confirms it (else fewer go, by bisection). Returns counts."""
    if scene.groups or scene.has_effects() or not is_tensor(scene.view):
        return {"candidates": 0, "dropped": 0, "renders": 0}
    h, w = target_rgb.shape[:2]
    found = _unseen_candidates(scene, (w, h))
    stats = {"candidates": len(found), "dropped": 0, "renders": 0}
    if not found:
        return stats
    originals = {s: scene.shapes[s].geometry for _, s, _, _ in found}
    subs_of = {s: subpath_segments(g) for s, g in originals.items()}

    def without(pairs):
        gone: dict[int, set] = {}
        for s, j in pairs:
            gone.setdefault(s, set()).add(j)
        for s, js in gone.items():
            scene.shapes[s].geometry = with_segments(originals[s], [x for j, x in enumerate(subs_of[s]) if j not in js])

    def restore():
        for s, g in originals.items():
            scene.shapes[s].geometry = g

    # Each subpath's cost is the change of the squared error in its box when it goes. A
    # subpath draws only within its box, so subpaths whose boxes do not meet are judged
    # together: one render of the whole picture without all of them, against one with
    # everything (a render packs the whole scene, however small its window).
    costs = []
    before = (render(scene, w, h) - target_rgb) ** 2
    stats["renders"] += 1
    for group in _apart(found):
        without([(s, j) for _, s, j, _ in group])
        after = (render(scene, w, h) - target_rgb) ** 2
        restore()
        stats["renders"] += 1
        for _, s, j, (x0, y0, x1, y1) in group:
            costs.append((float(after[y0:y1, x0:x1].sum() - before[y0:y1, x0:x1].sum()), s, j))
    costs.sort()

    def measure():
        stats["renders"] += 1
        return float(((render(scene, w, h) - target_rgb) ** 2).mean())

    base = float(before.mean())
    limit = base * 10 ** (budget_db / 10)
    allowed = (limit - base) * target_rgb.size
    chosen, spent = [], 0.0
    for cost, s, j in costs:
        if spent + max(cost, 0.0) > allowed:
            break
        chosen.append((s, j))
        spent += max(cost, 0.0)
    def within(k):
        restore()
        without(chosen[:k])
        return measure() <= limit

    lo = _largest_within(len(chosen), within)
    restore()
    without(chosen[:lo])
    stats["dropped"] = lo
    return stats

