"""Cut-outs: a drawing of stacked fills rewritten as pieces that do not overlap.

Cutters, vinyl plotters and screen printers want every colour as its own piece, with no
piece under another. The stacked drawing (what trace and refine write: shapes over a
backdrop, each reaching under those on top) is sampled on a grid finer than the pixels,
and its pieces (vecfit/scene/partition.py: the samples with the same stack of shapes)
are traced back along the lines between them. Each boundary between two pieces is one
chain: the stretch of the drawing's own outline that it runs along (cutout_curves.py), or
else fitted with the tracer's Bézier fit; it is written forwards in one piece and
backwards in the other, so the pieces meet edge to edge: no gap, no overlap.

A piece is painted with what its stack drew there: the top shape's colour where it is
opaque, translucent shapes composited over what they covered (so a cut-out of a
translucent drawing looks the same, and every piece is one flat colour).

Where two pieces meet, a renderer that anti-aliases each piece on its own lets a little of
the page through (each covers the edge pixel by its share, and the shares do not add up
to full cover): a seam. ``gap_filler`` draws every shared edge first, as a thin stroke
of the two sides' mean colour, under the pieces.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from vecfit.errors import VecfitError
from vecfit.scene.arrays import numpy_arrays, to_numpy
from vecfit.scene.model import Solid
from vecfit.scene.outline import f64, flattened, subpaths, transformed
from vecfit.scene.partition import OUTSIDE, absorb_specks, partition, sample_stacks
from vecfit.scene.placement import canvas_matrix, shape_matrices
from vecfit.scene.segments import layout_of
from vecfit.scene.untangle import loop_area, simple_loops
from vecfit.svg.document import SvgDocument
from vecfit.svg.numbers import fmt, hex_color
from vecfit.svg.pathdata import format_relative_path_data
from vecfit.svg.precision import root_decimals

from .bezier import TANGENT_REACH, Stretches, fit_outlines, fit_pieces, open_corners
from .cutout_curves import OutlineFinder, closed_loops, crossing_near, layout, local_polyline, on_outline
from .primitives import line_like, open_outline, straightened

MAX_SAMPLES = 16_000_000  # the sampling grid's size at most (a 2,000-px canvas at 2x2)
SCALE = 4                 # samples a pixel side where the canvas allows
FLATNESS = 0.02           # pixels: how far the sampled polygons stray from the curves
SPECK = 0.5               # square pixels: pieces smaller than this go to a neighbour
TOLERANCE = 0.2           # pixels: the fit of a chain (the drawing is sharp: finer than a trace's)
SMOOTHING = 0.35          # pixels: sigma of the smoothing of the sample grid's staircase
CORNER_ANGLE = 135.0      # degrees, as the tracer
CORNER_WINDOW = 1.5       # pixels either side over which a corner's angle is measured
LINES = 0.1               # pixels: a cubic this close to its chord is a line
STUB = 0.05              # pixels: a segment this short is dropped from a piece's outline
GAP_WIDTH = 1.5           # pixels: the gap filler's stroke (it covers every pixel an edge
                          # crosses: a pixel's far corner lies at most 0.71 px from the edge)


@dataclass
class CutoutReport:
    pieces: int        # paths written (one per stack of shapes that shows)
    chains: int        # boundary stretches, each written in the two pieces it parts
    followed: int      # of them, those laid on the drawing's own outlines (the rest fitted)
    gap_filler: int    # shared edges under a gap-filler stroke (0: none drawn)
    scale: int         # samples a pixel side

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def cutout_problem(scene) -> str | None:
    """Why ``scene`` cannot be cut out, or None: cut-outs need plain fills (no strokes,
    no gradients, no clip, mask, filter or blend, no group opacity)."""
    if scene.has_effects():
        return "it has clip paths, masks, filters or blend modes"
    if any(float(f64(g.opacity).reshape(-1)[0]) < 1 for g in scene.groups):
        return "it has groups with an opacity"
    for shape in scene.shapes:
        if shape.stroke is not None:
            return "it has strokes (cut-outs are filled pieces; use --style fills)"
        if shape.fill is not None and not isinstance(shape.fill, Solid):
            return "it has gradient fills"
    return None


def _alpha(shape) -> float:
    return float(f64(shape.fill.color)[3] * f64(shape.fill_opacity).reshape(-1)[0] *
                 f64(shape.opacity).reshape(-1)[0])


def _composite(stack, colours: np.ndarray, alphas: np.ndarray) -> tuple[np.ndarray, float]:
    """The straight colour and alpha of a stack of shapes drawn bottom to top."""
    premul, a = np.zeros(3), 0.0
    for k in stack:
        premul = premul * (1 - alphas[k]) + colours[k] * alphas[k]
        a = a * (1 - alphas[k]) + alphas[k]
    return (premul / a if a > 0 else premul), a


# ------------------------------------------------------------------- fitting

def _fit_open(polylines: list[np.ndarray], step: float) -> list[np.ndarray]:
    """Cubic segments [S, 4, 2] of each open polyline (points ``step`` px apart, ends held),
    cut at its corners and fitted as the tracer fits an outline's stretches."""
    sigma = SMOOTHING / step
    window = max(1, int(round(TANGENT_REACH / step)))
    reach = max(1, int(round(CORNER_WINDOW / step)))
    pieces, owner = [], []
    for k, p in enumerate(polylines):
        light = Stretches(p, np.array([len(p)])).smoothed(sigma / 2)
        bounds = [0, *open_corners(light, CORNER_ANGLE, reach), len(p) - 1]
        for a, b in zip(bounds[:-1], bounds[1:]):
            pieces.append(p[a:b + 1])
            owner.append(k)
    return fit_pieces(pieces, owner, len(polylines), sigma, window, TOLERANCE)


def _boundary_shape(chain, stacks) -> int | None:
    """The shape whose outline a chain runs along: the topmost that covers one side and not
    the other (None on the canvas's edge)."""
    if OUTSIDE in (chain.left, chain.right):
        return None
    left = set(stacks[chain.left]) if chain.left >= 0 else set()
    right = set(stacks[chain.right]) if chain.right >= 0 else set()
    differ = left ^ right
    return max(differ) if differ else None


def _chain_curves(chains, stacks, loops, scale: int) -> tuple[list[tuple[np.ndarray, list[int]]], int]:
    """Each chain as (points, degrees) in pixels, the Scene's open layout (its start, then
    each segment's points after its start; a closed chain ends at its start): the stretch of
    the shape's outline it runs along where it follows one (cutout_curves.py), else fitted
    to its samples with straight runs as lines. Chains that meet at a junction are made to
    meet exactly (``_junctions``). Returns them and how many followed an outline."""
    step = 1.0 / scale
    polylines = [c.corners[:, ::-1].astype(np.float64) * step for c in chains]
    out: list = [None] * len(chains)
    follows: dict[int, tuple] = {}
    finders: dict[int, OutlineFinder] = {}
    for k, chain in enumerate(chains):
        shape = _boundary_shape(chain, stacks)
        if shape is None or not loops[shape]:
            continue
        if shape not in finders:
            finders[shape] = OutlineFinder(loops[shape])
        found = on_outline(polylines[k], chain.closed, finders[shape])
        if found is not None:
            piece, follow, hint = found
            out[k] = layout(piece)
            if follow is not None:
                follows[k] = (follow, hint)
    followed = sum(x is not None for x in out)
    open_ids = [k for k, c in enumerate(chains) if not c.closed and out[k] is None]
    closed_ids = [k for k, c in enumerate(chains) if c.closed and out[k] is None]
    if open_ids:
        for k, segs in zip(open_ids, _fit_open([polylines[k] for k in open_ids], step)):
            out[k] = open_outline(segs, LINES)
    if closed_ids:
        fitted = fit_outlines([polylines[k] for k in closed_ids], TOLERANCE, CORNER_ANGLE, SMOOTHING,
                              CORNER_WINDOW)
        for k, segs in zip(closed_ids, fitted):
            if not len(segs):  # too small to fit: its corners as a polygon
                p = np.vstack([polylines[k], polylines[k][:1]])
                out[k] = (p, [1] * (len(p) - 1))
                continue
            outline = straightened(segs, LINES)
            # straightened closes with a zero-length Z: the points end at the start
            out[k] = (outline.points, outline.degrees[:-1])
    _junctions(chains, out, follows, step)
    return out, followed


JUNCTION_REACH = 1.5  # pixels round a junction's grid corner where the outlines' crossing is sought


def _junctions(chains, curves, follows: dict, step: float) -> None:
    """Makes the open chains that meet at a junction end at one point: where the outlines
    they follow cross near the junction's grid corner (the exact corner of the drawing), or
    else the mean of their ends. A chain that follows an outline is cut from it afresh to
    end there, so it neither stops short nor overshoots (which would fold the outline of
    a piece into a little loop); a fitted chain's end is moved there with its control
    point (keeping its tangent)."""
    ends: dict[tuple[int, int], list] = {}
    for k, chain in enumerate(chains):
        if not chain.closed:
            for which, corner in ((0, chain.corners[0]), (-1, chain.corners[-1])):
                ends.setdefault((int(corner[0]), int(corner[1])), []).append((k, which))
    meets: dict[tuple[int, int], np.ndarray] = {}
    for corner, members in ends.items():
        near = np.array([corner[1], corner[0]], np.float64) * step
        outlines = {}
        for k, _ in members:
            if k in follows:
                follow = follows[k][0]
                outlines.setdefault((id(follow.finder), follow.loop), follow)
        lines = [local_polyline(f, near, JUNCTION_REACH) for f in outlines.values()]
        found = [x for i in range(len(lines)) for j in range(i + 1, len(lines))
                 if (x := crossing_near(lines[i], lines[j], near)) is not None]
        meets[corner] = np.mean(found, axis=0) if found else \
            np.mean([curves[k][0][which] for k, which in members], axis=0)
    for k, chain in enumerate(chains):
        if chain.closed:
            continue
        a = meets[(int(chain.corners[0][0]), int(chain.corners[0][1]))]
        b = meets[(int(chain.corners[-1][0]), int(chain.corners[-1][1]))]
        if k in follows:
            follow, hint = follows[k]
            piece = follow.piece(a, b, hint)
            if piece and np.hypot(*(piece[0][0] - a)) < JUNCTION_REACH and \
                    np.hypot(*(piece[-1][-1] - b)) < JUNCTION_REACH:
                curves[k] = layout(piece)
        curves[k] = _collinear_as_lines(*_moved_ends(*curves[k], a, b), LINES)


def _collinear_as_lines(points: np.ndarray, degrees: list[int], tolerance: float):
    """The open curve with each cubic whose control points lie within ``tolerance`` of
    its chord's line written as a line. Moving a chain's end back along a straight stretch
    can leave a control point past the new end: a flat cubic that runs beyond its end and
    doubles back, a spike the crossing test rightly finds (noto-emoji-040's cut-outs): so
    unlike the tracer's lines, past the chord's ends counts as on it."""
    out, kept, at = [points[:1]], [], 0
    for d in degrees:
        seg = points[at:at + d + 1]
        at += d
        if d == 3 and line_like(seg[None], tolerance, within_chord=False)[0]:
            seg, d = seg[[0, -1]], 1
        out.append(seg[1:])
        kept.append(d)
    return np.concatenate(out), kept


def _moved_ends(points: np.ndarray, degrees: list[int], a: np.ndarray, b: np.ndarray):
    """The open curve with its ends moved to ``a`` and ``b``, each end's control point
    moved with it."""
    points = points.copy()
    for which, target in ((0, a), (-1, b)):
        delta = target - points[which]
        points[which] = target
        if degrees[which] == 3:
            points[1 if which == 0 else -2] += delta
    return points, degrees


def _reversed(points: np.ndarray, degrees: list[int]) -> tuple[np.ndarray, list[int]]:
    return points[::-1], degrees[::-1]


# ------------------------------------------------------------------- writing

def _segments(points: np.ndarray, degrees: list[int]) -> list[np.ndarray]:
    """An open curve's segments ([d + 1, 2] control points each) from its layout."""
    out, at = [], 0
    for d in degrees:
        out.append(points[at:at + d + 1])
        at += d
    return out


def _without_stubs(segs: list[np.ndarray], shortest: float, closed: bool = True) -> list[np.ndarray]:
    """The loop (or open run) without segments whose control points all lie within
    ``shortest`` of their start (what a cut next to a node leaves at a junction), each
    segment after a dropped one starting where the one before ended: a stub folds an
    outline over itself after rounding. An open run of stubs only is dropped whole."""
    kept = [c for c in segs if float(np.abs(c - c[0]).max()) > shortest]
    if not closed:
        if not kept:
            return []
    elif len(kept) < 2:
        return [c for c in segs if float(np.abs(c - c[0]).max()) > 0]
    out = [c.copy() for c in kept]
    # each kept segment starts where the one before it (kept or not) ended: rejoin them
    for k in range(0 if closed else 1, len(out)):
        previous = out[k - 1][-1]
        delta = previous - out[k][0]
        out[k][0] = previous
        if len(out[k]) == 4:
            out[k][1] += delta
    return out


def _piece_layout(outlines, curves, user, decimals: int, tolerance: float, stub: float, min_area: float):
    """Points, degrees and subpath spans (the root's user space) of a piece's closed
    outlines, each chained from its chains' curves and, should joining the chains have
    made it cross itself, cut at the crossing into simple loops (as untangle.py does, judged
    at the decimals written; loops under ``min_area`` dropped)."""
    points, degrees, spans = [], [], []
    for outline in outlines:
        segs = []
        for k, backwards in outline:
            p, d = curves[k]
            if backwards:
                p, d = _reversed(p, d)
            segs += _segments(user(p), d)
        segs = _without_stubs(segs, stub)
        if not segs:
            continue
        loops = simple_loops(segs, tolerance, decimals)
        for loop in loops:
            area = abs(loop_area(loop))
            # (a lone loop is the piece: kept however small, unless it has no area at all,
            # as where its two chains were laid on the same stretch of an outline)
            if area < (min_area if len(loops) > 1 else stub * stub):
                continue
            loop_points, loop_degrees = layout_of(loop, True)
            spans.append((len(degrees), len(loop_degrees), True))
            points.append(loop_points)
            degrees += loop_degrees
    if not points:  # nothing left of it but slivers
        return None
    return np.concatenate(points), degrees, spans


def _open_layout(runs):
    """Points, degrees and spans of open runs ((points, degrees) each, in pixels)."""
    points, degrees, spans = [], [], []
    for p, d in runs:
        spans.append((len(degrees), len(d), False))
        points.append(p)
        degrees += d
    return np.concatenate(points), degrees, spans


def cut_out(svg: bytes, pixels: tuple[int, int], gap_filler: bool = False,
            precision: int | None = None, name: str = "the SVG") -> tuple[bytes, CutoutReport]:
    """The drawing of ``svg`` (bytes) as cut-outs (see the module's docstring), sampled on a
    ``pixels`` (width, height) canvas; its root element's size and viewBox are kept.
    Raises VecfitError for a drawing that cannot be cut out (``cutout_problem``)."""
    from vecfit.svg.read import scene_of

    document = SvgDocument.parse(svg, name)
    with numpy_arrays(), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = scene_of(document, for_writing=False)
    problem = cutout_problem(scene)
    if problem is not None:
        raise VecfitError(f"{name}: cannot be cut out: {problem}")
    w, h = int(pixels[0]), int(pixels[1])
    scale = max(1, min(SCALE, int(math.sqrt(MAX_SAMPLES / max(w * h, 1)))))
    matrices = np.asarray(to_numpy(shape_matrices(scene, w, h)), np.float64)
    drawn, loops, colours, alphas = [], [], [], []
    for shape, m in zip(scene.shapes, matrices):
        if shape.fill is None:
            continue
        a = _alpha(shape)
        if a <= 0:
            continue
        outline = transformed(subpaths(shape.geometry), m)
        polygons = [flattened(sp, FLATNESS) for sp in outline]
        loops.append(closed_loops(outline))
        drawn.append((polygons, shape.fill_rule == "evenodd", a >= 1.0))
        colours.append(f64(shape.fill.color)[:3])
        alphas.append(min(a, 1.0))
    stacks = sample_stacks(drawn, w, h, scale)
    labels = absorb_specks(stacks.labels, max(1, int(round(SPECK * scale * scale))))
    parts = partition(labels)
    fitted, followed = _chain_curves(parts.chains, stacks.stacks, loops, scale)

    # pixels -> the root's user space, where the file's coordinates are
    to_user = np.linalg.inv(np.asarray(to_numpy(canvas_matrix(scene, w, h)), np.float64))
    decimals = root_decimals(scene, (w, h), precision)
    units_per_pixel = math.sqrt(abs(np.linalg.det(to_user[:2, :2])))

    def user(p):
        return p @ to_user[:2, :2].T + to_user[:2, 2]

    colours, alphas = np.array(colours).reshape(-1, 3), np.array(alphas)
    paints = [_composite(stack, colours, alphas) for stack in stacks.stacks]
    out = SvgDocument.new(w, h)
    for attribute in ("width", "height", "viewBox", "preserveAspectRatio"):
        value = document.root.get(attribute)
        if value is None:
            out.root.attrib.pop(attribute, None)
        else:
            out.root.set(attribute, value)

    # pieces in the order of their topmost shape: the backdrop first, as it was drawn
    order = sorted(parts.outlines, key=lambda piece: (stacks.stacks[piece][-1], len(stacks.stacks[piece]), piece))
    rank = {piece: n for n, piece in enumerate(order)}
    shared = []
    if gap_filler:  # under everything: each edge two pieces share, in the colour of the first drawn
        by_colour: dict[str, list] = {}
        for k, chain in enumerate(parts.chains):
            if chain.left in rank and chain.right in rank:
                under = min(chain.left, chain.right, key=rank.get)
                segs = _without_stubs(_segments(*fitted[k]), STUB, closed=False)
                if segs:  # (a chain of next to no length, where three pieces meet at a point: none)
                    by_colour.setdefault(hex_color(paints[under][0]), []).append(layout_of(segs, False))
                    shared.append(k)
        width = fmt(GAP_WIDTH * units_per_pixel, max(decimals, 2))
        for colour, runs in by_colour.items():
            points, degrees, spans = _open_layout(runs)
            out.add("path", {"d": format_relative_path_data(user(points), degrees, spans, decimals),
                             "fill": "none", "stroke": colour, "stroke-width": width,
                             "stroke-linejoin": "round", "stroke-linecap": "round"})
    written = 0
    for piece in order:
        layout = _piece_layout(parts.outlines[piece], fitted, user, decimals, tolerance=0.01 * units_per_pixel,
                               stub=STUB * units_per_pixel, min_area=units_per_pixel ** 2)
        if layout is None:
            continue
        points, degrees, spans = layout
        written += 1
        colour, alpha = paints[piece]
        attributes = {"d": format_relative_path_data(points, degrees, spans, decimals),
                      "fill": hex_color(colour)}
        if alpha < 0.9995:
            attributes["fill-opacity"] = fmt(alpha, 3)
        out.add("path", attributes)
    report = CutoutReport(pieces=written, chains=len(parts.chains), followed=followed, gap_filler=len(shared), scale=scale)
    return out.serialize(), report
