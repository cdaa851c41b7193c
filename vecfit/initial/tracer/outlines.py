"""Outlines of regions along pixel edges, drawing order, and the overlap that closes seams.

Pixel (x, y) covers [x, x+1) x [y, y+1). cv2.findContours on a mask returns the centres
of boundary pixels, half a pixel inside the true edge. We trace instead a grid of twice
the resolution plus one, whose cells are the pixel corners, edge midpoints and centres:
a pixel sets its centre cell and the eight cells around it (its edges and corners). The
outline of that grid runs exactly along the pixel edges, so shapes are not shrunk.
"""
from __future__ import annotations

import cv2
import numpy as np

from .labels import fill_holes
from .tucked import hull_filled


def crack_outlines(mask: np.ndarray, origin=(0, 0), sharp: bool = True) -> list[np.ndarray]:
    """Outer boundaries of a boolean mask along pixel edges: closed polygons, float
    [N, 2] (x, y) in image coordinates (origin = (x0, y0) of the mask), vertices every
    half pixel. Holes are not traced (see shape_outlines). ``sharp``: concave corners
    through the pixel corner (see _through_corners); else cut by half a pixel, which
    smooths the staircases of a photograph's regions (sharp, their corners cost the
    four photos' traces 13-19% more segments for 0.2-0.3 dB)."""
    x0, y0 = origin
    return [(_through_corners(c[:, 0, :]) if sharp else c[:, 0, :]).astype(np.float64) * 0.5
            + (x0 - 0.5, y0 - 0.5) for c in _grid_contours(mask)]


def _through_corners(c: np.ndarray, reach: int = 4) -> np.ndarray:
    """The grid contour ([N, 2] cells) with each diagonal step between two straight runs
    of ``reach`` cells or more (2 px) replaced by the two steps along the pixel edges,
    through the pixel corner between them. The contour of the grid's cells cuts across a
    region's concave corners (a cell whose four neighbours are all set is not on the
    border): a half-pixel chamfer that measured as two 135-degree turns, so the fit took
    no corner there and rounded a flag's cross over tens of pixels. On a staircase (runs
    shorter than that: a gradient band's edge) the chamfer stays: it smooths the steps."""
    n = len(c)
    steps = np.roll(c, -1, axis=0) - c
    diagonal = np.flatnonzero((steps != 0).all(axis=1))
    if not len(diagonal) or n < 2 * reach + 1:
        return c
    straight = (steps == 0).any(axis=1)

    def run(offsets):  # the steps at those offsets from each diagonal: straight and all alike
        at = (diagonal[:, None] + offsets[None, :]) % n
        return straight[at].all(axis=1) & (steps[at] == steps[at[:, :1]]).all(axis=(1, 2))

    diagonal = diagonal[run(-np.arange(1, reach + 1)) & run(np.arange(1, reach + 1))]
    if not len(diagonal):
        return c
    a, b = c[diagonal], c[(diagonal + 1) % n]
    # of the two L-turns, the one through a pixel corner: odd cells in both coordinates
    corner = np.where(((a[:, :1] % 2 == 1) & (b[:, 1:] % 2 == 1)),
                      np.column_stack([a[:, 0], b[:, 1]]), np.column_stack([b[:, 0], a[:, 1]]))
    return np.insert(c, diagonal + 1, corner, axis=0)


_CELL = np.ones((3, 3), np.uint8)  # a pixel's centre and the eight grid cells round it


def _grid_contours(mask: np.ndarray):
    """crack_outlines' polygons in the cells of its grid (int32 [N, 1, 2]): cell j is at
    coordinate (j - 1) / 2 of the mask."""
    h, w = mask.shape
    grid = np.zeros((2 * h + 3, 2 * w + 3), np.uint8)
    grid[2:2 * h + 1:2, 2:2 * w + 1:2] = mask
    grid = cv2.dilate(grid, _CELL)
    contours, _ = cv2.findContours(grid, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    return contours


def shape_outlines(mask: np.ndarray, ranks: np.ndarray, rank: int, origin=(0, 0),
                   min_piece: float = 0, sharp: bool = True):
    """The outlines of the shape that draws a region, and which of them are holes.

    ranks: the drawing rank of the region at each pixel of the mask's box (-1 where no
    region draws: transparent); rank: the rank of this shape's region.

    A hole of the region that holds only regions drawn later needs no outline: they go
    on top. But the filled outline must not paint over what lies below it: transparent
    pixels in a hole (a ring on a transparent canvas would become a disc), nor pixels of
    regions drawn before this one that the outline encloses although their region
    reaches outside. That happens because outlines join pixels that touch at a corner:
    where two regions cross at a corner (both 8-connected through it), or where a region
    grown by the overlap closes a corner gap, the outline of one encloses part of the
    other, which was drawn first, being larger. Those pixels are cut out, but for pieces
    of earlier regions under `min_piece` pixels: like the specks the regions merged
    away, they cost less error than the outlines that would cut them. The shape is the
    mask with its holes filled except for the cut; its boundaries alternate, outline,
    hole, island in the hole..., and are filled even-odd. Returns (outlines as
    crack_outlines gives them, ``sharp`` passed on; a bool per outline: is it a hole)."""
    filled = fill_holes(mask)
    enclosed = filled & ~mask
    cut = None
    if enclosed.any():  # (most regions have no hole: they skip this)
        below = ranks[enclosed]
        cut = np.zeros_like(mask)
        cut[enclosed] = below < 0  # transparent
        covered = np.zeros_like(mask)
        covered[enclosed] = (below >= 0) & (below < rank)
        if covered.any():
            _, pieces, stats, _ = cv2.connectedComponentsWithStats(covered.view(np.uint8), connectivity=8)
            large = stats[:, cv2.CC_STAT_AREA] >= min_piece
            large[0] = False  # the background label
            cut |= large[pieces]
    if cut is None or not cut.any():  # nothing to cut: the outer outlines alone (the usual case)
        found = crack_outlines(mask, origin, sharp)
        return found, [False] * len(found)
    outlines, holes = [], []
    level, hole = filled & ~cut, False
    while level.any():
        found = crack_outlines(level, origin, sharp)
        outlines += found
        holes += [hole] * len(found)
        # what this level encloses without being part of it: the next level in
        level = fill_holes(level) & ~level
        hole = not hole
    return outlines, holes


def drawing_order(labels: np.ndarray, count: int, boxes, host: np.ndarray | None = None) -> np.ndarray:
    """Regions sorted by filled area (pixels plus holes), largest first: a region that
    encloses another always comes before it, so its holes need no cutting out where other
    regions fill them (only transparent pixels, and regions crossing it at a corner, are
    cut: see shape_outlines). ``host``: the pieces tucked under each region (tucked.py),
    which its area counts (``boxes`` must then hold them too)."""
    filled = np.zeros(count)
    for i, box in enumerate(boxes):
        if box is None:
            continue
        mask = labels[box] == i
        if host is not None:
            mask |= host[box] == i
        # the outlines' areas in grid cells (a quarter pixel each): on integer vertices
        # every sum is exact, so this is the area of crack_outlines' polygons to the bit
        filled[i] = 0.25 * sum(cv2.contourArea(c) for c in _grid_contours(mask))
    return np.argsort(-filled, kind="stable")


def grown_masks(labels: np.ndarray, rank: np.ndarray, ranks: np.ndarray, regions, boxes, overlap: int,
                host: np.ndarray | None = None, hulls: bool = False):
    """grown_mask of each of `regions`, their corner notches filled all at once (rank:
    each region's drawing rank; ranks: each pixel's region's, -1 where none; host: the
    pieces tucked under each region; hulls: pieces grown under what covers them, both
    tucked.py)."""
    grown = [grown_mask(labels, ranks, i, rank[i], boxes[i], overlap, host, hulls) for i in regions]
    filled = fill_corner_notches_many([mask for mask, _ in grown])
    return [(mask, origin) for mask, (_, origin) in zip(filled, grown)]


def grown_mask(labels: np.ndarray, ranks: np.ndarray, i: int, rank_i: int, box, overlap: int,
               host: np.ndarray | None = None, hulls: bool = False):
    """Region i's mask, grown by `overlap` pixels into the regions drawn after it (on
    top; ranks: each pixel's region's drawing rank, -1 where none; rank_i: region i's). Two regions that meet
    side by side both have anti-aliased edges there, which would let the background show
    through as a faint seam; growing the lower one under the upper one hides it, and also
    absorbs the curve fit's error. Returns the mask (corner notches not yet filled:
    grown_masks fills them) and its (x0, y0) in the image."""
    h, w = labels.shape
    r0, r1 = max(box[0].start - overlap, 0), min(box[0].stop + overlap, h)
    c0, c1 = max(box[1].start - overlap, 0), min(box[1].stop + overlap, w)
    mask = labels[r0:r1, c0:c1] == i
    if host is not None:  # the pieces tucked under it, where they are drawn after it
        mask |= (host[r0:r1, c0:c1] == i) & (ranks[r0:r1, c0:c1] > rank_i)
    if hulls:
        mask = hull_filled(mask, ranks[r0:r1, c0:c1] > rank_i)
    if overlap > 0:
        later = ranks[r0:r1, c0:c1] > rank_i
        size = 2 * overlap + 1
        mask = mask | (cv2.dilate(mask.astype(np.uint8), np.ones((size, size), np.uint8)) > 0) & later
    return mask, (c0, r0)


def fill_corner_notches_many(masks: list[np.ndarray], arm: int = 3, width: int = 1024) -> list[np.ndarray]:
    """fill_corner_notches of each mask, in one call on all of them: they are packed on
    shelves of one canvas, `arm` empty pixels apart (all that a notch's test reads
    beyond a mask, as the padding does), so a thousand small masks cost one pass."""
    if not masks:
        return []
    width = max(width, max(m.shape[1] for m in masks) + 2 * arm)
    places = [None] * len(masks)
    x = y = arm
    shelf = 0
    for k in sorted(range(len(masks)), key=lambda k: -masks[k].shape[0]):
        h, w = masks[k].shape
        if x + w + arm > width:
            x, y, shelf = arm, y + shelf + arm, 0
        places[k] = (y, x)
        x, shelf = x + w + arm, max(shelf, h)
    canvas = np.zeros((y + shelf + arm, width), bool)
    for (y, x), m in zip(places, masks):
        canvas[y:y + m.shape[0], x:x + m.shape[1]] = m
    canvas = fill_corner_notches(canvas, arm)
    return [canvas[y:y + m.shape[0], x:x + m.shape[1]] for (y, x), m in zip(places, masks)]


def fill_corner_notches(mask: np.ndarray, arm: int = 3) -> np.ndarray:
    """The mask with the missing pixel of each sharp corner added.

    At an anti-aliased right-angle corner the corner pixel is covered by the product of
    the two edges' fractions, so it can fall below one half while both edges are traced
    (0.75 x 0.5): the outline then has a one-pixel notch, which the fit turns into a
    chamfer. A notch is an empty pixel with straight filled arms of `arm` pixels along
    two sides and nothing along the other two (unlike a staircase step). Shorter arms
    also catch ragged photo edges, where filling adds segments and no accuracy."""
    m = np.pad(mask, arm)
    empty = ~m
    h, w = mask.shape

    def at(a, dx, dy):
        return a[arm + dy:arm + dy + h, arm + dx:arm + dx + w]

    add = np.zeros_like(mask)
    for sx in (-1, 1):
        for sy in (-1, 1):
            hit = at(empty, -sx, 0) & at(empty, 0, -sy)
            for k in range(1, arm + 1):
                hit &= at(m, k * sx, 0)
                hit &= at(m, 0, k * sy)
                hit &= at(empty, k * sx, -sy)
                hit &= at(empty, -sx, k * sy)
            add |= hit
    return mask | add
