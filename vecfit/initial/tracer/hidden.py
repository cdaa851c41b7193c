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
    h, w = covered.shape
    inside = cv2.distanceTransform(np.pad(covered.astype(np.uint8), 1), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    inside = inside[1:-1, 1:-1]
    return [_smoothed(o, _point_depth(o, inside, w, h)) for o in outlines]


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


def _smoothed(points: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """The closed outline with its hidden points smoothed, each moved at most its depth
    less MARGIN."""
    hidden = depth >= MIN_DEPTH
    if len(points) < 3 or not hidden.any():
        return points
    step = float(np.median(np.linalg.norm(np.diff(points, axis=0), axis=1))) or 1.0
    sigma = SMOOTHING / step
    reach = min(int(3 * sigma), (len(points) - 1) // 2)
    kernel = np.exp(-0.5 * (np.arange(-reach, reach + 1) / sigma) ** 2)
    kernel /= kernel.sum()
    wrapped = np.concatenate([points[-reach:], points, points[:reach]]) if reach else points
    smooth = np.stack([np.convolve(wrapped[:, k], kernel, mode="valid") for k in range(2)], axis=1)
    move = smooth - points
    room = np.maximum(depth - MARGIN, 0.0)
    length = np.linalg.norm(move, axis=1)
    scale = np.where(length > room, room / np.maximum(length, 1e-12), 1.0)
    return np.where(hidden[:, None], points + move * scale[:, None], points)
