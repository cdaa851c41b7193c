"""Closed strokes that are polygons.

A small ring of line art (a diamond or a triangle drawn 2 units wide in 24) thins to a
rounded loop: thinning cuts each corner over a few pixels, and where the sides are short
beside the width the cuts meet, so the tracer finds no corner and fits a smooth closed
curve, which the fit then keeps round. Each closed, round-joined stroke is tried as the
polygon its sides make: Douglas-Peucker on its centerline finds the sides, each side's
middle points fix its line (away from the cut corners), and neighbouring lines meet at
the corners (at two tolerances, each judged). A loop takes its polygon where the render's squared error about it (its box
and the stroke's width) falls to CLEARLY_BETTER of what it was, and the polygons taken
are kept where the whole picture's error falls."""
from __future__ import annotations

import numpy as np

from vecfit.scene.arrays import to_numpy
from vecfit.scene.placement import shape_matrices
from vecfit.scene.segments import path_segments, points_at, with_segments

from .fillets import half_width, stroked
from .windows import choose_in_windows

SIDES = (3, 8)          # polygons of this many sides are tried
DP_TOLERANCES = (0.5, 1.0)  # half widths: Douglas-Peucker's tolerances, finding the sides (each tried)
SIDE_MIDDLE = 0.6       # the share of a side's points, about its middle, that fixes its line
CORNER_REACH = 3.0      # half widths: a corner further than this from Douglas-Peucker's is no corner
CLEARLY_BETTER = 0.7    # a loop's error about it, as a share of its error as traced
SAMPLES = 24            # points a segment


def _points(segs: list[np.ndarray]) -> np.ndarray:
    """A closed subpath's points, SAMPLES a segment (each segment's end left to the next)."""
    t = np.linspace(0.0, 1.0, SAMPLES, endpoint=False)
    return np.concatenate([points_at(c, t) for c in segs])


def _line(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The least-squares line through points: (a point on it, its unit direction)."""
    mean = points.mean(0)
    _, _, vt = np.linalg.svd(points - mean)
    return mean, vt[0]


def polygon_of(segs: list[np.ndarray], hw: float, tolerance: float = DP_TOLERANCES[0]) -> list[np.ndarray] | None:
    """The closed subpath's segments as the polygon of its sides (see the module's text;
    Douglas-Peucker within ``tolerance`` half widths), as lines; None where it has not
    SIDES sides or its sides do not meet near its turns."""
    import cv2

    pts = _points(segs)
    if len(pts) < 3 * SIDES[0]:
        return None
    found = cv2.approxPolyDP(pts.astype(np.float32).reshape(-1, 1, 2), tolerance * hw, True).reshape(-1, 2)
    k = len(found)
    if not SIDES[0] <= k <= SIDES[1]:
        return None
    at = sorted(int(np.argmin(np.hypot(*(pts - q).T))) for q in found)
    lines = []
    for i in range(k):
        a, b = at[i], at[(i + 1) % k]
        side = pts[a:b + 1] if b > a else np.concatenate([pts[a:], pts[:b + 1]])
        trim = int(len(side) * (1 - SIDE_MIDDLE) / 2)
        middle = side[trim:len(side) - trim]
        if len(middle) < 3:
            return None
        lines.append(_line(middle))
    corners = []
    for i in range(k):
        (p, u), (q, v) = lines[i - 1], lines[i]
        m = np.array([u, -v]).T
        if abs(np.linalg.det(m)) < 0.2:  # (sides within 12 degrees of each other: no corner)
            return None
        s, _ = np.linalg.solve(m, q - p)
        corner = p + s * u
        if np.hypot(*(corner - pts[at[i]])) > CORNER_REACH * hw:
            return None
        corners.append(corner)
    return [np.stack([corners[i], corners[(i + 1) % k]]) for i in range(k)]


def sharpen_loops(scene, render_rgb, target_rgb: np.ndarray, size: tuple[int, int],
                  image=None) -> tuple[dict, np.ndarray]:
    """Closed, round-joined strokes of ``scene`` made the polygons they are, in place,
    where the render says (see the module's text). ``image``: ``render_rgb(scene)`` where
    the caller has it. Returns counts, and the render of the scene as it is left."""
    shapes = path_segments(scene)
    mats = np.asarray(to_numpy(shape_matrices(scene, size[0], size[1])), np.float64)
    found = {}  # (shape, subpath) -> ({tolerance index: polygon}, the box in pixels of them all)
    for s, subs in shapes.items():
        sh = scene.shapes[s]
        if not stroked(sh) or sh.linejoin != "round":
            continue
        hw = half_width(sh)
        m = mats[s]
        scale = float(np.sqrt(abs(np.linalg.det(m[:2, :2]))))
        for j, (segs, closed) in enumerate(subs):
            if not closed or all(len(c) == 2 for c in segs):
                continue
            tried = {i: polygon_of(segs, hw, t) for i, t in enumerate(DP_TOLERANCES)}
            tried = {i: p for i, p in tried.items() if p is not None}
            if not tried:
                continue
            both = np.concatenate([_points(segs)] + [np.concatenate(p) for p in tried.values()]) @ m[:2, :2].T + m[:2, 2]
            pad = scale * hw + 2
            found[(s, j)] = (tried, (both.min(0) - pad, both.max(0) + pad))
    stats = {"loops": len(found), "sharpened": 0}
    if image is None:
        image = render_rgb(scene)
    if not found:
        return stats, image
    originals = {s: scene.shapes[s].geometry for s, _ in found}
    h, w = image.shape[:2]

    def apply(choice: dict) -> None:
        """choice: (shape, subpath) -> tolerance index."""
        for s in originals:
            subs = [(found[(s, j)][0][choice[(s, j)]] if (s, j) in choice else segs, closed)
                    for j, (segs, closed) in enumerate(shapes[s])]
            scene.shapes[s].geometry = with_segments(originals[s], subs)

    def restore() -> None:
        for s, g in originals.items():
            scene.shapes[s].geometry = g

    def window(box) -> tuple[slice, slice]:
        (x0, y0), (x1, y1) = box
        return (slice(int(max(0, np.floor(y0))), int(min(h, np.ceil(y1)))),
                slice(int(max(0, np.floor(x0))), int(min(w, np.ceil(x1)))))

    choice, image = choose_in_windows(
        scene, render_rgb, target_rgb, image, {key: window(box) for key, (_, box) in found.items()},
        range(len(DP_TOLERANCES)), lambda key, i: i in found[key][0], apply, restore, CLEARLY_BETTER)
    stats["sharpened"] = len(choice)
    return stats, image
