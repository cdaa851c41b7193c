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
from .crossings import crossed_subpaths, subpath_crossings
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
    p = np.asarray(point, np.float64)
    if seg_a == seg_b:
        head, rest = split_at(segs[seg_a], t_a)
        inner, tail = split_at(rest, (t_b - t_a) / (1 - t_a) if t_a < 1 else 0.0)
        loop = [inner]
        other = [tail] + segs[seg_a + 1:] + segs[:seg_a] + [head]
    else:
        a0, a1 = split_at(segs[seg_a], t_a)
        b0, b1 = split_at(segs[seg_b], t_b)
        loop = [a1] + segs[seg_a + 1:seg_b] + [b0]
        other = [b1] + segs[seg_b + 1:] + segs[:seg_a] + [a0]
    return _closed_at(loop, p), _closed_at(other, p)


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
    done, todo, cuts = [], [segs], 0
    while todo:
        loop = todo.pop()
        if decimals is not None:
            loop = [np.round(c, decimals) for c in loop]
            loop = [c for c in loop if _usable(c)]
        judged = loop and not _speck(loop, tolerance, decimals)
        found = subpath_crossings(*layout_of(loop, True), True, tolerance) if judged else []
        if not found or cuts >= MAX_CUTS:
            if loop:
                done.append(loop)
            continue
        # (a crossing reported where the loop closes, its start, cuts off nothing: the next)
        c = next((c for c in found if not _at_start(c, loop)), None)
        pieces = cut_at(loop, c.seg_a, c.t_a, c.seg_b, c.t_b, c.point) if c is not None else [loop]
        if any(_same(piece, loop) for piece in pieces):  # rounding undid the cut: no progress
            done.append(loop)
            continue
        todo.extend(pieces)
        cuts += 1
    return done


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
        by_shape.setdefault(shape_index, set()).add(subpath)
    for shape_index, subpaths in by_shape.items():
        shape = scene.shapes[shape_index]
        if shape.geometry.widths is not None:
            continue  # per-point stroke widths would not survive the cuts
        scale = scales[shape_index] if scales[shape_index] > 0 else 1.0
        places = None if decimals is None else decimals[shape_index]
        shape.geometry = _untangled(judged.shapes[shape_index].geometry, subpaths, tolerance / scale,
                                    min_area / scale ** 2, places, is_tensor(shape.geometry.points))
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


def _untangled(path: Path, cut: set[int], tolerance: float, min_area: float, decimals: int | None,
               tensor: bool) -> Path:
    """The path with the subpaths ``cut`` replaced by their simple loops (its points a
    tensor or, for a Scene of NumPy arrays, an array)."""
    pts = np.asarray(to_numpy(path.points), np.float64)
    points, degrees, subpaths = [], [], []
    for index, ((first, count, closed), (p0, n)) in enumerate(zip(path.subpaths, path.subpath_point_ranges())):
        own = pts[p0:p0 + n]
        degs = [int(d) for d in path.degrees[first:first + count]]
        if index not in cut:
            subpaths.append((len(degrees), count, closed))
            points.append(own)
            degrees += degs
            continue
        for loop in simple_loops(segments_of(own, degs, True), tolerance, decimals):
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

