"""The tracer's sub-pixel placement in the compiled core (csrc/trace/subpixel.cpp) moves
outline points, bit for bit, as the NumPy code it replaced did (kept here as the
reference): on the outlines a trace of a photograph and of a transparent, anti-aliased
drawing with holes hands it; and bad input is refused."""
from __future__ import annotations

import numpy as np
import pytest
import skimage.data

from vecfit import _core
from vecfit.initial.tracer import TraceSettings, trace
from vecfit.initial.tracer.subpixel import MAX_SHIFT, MIN_CONTRAST, REACH, refine_outlines


# -------------------------------------------------- the NumPy version, as subpixel.py had it

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


def reference_refine(outlines: list[np.ndarray], regions: np.ndarray, labels: np.ndarray,
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


# ------------------------------------------------------------------------- the tests

def calls_in_a_trace(image, **settings):
    """The arguments trace_image passes to refine_outlines."""
    calls = []

    def capture(*args):
        calls.append(args)
        return refine_outlines(*args)

    saved = trace.refine_outlines
    trace.refine_outlines = capture
    try:
        trace.trace_image(image, TraceSettings.defaults(**settings))
    finally:
        trace.refine_outlines = saved
    assert len(calls) == 1
    return calls[0]


def assert_same_moves(args):
    got = refine_outlines(*args)
    expected = reference_refine(*args)
    assert len(got) == len(expected) > 0
    moved = 0
    for g, e, o in zip(got, expected, args[0]):
        np.testing.assert_array_equal(g, e)
        moved += np.count_nonzero(g != o)
    assert moved > 1000  # the edges did move


@pytest.mark.slow
def test_a_photos_outlines_move_as_numpy_moved_them():
    rgb = skimage.data.chelsea()[:200, :260].astype(np.float32) / 255
    image = np.concatenate([rgb, np.ones_like(rgb[..., :1])], 2)
    assert_same_moves(calls_in_a_trace(image, paths=300))


def test_a_transparent_drawings_outlines_move_as_numpy_moved_them():
    """Anti-aliased discs and rings over transparency: edges against transparency read
    alpha, holes are cut out, regions drawn later meet regions drawn earlier."""
    h = w = 160
    y, x = np.mgrid[0:h, 0:w] + 0.5
    image = np.zeros((h, w, 4), np.float32)
    for cx, cy, r, ring, colour in [(60, 60, 45, 20, (0.9, 0.2, 0.1)), (110, 100, 35, 0, (0.1, 0.3, 0.9)),
                                    (50, 120, 20, 8, (0.2, 0.8, 0.2))]:
        d = np.hypot(x - cx, y - cy)
        cover = np.clip(r - d + 0.5, 0, 1) * (np.clip(d - ring + 0.5, 0, 1) if ring else 1)
        image[..., :3] = image[..., :3] * (1 - cover[..., None]) + np.array(colour) * cover[..., None]
        image[..., 3] = image[..., 3] * (1 - cover) + cover
    image[..., :3] = np.where(image[..., 3:] > 0, image[..., :3] / np.maximum(image[..., 3:], 1e-6), 0)
    args = calls_in_a_trace(np.clip(image, 0, 1), paths=64)
    assert np.asarray(args[-1]).any()  # holes among the outlines
    assert_same_moves(args)


def test_bad_input_is_refused():
    labels = np.zeros((2, 2), np.int32)
    good = dict(points=np.zeros((4, 2)), lengths=np.array([4]), region=np.array([0]), hole=np.array([False]),
                labels=labels, rank=np.array([0]), colors=np.zeros((1, 3)), rgb=np.zeros((2, 2, 3), np.float32),
                alpha=np.ones((2, 2), np.float32),
                options=_core.SubpixelOptions(min_contrast=MIN_CONTRAST, max_shift=MAX_SHIFT, reach=REACH))
    assert _core.refine_outlines(**good).shape == (4, 2)
    with pytest.raises(ValueError, match="expected"):
        _core.refine_outlines(**{**good, "lengths": np.array([3])})
    with pytest.raises(ValueError, match="region is out of range"):
        _core.refine_outlines(**{**good, "region": np.array([1])})
    with pytest.raises(ValueError, match="label is out of range"):
        _core.refine_outlines(**{**good, "labels": np.ones((2, 2), np.int32)})
