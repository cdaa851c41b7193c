"""Tucked pieces: a piece of flat art that one other region mostly surrounds is drawn on top
of that region's shape, which runs on under it.

A designer draws Iceland's flag as a white cross with a red cross over it; traced region
by region, the white is four L-shaped pieces round the red, stacked on top of it or cut
around it: twice the nodes, and shapes nobody would draw. Here a piece (an 8-connected
component of one region, as its outline joins it) whose outline lies mostly against one
other region, at least TUCK_SHARE of its length (the canvas's edge and transparency
count against it), is
"tucked" under that region: the region's shape covers the piece too, so the region is
drawn first (its area counts the piece: see outlines.drawing_order) and the piece over it.
A shape enclosed by another was already drawn this way (its holes are filled); this also
takes pieces that reach the canvas's edge or touch a third region along a little of
their outline. Rings that lie half against one region and half against another (an
emoji's outline round its face) stay as they are: neither shares enough.

A piece also runs on under what is drawn over it where that makes its outline simpler
(``hull_filled``): it takes the pixels of its convex hull that later shapes cover, if its
outline gets shorter (by 1% at least). A flag's stripes are then rectangles under the
star, not rectangles with a star-shaped notch.
"""
from __future__ import annotations

import cv2
import numpy as np
from .regions import components

TUCK_SHARE = 0.6
HULL_GAIN = 0.99  # a piece takes the covered part of its hull where its outline gets shorter than this share

_OUTSIDE = -2  # the neighbour "label" of a pixel edge on the canvas's edge


def tucked_hosts(labels: np.ndarray, count: int) -> np.ndarray:
    """[H, W] int64: at each pixel of a tucked piece, the region it is tucked under; -1
    elsewhere. ``labels``: each pixel's region, 0..count-1, -1 where none (transparent)."""
    labels = np.asarray(labels, np.int64)
    host = np.full(labels.shape, -1, np.int64)
    if count < 2 or labels.size == 0:
        return host
    found, n = components(labels)
    pieces = found.astype(np.int64) + 1  # 0: transparent
    n += 1
    owner = np.full(n, -1, np.int64)
    owner[pieces.ravel()] = labels.ravel()

    # every pixel edge between two pieces, counted for each side against the other's region
    sides, against = [], []
    for a, b in ((pieces[:, :-1], pieces[:, 1:]), (pieces[:-1, :], pieces[1:, :])):
        differ = a != b
        a, b = a[differ], b[differ]
        sides += [a, b]
        against += [owner[b], owner[a]]
    for edge in (pieces[0, :], pieces[-1, :], pieces[:, 0], pieces[:, -1]):
        sides.append(edge)
        against.append(np.full(edge.shape, _OUTSIDE, np.int64))
    side, other = np.concatenate(sides), np.concatenate(against)
    keys, counts = np.unique(side * (count + 2) + (other + 2), return_counts=True)
    piece, region = keys // (count + 2), keys % (count + 2) - 2
    perimeter = np.bincount(piece, counts, minlength=n)

    shared = np.where(region >= 0, counts, 0)
    best = np.zeros(n)
    by = np.full(n, -1, np.int64)
    order = np.lexsort((shared, piece))  # within each piece, its largest share last
    best[piece[order]] = shared[order]
    by[piece[order]] = region[order]
    tucked = (owner >= 0) & (by >= 0) & (by != owner) & (best >= TUCK_SHARE * np.maximum(perimeter, 1))
    tucked[0] = False
    if not tucked.any():
        return host
    return np.where(tucked, by, -1)[pieces]


def hull_filled(mask: np.ndarray, later: np.ndarray) -> np.ndarray:
    """The shape's mask with each piece (8-connected) grown into the pixels of its convex
    hull that ``later`` marks (drawn over it: they hide whatever lies under them), where
    that cuts the piece's outline to HULL_GAIN of its length or less."""
    whole = _hull_grown(mask, later)  # all the pieces at once: a band a star cuts in two
    if whole is not None:
        return mask | whole
    count, pieces, stats, _ = cv2.connectedComponentsWithStats(mask.view(np.uint8), connectivity=8)
    out = mask.copy()
    for k in range(1, count):
        x, y, w, h = (int(v) for v in stats[k, :4])
        if w < 3 or h < 3:
            continue
        grown = _hull_grown(pieces[y:y + h, x:x + w] == k, later[y:y + h, x:x + w])
        if grown is not None:
            out[y:y + h, x:x + w] |= grown
    return out


def _hull_grown(mask: np.ndarray, later: np.ndarray) -> np.ndarray | None:
    """The ``later`` pixels of the mask's convex hull that it lacks, if taking them cuts
    its outline to HULL_GAIN of its length or less; else None."""
    points = cv2.findNonZero(mask.view(np.uint8))
    if points is None:
        return None
    hull = np.zeros(mask.shape, np.uint8)
    cv2.fillConvexPoly(hull, cv2.convexHull(points), 1)
    grown = (hull > 0) & later & ~mask
    if grown.any() and _perimeter(mask | grown) <= HULL_GAIN * _perimeter(mask):
        return grown
    return None


def _perimeter(mask: np.ndarray) -> int:
    """The pixel edges between the mask and what is not."""
    m = np.pad(mask, 1)
    return int(np.count_nonzero(m[1:] != m[:-1]) + np.count_nonzero(m[:, 1:] != m[:, :-1]))
