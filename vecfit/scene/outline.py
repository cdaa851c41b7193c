"""A Scene's shapes as plain outlines, for the passes that read geometry rather than draw
it (the PDF and DXF exporters, cut-outs): its floats as float64 NumPy, each shape's
geometry as subpaths of lines and cubics (quadratics raised to cubics, which is exact),
polylines within a tolerance, the matrices from a shape's or a group's own space to
another, and bounding boxes."""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from vecfit.scene import arrays
from vecfit.scene.geometry import KAPPA, rect_path
from vecfit.scene.model import Circle, Ellipse, Path, Rect, Scene


def f64(value) -> np.ndarray:
    """A tensor's or array's values as float64 NumPy (detached)."""
    return np.asarray(arrays.to_numpy(value), dtype=np.float64)


def num(value) -> float:
    return float(f64(value).reshape(-1)[0])


@dataclass
class Subpath:
    """One subpath: its start point and its segments, each (degree, points after the
    start: 1 for a line, 3 for a cubic), in the shape's own space."""
    start: np.ndarray
    segments: list
    closed: bool


def subpaths(geometry) -> list[Subpath]:
    """The geometry as subpaths of lines and cubics (a circle or an ellipse as four
    quarter-ellipse cubics from (cx + rx, cy), as the SVG writer and resvg start it); empty
    for a rect or ellipse that SVG does not draw (a side or radius not positive)."""
    if isinstance(geometry, Rect):
        size = f64(geometry.p_max) - f64(geometry.p_min)
        if size[0] <= 0 or size[1] <= 0:
            return []
        pts, degrees = rect_path(Rect(f64(geometry.p_min), f64(geometry.p_max), f64(geometry.corner_radii)))
        return _from_points(np.asarray(pts, np.float64).reshape(-1, 2), list(degrees), [(0, len(degrees), True)])
    if isinstance(geometry, (Circle, Ellipse)):
        c = f64(geometry.center).reshape(2)
        r = np.repeat(f64(geometry.radius).reshape(1), 2) if isinstance(geometry, Circle) else f64(geometry.radii)
        if r.min() <= 0:
            return []
        k = KAPPA
        unit = np.array([[1, 0], [1, k], [k, 1], [0, 1], [-k, 1], [-1, k], [-1, 0],
                         [-1, -k], [-k, -1], [0, -1], [k, -1], [1, -k]], np.float64)
        return _from_points(c + unit * r, [3, 3, 3, 3], [(0, 4, True)])
    if isinstance(geometry, Path):
        return _from_points(f64(geometry.points).reshape(-1, 2), [int(d) for d in geometry.degrees],
                            geometry.subpaths)
    return []


def _from_points(points: np.ndarray, degrees: list, spans) -> list[Subpath]:
    out, p = [], 0
    for first, count, closed in spans:
        ds = degrees[first:first + count]
        n = sum(ds) + (0 if closed else 1)
        pts = points[p:p + n]
        p += n
        if n == 0:
            continue
        segments, k = [], 0
        for d in ds:
            idx = [(k + i) % n if closed else k + i for i in range(1, d + 1)]
            ctrl = pts[idx]
            if d == 2:  # degree elevation: the same curve as a cubic
                a = pts[k]
                ctrl = np.array([a + 2 / 3 * (ctrl[0] - a), ctrl[1] + 2 / 3 * (ctrl[0] - ctrl[1]), ctrl[1]])
                d = 3
            segments.append((d, ctrl))
            k += ds[len(segments) - 1]
        out.append(Subpath(pts[0].copy(), segments, bool(closed)))
    return out


def transformed(paths: list[Subpath], m: np.ndarray) -> list[Subpath]:
    """The subpaths mapped by the 3x3 affine ``m`` (exact for Béziers)."""
    def f(p):
        return p @ m[:2, :2].T + m[:2, 2]
    return [Subpath(f(s.start[None])[0], [(d, f(c)) for d, c in s.segments], s.closed) for s in paths]


def flattened(path: Subpath, tolerance: float) -> np.ndarray:
    """[n, 2] points along the subpath (closed ones end at their start), each cubic cut
    into enough chords that none strays more than ``tolerance`` from the curve (a cubic's
    chords at n even steps stray at most 3/4 max|second difference| / n^2)."""
    out = [path.start[None]]
    a = path.start
    for d, c in path.segments:
        if d == 1:
            out.append(c[-1:])
        else:
            p = np.vstack([a[None], c])
            dd = max(np.hypot(*(p[2] - 2 * p[1] + p[0])), np.hypot(*(p[3] - 2 * p[2] + p[1])))
            n = int(min(4096, max(1, math.ceil(math.sqrt(0.75 * dd / max(tolerance, 1e-12))))))
            out.append(_bernstein(n) @ p)
        a = c[-1]
    if path.closed and not np.array_equal(a, path.start):
        out.append(path.start[None])
    return np.vstack(out)


@functools.lru_cache(maxsize=256)
def _bernstein(n: int) -> np.ndarray:
    """[n, 4]: the cubic Bernstein weights at t = 1/n, 2/n, ..., 1."""
    t = np.arange(1, n + 1, dtype=np.float64)[:, None] / n
    u = 1 - t
    return np.hstack([u ** 3, 3 * u * u * t, 3 * u * t * t, t ** 3])


def encloses(path: Subpath) -> bool:
    """Whether the subpath, closed, encloses anything: SVG fills nothing for a line (an
    open line's fill, a path that goes there and back), and PDF viewers draw such a fill as
    a hairline. A Bézier lies on a line exactly when its control points do."""
    pts = np.vstack([path.start[None]] + [c for _, c in path.segments])
    if len(pts) < 3:
        return False
    sv = np.linalg.svd(pts - pts.mean(axis=0), compute_uv=False)
    return bool(sv[-1] > 1e-9 * max(sv[0], 1e-300))


def is_dot(path: Subpath) -> bool:
    """Whether the subpath has no length (every point at its start): a stroke draws it as
    its cap alone."""
    return all(np.array_equal(c, np.broadcast_to(path.start, c.shape)) for _, c in path.segments)


def bbox(paths: list[Subpath]) -> tuple[np.ndarray, np.ndarray] | None:
    """The tight bounds of the subpaths (curves sampled finely enough for a gradient's or
    clip's bounding-box units), or None when there are none."""
    pts = [flattened(s, 1e-4 * _extent(s)) for s in paths]
    if not pts:
        return None
    allp = np.vstack(pts)
    return allp.min(axis=0), allp.max(axis=0)


def _extent(s: Subpath) -> float:
    pts = np.vstack([s.start[None]] + [c for _, c in s.segments])
    return float(np.ptp(pts, axis=0).max(initial=0)) or 1.0


def group_chain(scene: Scene, group: int) -> list[int]:
    """The groups from the root down to ``group`` (indices)."""
    chain = []
    while group >= 0:
        chain.append(group)
        group = scene.groups[group].parent
    return chain[::-1]


def shape_to(scene: Scene, shape, ancestor: int = -1) -> np.ndarray:
    """The shape's own space -> the space of group ``ancestor`` (-1: the root user space)."""
    m = f64(shape.transform)
    g = shape.group
    while g != ancestor and g >= 0:
        m = f64(scene.groups[g].transform) @ m
        g = scene.groups[g].parent
    return m


def scene_bbox(scene: Scene, group: int = -1) -> tuple[np.ndarray, np.ndarray] | None:
    """Bounds of the fills of the shapes inside group ``group`` (-1: all), in its space:
    a group's bounding box for clip and mask units."""
    boxes = []
    for shape in scene.shapes:
        if group >= 0 and group not in group_chain(scene, shape.group):
            continue
        b = bbox(transformed(subpaths(shape.geometry), shape_to(scene, shape, group)))
        if b is not None:
            boxes.append(b)
    if not boxes:
        return None
    return np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)


def unit_box(box) -> np.ndarray | None:
    """The matrix of objectBoundingBox units for the box (min, max); None for an empty one."""
    if box is None:
        return None
    (x0, y0), (x1, y1) = box
    if x1 - x0 <= 0 or y1 - y0 <= 0:
        return None
    return np.array([[x1 - x0, 0, x0], [0, y1 - y0, y0], [0, 0, 1]], np.float64)
