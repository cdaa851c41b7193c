"""A subpath's segments one by one: control-point arrays out of the Scene's packed layout
and back, and de Casteljau's split (for the passes that rewrite outlines: untangle.py,
simplify.py)."""
from __future__ import annotations

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
