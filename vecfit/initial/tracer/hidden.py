"""Outlines of the fills that the strokes hide (``--style mixed``): smoothed before the fit.

In mixed, the colour areas run on under their outlines (centerline.py paints the lines'
pixels with the nearest area's colour), and two areas meet somewhere under the line that
covers them, along a staircase the label map makes and the fit follows node after node.
No pixel shows it, and a designer draws such an area as a plain shape under its outline.
The outline's points under the strokes are smoothed hard (a Gaussian of SMOOTHING px along
it), each moved no further than it lies under the strokes, less a margin: the fit then
needs few curves there. Points that show are not moved. (Douglas-Peucker polygons within
the same band were tried first: a circle's stretch under a ring became many short lines.)
"""
from __future__ import annotations

import cv2
import numpy as np

from .bezier import Loops

# A point is hidden where every pixel within this many pixels of it is covered.
MIN_DEPTH = 2.0
# Of its depth under the strokes, a smoothed point may move this much less.
MARGIN = 1.0
# The smoothing's sigma (pixels along the outline).
SMOOTHING = 8.0


def smoothed_under_strokes(outlines: list[np.ndarray], covered: np.ndarray) -> list[np.ndarray]:
    """The outlines (each [N, 2], closed, evenly spaced, in pixel units, as the tracer
    makes them) smoothed where they lie under ``covered`` (bool [H, W]: the pixels drawn
    over them; see the module's docstring)."""
    if not outlines:
        return []
    h, w = covered.shape
    inside = cv2.distanceTransform(np.pad(covered.astype(np.uint8), 1), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    inside = inside[1:-1, 1:-1]
    points = np.concatenate(outlines).astype(np.float64, copy=False)
    depth = _point_depth(points, inside, w, h)
    hidden = depth >= MIN_DEPTH
    if not hidden.any():
        return outlines
    loops = Loops(points, np.array([len(o) for o in outlines], np.int64))
    step = float(np.median(np.hypot(*np.diff(outlines[0], axis=0).T))) if len(outlines[0]) > 1 else 1.0
    move = loops.smoothed(SMOOTHING / (step or 1.0)) - points  # all loops at once (bezier.py)
    # each hidden point moved at most its depth less MARGIN; the others stay
    room = np.where(hidden, np.maximum(depth - MARGIN, 0.0), 0.0)
    length = np.hypot(move[:, 0], move[:, 1])
    moved = points + move * np.minimum(1.0, room / np.maximum(length, 1e-12))[:, None]
    return np.split(moved, np.cumsum(loops.lengths)[:-1])


def _point_depth(points: np.ndarray, inside: np.ndarray, w: int, h: int) -> np.ndarray:
    """Each point's depth under the cover: the least of the four pixels around it (a point
    at a pixel corner or edge midpoint touches up to four), less the half pixel the
    distance transform counts to a pixel's centre."""
    x = np.floor(points[:, 0] - 0.5).astype(np.int64)
    y = np.floor(points[:, 1] - 0.5).astype(np.int64)
    least = np.full(len(points), np.inf)
    for dx in (0, 1):
        for dy in (0, 1):
            xi, yi = x + dx, y + dy
            on = (xi >= 0) & (xi < w) & (yi >= 0) & (yi < h)
            least = np.minimum(least, np.where(on, inside[np.clip(yi, 0, h - 1), np.clip(xi, 0, w - 1)], 0.0))
    return least - 0.5
