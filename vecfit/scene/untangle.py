"""Closed outlines that cross themselves, cut into simple loops.

Refinement moves control points freely, and an outline can come out crossing itself: a
cubic thrown into a loop, a corner folded over, a figure-eight. A cutter follows such a
loop and a designer must untangle it by hand. Cutting the outline at each crossing point
into separate closed loops keeps every edge where it was, so the winding number of every
point, and with it the filled area under either fill rule, is the same: the picture does
not change (only where the outline is also stroked does a crossing become a corner). A
loop left smaller than ``min_area`` square pixels (the fold of a corner, a cubic's
little twist) is dropped: it draws next to nothing and is what a designer would delete.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .arrays import floats_torch, is_tensor, to_numpy
from .crossings import Crossing, crossed_subpaths, many_subpath_crossings
from .model import Path, Scene
from .placement import pixel_scales
from .segments import layout_of, segments_of, split_at

MAX_CUTS = 10_000  # per subpath: a pathological outline is left as far as it got
MIN_LENGTH = 1e-9  # a piece of a segment shorter than this (its own units) is dropped


def _usable(ctrl: np.ndarray) -> bool:
    return float(np.abs(ctrl - ctrl[0]).max()) > MIN_LENGTH


def cut_at(segs: list[np.ndarray], seg_a: int, t_a: float, seg_b: int, t_b: float,
           point) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """The closed loop of segments ``segs`` cut where it passes ``point`` twice (segment
    seg_a at t_a, then seg_b at t_b) into two closed loops, each from the point back to it:
    the stretch between the two passes, and the rest."""
    return _closed_both(_laid_out(segs, seg_a, t_a, seg_b, t_b), point)


def _closed_both(laid, point) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """_closed_at of both loops _laid_out makes."""
    p = np.asarray(point, np.float64)
    return _closed_at(laid[0], p), _closed_at(laid[1], p)


def _laid_out(segs: list[np.ndarray], seg_a: int, t_a: float, seg_b: int, t_b: float):
    """cut_at's two loops before _closed_at: the stretch between the passes (from seg_a's
    part after t_a to seg_b's part before t_b), and the rest (from seg_b's part after t_b
    round to seg_a's part before t_a)."""
    if seg_a == seg_b:
        head, rest = split_at(segs[seg_a], t_a)
        inner, tail = split_at(rest, (t_b - t_a) / (1 - t_a) if t_a < 1 else 0.0)
        return [inner], [tail] + segs[seg_a + 1:] + segs[:seg_a] + [head]
    a0, a1 = split_at(segs[seg_a], t_a)
    b0, b1 = split_at(segs[seg_b], t_b)
    return [a1] + segs[seg_a + 1:seg_b] + [b0], [b1] + segs[seg_b + 1:] + segs[:seg_a] + [a0]


def _closed_at(loop: list[np.ndarray], p: np.ndarray) -> list[np.ndarray]:
    """The loop with its degenerate pieces dropped, starting and ending exactly at p."""
    loop = [c.copy() for c in loop if _usable(c)]
    if loop:
        loop[0][0] = p
        loop[-1][-1] = p
    return loop


def loop_area(segs: list[np.ndarray]) -> float:
    """The signed area a closed loop of Bézier segments encloses (Green's theorem on the
    segments flattened finely enough for the purpose: dropping slivers)."""
    u = np.linspace(0.0, 1.0, 17)[:-1]
    pts = []
    for c in segs:
        level = np.broadcast_to(c, (len(u), *c.shape)).copy()
        while level.shape[1] > 1:
            level = (1 - u)[:, None, None] * level[:, :-1] + u[:, None, None] * level[:, 1:]
        pts.append(level[:, 0])
    q = np.concatenate(pts)
    x, y = q[:, 0], q[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _speck(loop: list[np.ndarray], tolerance: float, decimals: int | None) -> bool:
    """Whether a loop fits within ten rounding steps (or tolerances): cut at a crossing,
    such a loop can round to segments that cross again at every cut, for ever; it is left
    whole (its area is a hundred steps squared at most: the callers drop it by its area)."""
    pts = np.concatenate(loop)
    step = max(tolerance, 10.0 ** -decimals if decimals is not None else 0.0)
    return float(np.ptp(pts, axis=0).max()) <= 10 * step


def _same(a: list[np.ndarray], b: list[np.ndarray]) -> bool:
    return len(a) == len(b) and all(x.shape == y.shape and np.array_equal(x, y) for x, y in zip(a, b))


def _at_start(c, loop: list[np.ndarray]) -> bool:
    """Whether a crossing lies at the loop's start, where its first segment begins and a
    segment ends that only segments of no length follow."""
    return (c.seg_a == 0 and c.t_a <= 1e-12 and c.t_b >= 1 - 1e-12
            and float(np.abs(loop[c.seg_b][-1] - loop[0][0]).max()) <= MIN_LENGTH
            and not any(_usable(rest) for rest in loop[c.seg_b + 1:]))


def simple_loops(segs: list[np.ndarray], tolerance: float, decimals: int | None = None) -> list[list[np.ndarray]]:
    """A closed loop cut at its crossings into loops that do not cross themselves; with
    ``decimals``, each loop's control points rounded to them before it is checked (as the
    file will hold them)."""
    return simple_loops_many([(segs, tolerance, decimals)])[0]


def simple_loops_many(jobs) -> list[list[list[np.ndarray]]]:
    """simple_loops of each (segs, tolerance, decimals) in ``jobs``, the crossings found in
    batches: every loop to be checked in one round is checked in one call.

    A loop's crossings are found once and handed on to the two loops each cut makes (those
    with both passes in one loop are its own; a crossing with a pass in each is one loop
    crossing the other, no longer a loop crossing itself); a loop handed none is checked
    again in the next round, so every loop kept has been checked. Checking again after
    every cut, one loop at a time, took 1,300 s on a gradient emoji (noto-emoji-080 at
    normal: 10,000 cuts of one outline, each a new check of what was left of it)."""
    done: list[list] = [[] for _ in jobs]
    cuts = [0] * len(jobs)

    def prepared(k, loop, known):
        """The loop as the file will hold it and its crossings still known, or None where it
        is done with (empty, or a speck: kept whole)."""
        decimals = jobs[k][2]
        if decimals is not None:
            rounded = [np.round(c, decimals) for c in loop]
            loop = [c for c in rounded if _usable(c)]
            if len(loop) != len(rounded):
                known = None  # the pieces moved: the crossings handed on no longer say where
        if loop and _speck(loop, jobs[k][1], decimals):
            done[k].append(loop)
            return None
        return (loop, known) if loop else None

    to_check = [(k, *ready) for k, (segs, _, _) in enumerate(jobs) if (ready := prepared(k, segs, None))]
    while to_check:
        found = many_subpath_crossings([(*layout_of(loop, True), True, jobs[k][1]) for k, loop, _ in to_check])
        work = [(k, loop, crossings) for (k, loop, _), crossings in zip(to_check, found)]
        to_check = []
        while work:
            k, loop, crossings = work.pop()
            if not crossings or cuts[k] >= MAX_CUTS:
                done[k].append(loop)
                continue
            # (a crossing reported where the loop closes, its start, cuts off nothing: the next)
            c = next((c for c in crossings if not _at_start(c, loop)), None)
            laid = _laid_out(loop, c.seg_a, c.t_a, c.seg_b, c.t_b) if c is not None else None
            pieces = _closed_both(laid, c.point) if c is not None else [loop]
            if any(_same(piece, loop) for piece in pieces):  # rounding undid the cut: no progress
                done[k].append(loop)
                continue
            cuts[k] += 1
            handed_on = _handed_on(len(loop), c, laid, [other for other in crossings if other is not c])
            for piece, handed in zip(pieces, handed_on):
                ready = prepared(k, piece, handed)
                if ready is None:
                    continue
                if ready[1]:
                    work.append((k, *ready))
                else:
                    to_check.append((k, ready[0], None))
    return done


def _handed_on(n: int, cut: Crossing, laid, others: list[Crossing]) -> tuple[list, list]:
    """The crossings ``others`` of a loop of ``n`` segments that lie wholly in each of the
    two loops its cut at ``cut`` makes (``laid``: as _laid_out lays them out, the stretch
    between the cut's passes, then the rest), their places rewritten in that loop's
    segments and in order along it. A crossing on a pass at the cut's own parameters, or on
    a piece _closed_at drops, is left out: the loop is then checked again (simple_loops),
    as one handed none is."""
    sa, ta, sb, tb = cut.seg_a, cut.t_a, cut.seg_b, cut.t_b

    def place(seg: int, t: float):
        """(which loop: 0 the stretch, 1 the rest, its segment, parameter) as cut_at lays
        them out; None on the cut itself."""
        if seg == sa == sb:
            if t == ta or t == tb:
                return None
            if ta < t < tb:
                return 0, 0, (t - ta) / (tb - ta)
            return (1, 0, (t - tb) / (1 - tb)) if t > tb else (1, n, t / ta)
        if seg == sa:
            if t == ta:
                return None
            return (0, 0, (t - ta) / (1 - ta)) if t > ta else (1, n - sb + sa, t / ta)
        if seg == sb:
            if t == tb:
                return None
            return (0, sb - sa, t / tb) if t < tb else (1, 0, (t - tb) / (1 - tb))
        if sa < seg < sb:
            return 0, seg - sa, t
        return (1, seg - sb, t) if seg > sb else (1, n - sb + seg, t)

    # each loop's segments renumbered past those _closed_at drops
    usable = [[_usable(c) for c in side] for side in laid]
    renumbered = [np.cumsum(kept) - 1 for kept in usable]
    handed: tuple[list, list] = ([], [])
    for other in others:
        a, b = place(other.seg_a, other.t_a), place(other.seg_b, other.t_b)
        if a is None or b is None or a[0] != b[0]:
            continue  # on the cut, or one loop crossing the other
        if not (usable[a[0]][a[1]] and usable[a[0]][b[1]]):
            continue
        first, second = sorted([(int(renumbered[a[0]][a[1]]), a[2]), (int(renumbered[b[0]][b[1]]), b[2])])
        handed[a[0]].append(Crossing(first[0], first[1], second[0], second[1], other.point))
    for crossings in handed:
        crossings.sort(key=lambda c: (c.seg_a, c.t_a, c.seg_b, c.t_b))
    return handed


def untangle(scene: Scene, keep=frozenset(), tolerance: float = 0.01, min_area: float = 1.0,
             decimals: list[int] | None = None) -> int:
    """Cut every filled closed subpath that crosses itself into simple loops, in place,
    except the subpaths in ``keep`` ((shape index, subpath index): crossings the user drew).
    Loops under ``min_area`` px² are dropped. ``tolerance`` is in canvas pixels. Returns how
    many subpaths were cut.

    ``decimals`` (per shape, in its own units: what the SVG writer will write) has the
    outlines judged and cut as the file will hold them: rounding moves a point by up to
    half a step, enough to make two parts of an outline that meet at a sharp angle (the
    vertex of a loop cut off) cross near that vertex."""
    judged = scene if decimals is None else _rounded(scene, decimals)
    crossed = crossed_subpaths(judged, tolerance) - set(keep)
    if not crossed:
        return 0
    scales = pixel_scales(scene)
    by_shape: dict[int, set[int]] = {}
    for shape_index, subpath in crossed:
        if scene.shapes[shape_index].geometry.widths is None:  # per-point stroke widths would not survive the cuts
            by_shape.setdefault(shape_index, set()).add(subpath)
    # every cut subpath's loops found in one batch, then each shape's path rebuilt
    jobs, owners = [], []
    for shape_index, subpaths in sorted(by_shape.items()):
        path = judged.shapes[shape_index].geometry
        scale = scales[shape_index] if scales[shape_index] > 0 else 1.0
        places = None if decimals is None else decimals[shape_index]
        pts = np.asarray(to_numpy(path.points), np.float64)
        for index, ((first, count, _), (p0, n)) in enumerate(zip(path.subpaths, path.subpath_point_ranges())):
            if index in subpaths:
                degs = [int(d) for d in path.degrees[first:first + count]]
                jobs.append((segments_of(pts[p0:p0 + n], degs, True), tolerance / scale, places))
                owners.append((shape_index, index))
    loops_of = dict(zip(owners, simple_loops_many(jobs)))
    for shape_index in by_shape:
        shape = scene.shapes[shape_index]
        scale = scales[shape_index] if scales[shape_index] > 0 else 1.0
        shape.geometry = _untangled(judged.shapes[shape_index].geometry, shape_index, loops_of,
                                    min_area / scale ** 2, is_tensor(shape.geometry.points))
    return len(crossed)


def _rounded(scene: Scene, decimals: list[int]) -> Scene:
    """A copy of the Scene for judging crossings: every path's points rounded (NumPy)."""
    shapes = []
    for shape, places in zip(scene.shapes, decimals):
        g = shape.geometry
        if isinstance(g, Path):
            points = np.round(np.asarray(to_numpy(g.points), np.float64), places)
            shape = dataclasses.replace(shape, geometry=dataclasses.replace(g, points=points))
        shapes.append(shape)
    return dataclasses.replace(scene, shapes=shapes)


def _untangled(path: Path, shape_index: int, loops_of: dict, min_area: float, tensor: bool) -> Path:
    """The path with each subpath in ``loops_of`` ((shape index, subpath index) -> its
    simple loops) replaced by its loops of ``min_area`` or more (its points a tensor or,
    for a Scene of NumPy arrays, an array)."""
    pts = np.asarray(to_numpy(path.points), np.float64)
    points, degrees, subpaths = [], [], []
    for index, ((first, count, closed), (p0, n)) in enumerate(zip(path.subpaths, path.subpath_point_ranges())):
        loops = loops_of.get((shape_index, index))
        if loops is None:
            subpaths.append((len(degrees), count, closed))
            points.append(pts[p0:p0 + n])
            degrees += [int(d) for d in path.degrees[first:first + count]]
            continue
        for loop in loops:
            if abs(loop_area(loop)) < min_area:
                continue
            loop_points, loop_degrees = layout_of(loop, True)
            subpaths.append((len(degrees), len(loop_degrees), True))
            points.append(loop_points)
            degrees += loop_degrees
    if not points:  # every loop was a sliver: keep a point, so the path stays a path
        points, degrees, subpaths = [pts[:1], pts[:1]], [1], [(0, 1, False)]
    flat = np.concatenate(points).astype(np.float32)
    return Path(points=floats_torch(flat) if tensor else flat, degrees=np.array(degrees, np.int64),
                subpaths=subpaths)
