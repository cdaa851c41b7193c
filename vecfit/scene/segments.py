"""A subpath's segments one by one: control-point arrays out of the Scene's packed layout
and back, points along them, and de Casteljau's split (for the passes that rewrite
outlines: untangle.py, fitting/simplify.py, fillets.py, polygons.py)."""
from __future__ import annotations

from math import comb

import numpy as np


def segments_of(points: np.ndarray, degrees, closed: bool) -> list[np.ndarray]:
    """A subpath's segments as control-point arrays [degree + 1, 2], from the Scene's
    layout (a closed subpath's last segment ends at its start, which is not stored again)."""
    out, p = [], 0
    n = len(degrees)
    for k, d in enumerate(int(x) for x in degrees):
        ctrl = points[p:p + d + 1]
        if closed and k == n - 1:
            ctrl = np.concatenate([points[p:p + d], points[:1]])
        out.append(np.array(ctrl, np.float64))
        p += d
    return out


def layout_of(segs: list[np.ndarray], closed: bool) -> tuple[np.ndarray, list[int]]:
    """Points and degrees of a subpath of segments in the Scene's layout (segments_of's
    inverse; a closed subpath's segments end where they start)."""
    points = [segs[0][:1]] + [c[1:] for c in segs[:-1]] + [segs[-1][1:-1] if closed else segs[-1][1:]]
    return np.concatenate(points), [len(c) - 1 for c in segs]


def split_at(ctrl: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """A Bézier segment (control points [d + 1, 2]) split at t by de Casteljau."""
    left, right = [ctrl[0]], [ctrl[-1]]
    level = ctrl
    while len(level) > 1:
        level = (1 - t) * level[:-1] + t * level[1:]
        left.append(level[0])
        right.append(level[-1])
    return np.array(left), np.array(right[::-1])


def points_at(ctrl: np.ndarray, t: np.ndarray) -> np.ndarray:
    """A Bézier segment of any degree (control points [d + 1, 2]) at parameters t [M]."""
    t = np.asarray(t, np.float64)
    deg = len(ctrl) - 1
    basis = np.stack([comb(deg, i) * t ** i * (1 - t) ** (deg - i) for i in range(deg + 1)], 1)
    return basis @ ctrl


def subpath_segments(path) -> list[tuple[list[np.ndarray], bool]]:
    """A Path's subpaths as (segments, closed), shape units."""
    from .arrays import to_numpy
    pts = np.asarray(to_numpy(path.points), np.float64)
    out = []
    for (first, count, closed), (p0, n) in zip(path.subpaths, path.subpath_point_ranges()):
        degs = [int(d) for d in path.degrees[first:first + count]]
        out.append((segments_of(pts[p0:p0 + n], degs, closed) if count else [], bool(closed)))
    return out


def path_segments(scene) -> dict[int, list[tuple[list[np.ndarray], bool]]]:
    """Shape index -> subpath_segments of each of ``scene``'s paths of one width (what the
    passes that rewrite outlines may change)."""
    from .model import Path
    return {i: subpath_segments(sh.geometry) for i, sh in enumerate(scene.shapes)
            if isinstance(sh.geometry, Path) and sh.geometry.widths is None}


def with_segments(path, subs: list[tuple[list[np.ndarray], bool]]):
    """A Path like ``path`` (its points a tensor where its were) of the subpaths ``subs``."""
    from .arrays import floats_torch, is_tensor
    from .model import Path
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
