"""Sub-pixel edges: moving outlines off the pixel grid by reading the anti-aliasing.

A region's outline from the label map runs along pixel edges, so it can be up to half a
pixel off the true edge. Where the target is anti-aliased, the pixels on either side of
an edge are blends of the two regions' colours, and the blend fractions say where the
edge lies: with the edge at offset e from the pixel edge (positive outwards, |e| < 1),
the outer pixel is covered max(e, 0) by the region and the inner one 1 + min(e, 0), so
e = f_out - (1 - f_in). Only edges that will show are moved: those against a region
drawn earlier (underneath) or against transparency (there the fraction is alpha).

All outlines of an image are processed together, laid end to end, in the compiled core.
"""
from __future__ import annotations

import numpy as np

from vecfit import _core

MIN_CONTRAST = 0.1  # RGB distance below which two colours are too close to read a blend from
MAX_SHIFT = 0.5     # pixels; photographs give noisy fractions, which stay within this
REACH = 2           # midpoints either side that vote on an edge's offset


def refine_outlines(outlines: list[np.ndarray], regions: np.ndarray, labels: np.ndarray,
                    rank: np.ndarray, colors: np.ndarray, rgb: np.ndarray,
                    alpha: np.ndarray, holes: np.ndarray) -> list[np.ndarray]:
    """The outlines (each [N, 2], vertices at the pixel corners and edge midpoints, as
    outlines.crack_outlines gives them; regions[k] is outline k's region, holes[k] whether
    it bounds a hole cut out of that region) with their visible edges moved to where the
    blend fractions put them. Corners follow the edges next to them.

    In the compiled core (csrc/trace/subpixel.cpp). Each edge midpoint reads the pixels
    just inside and outside it: only edges that show are read (against transparency,
    where the fraction is alpha, or against a region drawn earlier, where it is the
    coverage between the two fill colours, given a contrast of MIN_CONTRAST). Each
    midpoint's offset is then the median of the readings up to REACH midpoints either
    side along its outline that face the same way: near a corner a pixel is partly
    covered because of the other edge, which the one-edge model misreads, and the
    neighbours along the same edge outvote it (and photo noise too); midpoints with no
    reading of their own follow their neighbours the same way. Offsets are clipped to
    MAX_SHIFT; a corner vertex moves by the mean of its neighbours' shifts along a
    straight run, by their sum where the outline turns."""
    if not outlines:
        return []
    lengths = np.array([len(o) for o in outlines], np.int64)
    moved = _core.refine_outlines(np.concatenate(outlines).astype(np.float64, copy=False), lengths,
                                  np.asarray(regions, np.int64), np.asarray(holes, bool),
                                  np.asarray(labels, np.int32), np.asarray(rank, np.int64),
                                  np.asarray(colors, np.float64), np.asarray(rgb, np.float32),
                                  np.asarray(alpha, np.float32),
                                  _core.SubpixelOptions(min_contrast=MIN_CONTRAST, max_shift=MAX_SHIFT, reach=REACH))
    return np.split(moved, np.cumsum(lengths)[:-1])
