"""Outlines under mixed's strokes smoothed before the fit (vecfit/initial/tracer/hidden.py)."""
from __future__ import annotations

import cv2
import numpy as np

from vecfit.initial.tracer.bezier import fit_outlines
from vecfit.initial.tracer.hidden import MARGIN, MIN_DEPTH, _point_depth, smoothed_under_strokes


def box_outline(x0, y0, x1, y1, step=0.5):
    """A closed rectangle's outline, a point every ``step`` px, clockwise from (x0, y0)."""
    legs = [((x0, y0), (x1, y0)), ((x1, y0), (x1, y1)), ((x1, y1), (x0, y1)), ((x0, y1), (x0, y0))]
    out = []
    for (ax, ay), (bx, by) in legs:
        n = int(round(max(abs(bx - ax), abs(by - ay)) / step))
        u = np.arange(n)[:, None] / n
        out.append(np.array([ax, ay]) + u * (np.array([bx, by]) - np.array([ax, ay])))
    return np.concatenate(out)


def test_a_wobbling_edge_under_a_line_is_smoothed_and_the_rest_stays():
    covered = np.zeros((100, 100), bool)
    covered[40:62, :] = True  # a line 22 px wide across the image, drawn over the fills
    outline = box_outline(10.0, 20.0, 90.0, 51.0)
    bottom = np.abs(outline[:, 1] - 51.0) < 1e-9
    wobble = outline.copy()
    # where two areas meet under the line: a wobble of 2 px every 8 px
    wobble[bottom, 1] += 2 * np.sin(np.arange(bottom.sum()) * 2 * np.pi / 16)
    (smoothed,) = smoothed_under_strokes([wobble], covered)
    inside = cv2.distanceTransform(np.pad(covered.astype(np.uint8), 1), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
    depth = _point_depth(wobble, inside, 100, 100)
    moved = np.linalg.norm(smoothed - wobble, axis=1)
    assert np.array_equal(smoothed[depth < MIN_DEPTH], wobble[depth < MIN_DEPTH])  # what shows stays
    assert (moved <= np.maximum(depth - MARGIN, 0) + 1e-9).all()  # within the band
    middle = bottom & (np.abs(wobble[:, 0] - 50) < 25)
    assert np.std(smoothed[middle, 1]) < 0.2 * np.std(wobble[middle, 1])
    # and the fit needs fewer curves for it
    before, after = fit_outlines([wobble], 1.0, 135.0)[0], fit_outlines([smoothed], 1.0, 135.0)[0]
    assert len(after) < len(before), (len(before), len(after))


def test_nothing_covered_nothing_moves():
    outline = box_outline(10.0, 10.0, 50.0, 40.0)
    (same,) = smoothed_under_strokes([outline], np.zeros((64, 64), bool))
    assert np.array_equal(same, outline)
