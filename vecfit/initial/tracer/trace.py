"""trace_image: a raster image to an initial vector graphic (an SvgDocument).

Pipeline: colour quantisation (k-means in CIELAB) -> connected regions of each colour ->
speckles and slivers merged into neighbours, then merges until the path budget holds ->
regions stacked by filled area, largest first, each drawn as its filled outer outline
(less any transparent pixels, or pieces of regions drawn before it, that it encloses,
cut out even-odd), grown a pixel under the regions on top of it -> outlines fitted with
cubic Béziers.
"""
from __future__ import annotations

import time

import numpy as np

from vecfit.errors import VecfitError
from vecfit.io.tone import is_flat_art
from vecfit.svg.numbers import hex_color

from .bezier import fit_outlines
from .groups import grouped
from .labels import bounding_boxes, covering_boxes
from .hidden import smoothed_under_strokes
from .outlines import drawing_order, grown_masks, shape_outlines
from .quantize import OPAQUE, nearest_centre, palette_classes, prefilter, quantize_colors, to_lab
from .regions import build_regions, majority_class, palette_colors
from .settings import TraceResult, TraceSettings
from .subpixel import refine_outlines
from .primitives import Outline, as_primitive, distance_rms, ellipse_outline, straightened
from .tucked import tucked_hosts

# Compound paths keep every region (specks and slivers merge away regardless): the
# budget counts colours. (Capping the regions at 2-8 a path changed no file's segments by
# more than 10% and cost up to 4.6 dB; joining neighbours closer than 3-10 CIELAB units,
# the bands of a quantised gradient, cost 6-10 dB median on 7 designer files.)
ALL_REGIONS = 1 << 30

# An outline within this many pixels of an ellipse is one: the traced edges, placed between
# pixels from the anti-aliasing, stray 0.1-0.2 px from a true circle, and a rounded
# rectangle's sides 0.5 px or more from its nearest ellipse (an emoji's eye, 20 x 37 px).
ELLIPSE_TOLERANCE = 0.35
from .svgtext import add_path, add_primitive, add_rect, new_document, outline_path_data, path_data


def separate_primitives(edges: list, simplified: list, lines: float, most: int) -> list:
    """For each outline of one shape (its traced ``edges`` and fitted ``simplified``
    outlines), the rect, circle or ellipse it is (primitives.as_primitive), or None: only
    outlines whose control points' bounding box meets no other outline's of the shape,
    so each draws alone what it drew in the compound path (no hole in it, none it cuts),
    and its own element of the same opaque paint in the same stacking place leaves the
    picture as it was. At most ``most`` elements in all: the path left (if any) and the
    primitives, the first outlines first."""
    boxes = np.array([[*o.points.min(0), *o.points.max(0)] for o in simplified])
    meets = ((boxes[:, None, 0] <= boxes[None, :, 2]) & (boxes[None, :, 0] <= boxes[:, None, 2])
             & (boxes[:, None, 1] <= boxes[None, :, 3]) & (boxes[None, :, 1] <= boxes[:, None, 3]))
    alone = meets.sum(1) == 1  # (each box meets itself)
    found = [as_primitive(edge, o, lines, ELLIPSE_TOLERANCE) if ok else None
             for edge, o, ok in zip(edges, simplified, alone)]
    while sum(f is not None for f in found) + any(f is None for f in found) > most:
        last = max(k for k, f in enumerate(found) if f is not None)
        found[last] = None
    return found


def elliptical(edge: np.ndarray, outline: Outline) -> Outline:
    """A compound path's subpath that is no element of its own: the exact ellipse (as four
    cubics) where its traced ``edge`` is one within ELLIPSE_TOLERANCE (as_primitive's
    test) and the ellipse follows the edge at least as closely as the fitted ``outline``
    does (a font's 'o' is near an ellipse, not one); else that outline."""
    if 1 in outline.degrees[:-1]:
        return outline
    shape = as_primitive(edge, outline, 0.0, ELLIPSE_TOLERANCE)
    if shape is None:
        return outline
    exact = ellipse_outline(shape, outline)
    edge = np.asarray(edge, float)
    return exact if distance_rms(edge, exact) <= distance_rms(edge, outline) else outline


def check_image(image) -> np.ndarray:
    """The image as float32 RGBA [H, W, 4]; RGB is taken as opaque."""
    a = np.asarray(image)
    if a.ndim != 3 or a.shape[2] not in (3, 4):
        raise VecfitError("trace: expected an RGBA image of shape [H, W, 4], "
                          f"got shape {list(a.shape)}")
    if a.shape[0] == 0 or a.shape[1] == 0:
        raise VecfitError(f"trace: the image is empty ({a.shape[1]}x{a.shape[0]} pixels)")
    if not np.issubdtype(a.dtype, np.floating):
        raise VecfitError(f"trace: expected float values in [0, 1], got {a.dtype} "
                          "(divide 8-bit images by 255)")
    a = a.astype(np.float32)
    if not np.isfinite(a).all():
        raise VecfitError("trace: the image has NaN or infinite values")
    if a.min() < -1e-3 or a.max() > 1 + 1e-3:
        raise VecfitError(f"trace: values must lie in [0, 1], found [{a.min():g}, {a.max():g}]")
    a = np.clip(a, 0, 1)
    if a.shape[2] == 3:
        a = np.concatenate([a, np.ones_like(a[..., :1])], 2)
    return a


def trace_image(image: np.ndarray, settings: TraceSettings | None = None,
                progress=None, palette: np.ndarray | None = None, palette_by: str = "pixels",
                covered: np.ndarray | None = None) -> TraceResult:
    """Trace an image into an SVG document (vecfit.svg.document).

    image: float32 RGBA [H, W, 4], straight alpha in [0, 1] (what vecfit.io.images.load_rgba
    returns). Pixels with alpha >= 0.5 are traced as opaque shapes; the others get no shape,
    so a transparent background stays transparent. settings: None for the defaults
    (TraceSettings.defaults()). Raises VecfitError for a bad image (bad settings are
    refused where TraceSettings is made).

    progress, if given, is called as progress(stage, fraction): stage is one of
    "quantise", "regions", "order", "outline", "fit", fraction how much of the whole
    trace is done, in [0, 1].

    palette (optional, uint8 [n, 3]): the colours to paint with, exactly. ``palette_by``
    "pixels": each pixel takes the nearest of them in CIELAB (instead of k-means' centres)
    and each region the one most of its pixels took; "regions": the regions are k-means'
    as without a palette, each painted with the palette colour nearest (CIELAB) its mean
    colour (anti-aliased rims then merge and place edges as in a free trace: 3.8 dB better
    on a two-colour logo, 1 dB worse on a flag's fine tree; the trace job keeps the
    better of the two).

    covered (optional, bool [H, W]): pixels that strokes drawn over the trace cover
    (``--style mixed``): outlines deep under them are smoothed (hidden.py).
    """
    start = time.perf_counter()
    settings = TraceSettings.defaults() if settings is None else settings
    image = check_image(image)
    if settings.style != "fills":  # line work as strokes (fills where they do not fit)
        from .centerline import trace_strokes
        return trace_strokes(image, settings, progress)
    s = settings
    report = progress or (lambda stage, fraction: None)
    h, w = image.shape[:2]
    rgb = np.ascontiguousarray(image[..., :3])
    alpha = image[..., 3]
    opaque = alpha >= OPAQUE

    report("quantise", 0.0)
    by_pixels = palette is not None and palette_by == "pixels"
    if not by_pixels:
        classes = quantize_colors(prefilter(rgb, s.blur), opaque, int(s.colors), int(s.seed))
    else:
        classes = palette_classes(prefilter(rgb, s.blur), opaque, np.asarray(palette, np.float64) / 255.0)
    report("regions", 0.15)
    # over an opaque image the largest region becomes the background rect, which the budget
    # does not count (a designer's page is the background of the drawing); flat art keeps
    # every region and the budget counts colours (compound paths: groups.py)
    compound = s.compound and is_flat_art(rgb)
    host = None  # flat art's pieces tucked under another region (tucked.py)
    budget = ALL_REGIONS if compound else int(s.paths) + int(bool(opaque.all()))
    regions = build_regions(classes, rgb, budget, s.min_area, s.merge_thin)
    report("order", 0.35)
    boxes = bounding_boxes(regions.labels, regions.count)  # each region's (rows, cols) slices
    order = drawing_order(regions.labels, regions.count, boxes)
    if compound and regions.count:
        backdrop = int(order[0]) if opaque.all() else None
        regions = grouped(regions, rgb, int(s.paths), backdrop)
        host = tucked_hosts(regions.labels, regions.count)
        boxes = covering_boxes(bounding_boxes(regions.labels, regions.count),
                               bounding_boxes(host, regions.count))
        order = drawing_order(regions.labels, regions.count, boxes, host)
        if backdrop is not None:  # the backdrop's group (the last) is drawn first, as the rect
            order = np.concatenate([[regions.count - 1], order[order != regions.count - 1]])
    rank = np.empty(regions.count, np.int64)
    rank[order] = np.arange(regions.count)
    # over an opaque image, everything else is drawn over the largest region: a
    # full-canvas rect will do for that one
    background = order[0] if regions.count and opaque.all() else None

    report("outline", 0.4)
    shapes, outlines, holes = [], [], []  # shapes: (region, its outlines' slice of `outlines`)
    drawn = [i for i in order.tolist() if i != background]
    drawn_rank = np.append(rank, -1)[regions.labels]  # each pixel's region's rank; -1: none
    masks = dict(zip(drawn, grown_masks(regions.labels, rank, drawn_rank, drawn, boxes, int(s.overlap),
                                               host, hulls=compound)))
    for j, i in enumerate(order):
        if i == background:
            continue
        mask, (x0, y0) = masks.pop(i)
        # the shape must not paint over pixels no region draws (transparent, or an isolated
        # speck that was dropped) nor, mostly, those of the regions drawn before it
        ranks = drawn_rank[y0:y0 + mask.shape[0], x0:x0 + mask.shape[1]]
        found, is_hole = shape_outlines(mask, ranks, j, (x0, y0), s.min_area, sharp=compound)
        shapes.append((i, slice(len(outlines), len(outlines) + len(found))))
        outlines.extend(found)
        holes.extend(is_hole)
        if j % 64 == 0:
            report("outline", 0.4 + 0.3 * j / regions.count)
    if s.subpixel:
        owners = np.array([i for i, sl in shapes for _ in range(sl.start, sl.stop)], np.int64)
        outlines = refine_outlines(outlines, owners, regions.labels, rank, regions.color, rgb, alpha,
                                   np.array(holes, bool))
    if covered is not None:  # under mixed's strokes: smoothed (hidden.py)
        outlines = smoothed_under_strokes(outlines, covered)
    report("fit", 0.7)
    # one batched fit of all outlines (see bezier.py)
    fitted = fit_outlines(outlines, s.tolerance, s.corner_angle, s.smoothing, canvas=(w, h))

    if palette is not None:  # exactly the palette's colours
        palette_rgb = np.asarray(palette, np.float64).reshape(-1, 3) / 255.0
        paint = palette_rgb[majority_class(regions, classes, len(palette_rgb)) if by_pixels
                            else nearest_centre(to_lab(regions.color), to_lab(palette_rgb))]
    else:
        paint = palette_colors(regions, classes, rgb) if s.palette else regions.color
    document, segments, fills = new_document(w, h), 0, set()
    if background is not None:
        fills.add(hex_color(paint[background]))
        add_rect(document, w, h, hex_color(paint[background]))
    # the elements the budget still allows beyond one a shape: a compound path's subpaths
    # that are primitives each become one (separate_primitives)
    spare = int(s.paths) - sum(1 for _, sl in shapes if any(len(sp) for sp in fitted[sl]))
    for i, sl in shapes:
        kept = [k for k in range(sl.start, sl.stop) if len(fitted[k])]
        if not kept:
            continue
        subpaths = [fitted[k] for k in kept]
        fill = hex_color(paint[i])
        fills.add(fill)
        cut = any(holes[sl])
        if s.lines <= 0:
            add_path(document, path_data(subpaths), fill, evenodd=cut)
            segments += sum(len(sp) for sp in subpaths)
            continue
        simplified = [straightened(sp, s.lines) for sp in subpaths]
        # (a shape of one outline is one element either way: it may always be a primitive)
        found = (separate_primitives([outlines[k] for k in kept], simplified, s.lines, max(spare, 0) + 1)
                 if s.primitives else [None] * len(simplified))
        rest = [elliptical(outlines[k], o) if s.primitives else o
                for k, o, shape in zip(kept, simplified, found) if shape is None]
        if rest:
            add_path(document, outline_path_data(rest), fill, evenodd=cut)
            segments += sum(len(o.degrees) - 1 for o in rest)
        for shape in found:
            if shape is not None:
                add_primitive(document, shape.tag, shape.attributes, fill)
                segments += 4
        spare -= sum(shape is not None for shape in found) - (not rest)
    report("fit", 1.0)
    return TraceResult(document=document, paths=len(document.root) - (background is not None), colors=len(fills),
                       segments=segments, seconds=time.perf_counter() - start)
