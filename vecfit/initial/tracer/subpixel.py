"""Sub-pixel edges: moving outlines off the pixel grid by reading the anti-aliasing.

A region's outline from the label map runs along pixel edges, so it can be up to half a
pixel off the true edge. Where the target is anti-aliased, the pixels on either side of
an edge are blends of the two regions' colours, and the blend fractions say where the
edge lies: with the edge at offset e from the pixel edge (positive outwards, |e| < 1),
the outer pixel is covered max(e, 0) by the region and the inner one 1 + min(e, 0), so
e = f_out - (1 - f_in). Only edges that will show are moved: those against a region
drawn earlier (underneath) or against transparency (there the fraction is alpha).

All outlines of an image are processed together, laid end to end (each stays a closed
loop through its own previous / next index arrays).
"""
from __future__ import annotations

import numpy as np

MIN_CONTRAST = 0.1  # RGB distance below which two colours are too close to read a blend from
MAX_SHIFT = 0.5     # pixels; photographs give noisy fractions, which stay within this
REACH = 2           # midpoints either side that vote on an edge's offset


def coverage(pixels: np.ndarray, inside: np.ndarray, outside: np.ndarray) -> np.ndarray:
    """How much of each pixel is the `inside` colour rather than the `outside` one."""
    d = inside - outside
    return np.clip(((pixels - outside) * d).sum(-1) / np.maximum((d * d).sum(-1), 1e-12), 0, 1)


def cyclic_shift(lengths: np.ndarray, by: int) -> np.ndarray:
    """For loops of the given lengths laid end to end: the index `by` places further
    along each element's own loop."""
    first = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    owner = np.repeat(np.arange(len(lengths)), lengths)
    pos = np.arange(lengths.sum()) - first[owner]
    return first[owner] + (pos + by) % np.maximum(lengths[owner], 1)


def robust_offsets(offset, valid, normal, mid, lengths) -> np.ndarray:
    """Each midpoint's offset replaced by the median over the valid midpoints up to REACH
    places before and after it along its outline that face the same way. Near a corner
    a pixel is partly covered because of the other edge, which the one-edge model
    misreads; the neighbours along the same edge outvote it (and photo noise too).
    Midpoints with no reading of their own (a notch pixel added to the outline, an edge
    hidden under a later region) follow their neighbours the same way."""
    m = np.flatnonzero(mid)
    if len(m) == 0:
        return offset
    owner = np.repeat(np.arange(len(lengths)), lengths)
    mid_lengths = np.bincount(owner[m], minlength=len(lengths))  # midpoints per outline
    code = np.rint(normal[m] @ np.array([1.0, 3.0])).astype(int)  # which way each faces
    vals = np.where(valid[m], offset[m], np.nan)
    window = []
    for d in range(-REACH, REACH + 1):
        j = cyclic_shift(mid_lengths, d)
        window.append(np.where(code[j] == code, vals[j], np.nan))
    window = np.sort(np.array(window), axis=0)  # NaNs sort last
    count = (~np.isnan(window)).sum(0)
    cols = np.arange(len(m))
    lo, hi = np.maximum((count - 1) // 2, 0), np.maximum(count // 2, 0)
    out = offset.copy()
    out[m] = np.where(count > 0, 0.5 * (window[lo, cols] + window[hi, cols]), 0.0)
    return out


def refine_outlines(outlines: list[np.ndarray], regions: np.ndarray, labels: np.ndarray,
                    rank: np.ndarray, colors: np.ndarray, rgb: np.ndarray,
                    alpha: np.ndarray, holes: np.ndarray) -> list[np.ndarray]:
    """The outlines (each [N, 2], vertices at the pixel corners and edge midpoints, as
    outlines.crack_outlines gives them; regions[k] is outline k's region, holes[k] whether
    it bounds a hole cut out of that region) with their visible edges moved to where the
    blend fractions put them. Corners follow the edges next to them."""
    if not outlines:
        return []
    lengths = np.array([len(o) for o in outlines])
    pts = np.concatenate(outlines)
    region = np.repeat(np.asarray(regions), lengths)
    owner = np.repeat(np.arange(len(outlines)), lengths)
    prev, nxt = cyclic_shift(lengths, -1), cyclic_shift(lengths, 1)
    h, w = labels.shape
    v2 = np.rint(pts * 2).astype(np.int64)
    mid = (v2[:, 0] + v2[:, 1]) % 2 == 1  # edge midpoints; the other vertices are corners
    # outward normal of each midpoint's edge, from the outline's direction and orientation
    x, y = pts[:, 0], pts[:, 1]
    ccw = np.bincount(owner, weights=x * y[nxt] - y * x[nxt], minlength=len(outlines)) > 0
    ccw ^= holes  # a hole's outside is the region
    d = pts[nxt] - pts[prev]
    normal = np.stack([d[:, 1], -d[:, 0]], 1) * np.where(ccw[owner], 1.0, -1.0)[:, None]
    normal /= np.maximum(np.abs(normal).sum(1, keepdims=True), 1e-12)
    normal[~mid] = 0.0
    # the pixels just inside and just outside each midpoint
    ix, iy = np.floor(pts - 0.5 * normal).astype(np.int64).T
    ox, oy = np.floor(pts + 0.5 * normal).astype(np.int64).T
    valid = (mid & (np.minimum(ix, ox) >= 0) & (np.minimum(iy, oy) >= 0)
             & (np.maximum(ix, ox) < w) & (np.maximum(iy, oy) < h))
    ix, ox = np.clip(ix, 0, w - 1), np.clip(ox, 0, w - 1)
    iy, oy = np.clip(iy, 0, h - 1), np.clip(oy, 0, h - 1)
    lo = labels[oy, ox]
    valid &= (labels[iy, ix] == region) & (lo != region)
    # only edges that show: against transparency or a region underneath this one
    valid &= np.where(lo >= 0, rank[np.maximum(lo, 0)] < rank[region], True)
    offset = np.zeros(len(pts))
    clear = valid & (lo < 0)
    offset[clear] = alpha[oy[clear], ox[clear]] - (1 - alpha[iy[clear], ix[clear]])
    solid = valid & (lo >= 0)
    if solid.any():
        cin, cout = colors[region[solid]], colors[lo[solid]]
        contrast = np.sqrt(((cin - cout) ** 2).sum(1)) >= MIN_CONTRAST
        f_out = coverage(rgb[oy[solid], ox[solid]], cin, cout)
        f_in = coverage(rgb[iy[solid], ix[solid]], cin, cout)
        offset[solid] = np.where(contrast, f_out - (1 - f_in), 0.0)
    offset = robust_offsets(offset, valid, normal, mid, lengths)
    shift = np.clip(offset, -MAX_SHIFT, MAX_SHIFT)[:, None] * normal
    # a corner vertex follows its neighbours: the mean along a straight run, the sum
    # where the outline turns (the two shifts are then perpendicular)
    turn = np.abs((normal[prev] * normal[nxt]).sum(1)) < 0.5
    corner_shift = np.where(turn[:, None], shift[prev] + shift[nxt], 0.5 * (shift[prev] + shift[nxt]))
    moved = pts + np.where(mid[:, None], shift, corner_shift)
    return np.split(moved, np.cumsum(lengths)[:-1])
