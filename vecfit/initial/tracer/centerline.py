"""trace_strokes: line art traced as stroked paths along its centerlines (``--style strokes``),
and areas as fills under line work (``--style mixed``).

Pipeline: the background is the colour of the image's border; the ink colours are those of
the flat (not anti-aliased) pixels that differ from it, clustered and merged. Every pixel
is then a blend of the background and its nearest ink (its coverage: how far along the
line from one to the other it lies), and a pixel at least half covered is that ink's.
Each ink's connected pieces are skeletonised and joined into paths (skeleton.py), the
paths fitted with cubic Béziers (the tracer's own fitter, bezier.py; straight runs as
lines, closed circles as circles: primitives.py; a line through a junction, where the
skeleton wobbles, as one line: straight_runs.py), stroked with twice the median distance
from centerline to outline and the ink's colour. Caps and joins are chosen by rendering
the strokes with each and comparing with the image.

A piece the strokes do not draw well (thicker than ``max_stroke``, in mixed than
``max_line``, or a blob its skeleton does not cover) is traced as fills, under the strokes: the image with the
stroked line work removed goes through the fills tracer (trace.py). ``strokes`` warns
when that happens; ``mixed`` expects it (colour areas under outlines), and fills the
lines' pixels from their surroundings rather than with the background, so the areas run
on under the lines.
"""
from __future__ import annotations

import dataclasses
import time
import warnings

import cv2
import numpy as np

from vecfit.errors import VecfitWarning
from vecfit.svg.numbers import fmt_many, hex_color
from vecfit.svg.pathdata import format_relative_path_data

from .bezier import TANGENT_REACH, Stretches, _unit, fit_outlines, fit_pieces, open_corners
from .primitives import _continues, as_primitive, open_outline, straightened
from .quantize import OPAQUE, to_lab
from .settings import TraceResult, TraceSettings
from .skeleton import Chain, centerlines
from .straight_runs import straight_runs
from .svgtext import DECIMALS, add_rect, new_document

# A pixel is ink where it differs from the background by more than this (CIELAB units).
INK_CONTRAST = 20.0
# Ink colours closer than this (CIELAB) are one ink.
SAME_INK = 18.0
# A piece is line work where its strokes, drawn at their widths, cover at least this share
# of it and at most 1 - this share of what they draw is outside it (each within a pixel).
MIN_COVER = 0.85
# A piece's core: its pixels at least this far (px) inside the line, clear of its rims.
CORE_RADIUS = 1.5
# Pieces of ink smaller than this many pixels are specks.
MIN_PIECE = 12
# Centerlines shorter than this many widths are dots (a disc thins to a pixel or a short
# run): drawn as a round-capped stroke of no length.
DOT_LENGTH = 0.5
# How far either side (pixels) a centerline's corners are judged: thinning cuts a
# line's corner diagonally over a few pixels, two bends of 135 degrees that the fills'
# 3 pixels see as no corner at all.
CORNER_REACH = 6.0
# A centerline's cubic within this many pixels of its chord is a line (at least; the
# trace's `lines` if larger): a skeleton wobbles by a pixel where lines meet, which the
# refinement straightens, but only a line stays a line.
LINE_TOLERANCE = 1.0
# A piece's width is judged at this quantile of the widths along its centerlines: the
# median for strokes (a line's junctions and ends are wider or narrower); nearly all of it
# for mixed, where areas of colour are expected, and an area's skeleton runs mostly through
# its narrow parts between holes and the outline (an emoji's face round its eyes and mouth:
# median 59 px, 90% 110 px at 512 px; its outlines 13-15 px).
WIDTH_QUANTILE = {"strokes": 0.5, "mixed": 0.9}
# A dot (a round blob: a piece whose centerline is a dot) may be this many times as wide
# as the widest line with --style strokes: line art draws its dots twice as wide as its
# lines (Tabler's: a circle of radius 1 stroked 2 wide), and a dot of that size traced as
# a fill left an icon drawn by strokes but for one path. In mixed an eye is an area.
DOT_WIDEST = 2.0
# With mixed, line work is at least this wide (px, the median): a thinner piece of an area's
# colour is a sliver between outlines (an emoji's tongue where the outline crosses it) or a
# rim, which the refinement thins to nothing while it holds a path of the budget; the fills
# draw it.
MIN_MIXED_WIDTH = 2.0
SMOOTHING = 2.0
# The fit's tolerance for centerlines (at most; the trace's `tolerance` if smaller). 0.7 px
# gave 1.3 dB more on 5 icons for 23% more segments, 0.5 px 1.6 dB for 42% more.
FIT_TOLERANCE = 0.7
# Smoothing (sigma, pixels) of a centerline before its fit (at least; the trace's
# `smoothing` if larger).
# A closed centerline within this many pixels of an ellipse is one (the fills' 0.35 is
# for edges placed from the anti-aliasing; a centerline's points wobble more).
ELLIPSE_TOLERANCE = 0.75
# Coverage below this is paper (a scan's noise; 0.03 noise sigma, JPEG ringing).
NOISE_FLOOR = 0.12
# A background or ink colour within this of pure white or black (each channel) is that:
# paper and ink of a scan or a photo of a drawing come out a shade off (noise clipped at
# white and black, JPEG), where a designer's are pure.
SNAP = 0.04
# Ink a piece's strokes leave undrawn (more than a pixel from them) gets a dot stroke where
# it is at least this share of a disc of the piece's half width, and as wide as this
# share of it: a stub shorter than its width (Tabler's `M18 4l0 1` over a square) thins to
# nothing and was lost, 15 dB on its icon.
MISSING_AREA = 0.3
MISSING_WIDTH = 0.6
# A corner sharper than this many degrees (its sides as they leave it) is acute: a wide
# line's skeleton falls short of its apex by more than thinning's few pixels (see _apex).
ACUTE = 80.0
CAPS = ("round", "butt", "square")  # (the first of each is the default)
# Another cap or join is chosen where its render's squared error is this share of the
# default's or less.
CLEARLY_BETTER = 0.8
JOINS = ("round", "miter", "bevel")
# A join other than round, further: a round-cornered drawing (Tabler's corners of radius
# 1 at width 2) thins to sharp corners, whose round joins draw the outside too round and
# bevels too flat, and bevels came out 0.63-0.77 of round there (three Tabler letters,
# which the fit then kept bevelled, 11-17 dB below their ceiling); the corners' fillets
# (fitting/fillets.py) need round joins.
JOIN_CLEARLY_BETTER = 0.6


@dataclasses.dataclass
class Stroke:
    """A fitted centerline: its SVG element (tag, geometry attributes), segments, width and colour."""
    tag: str
    geometry: dict
    segments: int
    width: float
    color: str


# ---------------------------------------------------------------------- colours

def snapped(rgb: np.ndarray) -> np.ndarray:
    """Colours [..., 3] within SNAP of white or black made white or black."""
    rgb = np.array(rgb, np.float64)
    white = (rgb >= 1 - SNAP).all(-1)
    black = (rgb <= SNAP).all(-1)
    rgb[white] = 1.0
    rgb[black] = 0.0
    return rgb


def border_color(rgb: np.ndarray, alpha: np.ndarray) -> np.ndarray | None:
    """The median colour of the image's border pixels; None where the border is mostly
    transparent (then the background is transparency)."""
    border = np.concatenate([rgb[0], rgb[-1], rgb[:, 0], rgb[:, -1]])
    border_alpha = np.concatenate([alpha[0], alpha[-1], alpha[:, 0], alpha[:, -1]])
    if np.mean(border_alpha >= OPAQUE) < 0.5:
        return None
    return snapped(np.median(border[border_alpha >= OPAQUE], axis=0))


def ink_colors(rgb: np.ndarray, ink: np.ndarray, lab: np.ndarray, colors: int, seed: int) -> np.ndarray:
    """The ink colours [K, 3] (sRGB): the flat ink pixels (no neighbour differs by more than
    SAME_INK / 2, so not an anti-aliased rim) clustered and merged within SAME_INK, most
    used first; the most distinct ink pixels where no ink pixel is flat (hairlines)."""
    spread = cv2.dilate(lab, np.ones((3, 3), np.uint8)) - cv2.erode(lab, np.ones((3, 3), np.uint8))
    flat = ink & (np.abs(spread).max(-1) < SAME_INK / 2)
    chosen = flat if flat.sum() >= MIN_PIECE else ink
    samples = lab[chosen]
    if len(samples) == 0:
        return np.zeros((0, 3))
    rng = np.random.default_rng(seed)
    if len(samples) > 20_000:
        samples = samples[rng.choice(len(samples), 20_000, replace=False)]
    k = int(min(colors, 8, len(np.unique(np.round(samples), axis=0))))
    cv2.setRNGSeed(seed)
    _, labels, centres = cv2.kmeans(np.ascontiguousarray(samples, np.float32), k, None,
                                    (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 20, 0.1), 1,
                                    cv2.KMEANS_PP_CENTERS)
    counts = np.bincount(labels.reshape(-1), minlength=k)
    kept: list[tuple[np.ndarray, int]] = []  # (Lab centre, pixels), merged greedily by count
    for i in np.argsort(-counts).tolist():
        for j, (c, n) in enumerate(kept):
            if np.linalg.norm(c - centres[i]) < SAME_INK:
                kept[j] = ((c * n + centres[i] * counts[i]) / (n + counts[i]), n + counts[i])
                break
        else:
            if counts[i] >= MIN_PIECE or not kept:
                kept.append((centres[i], int(counts[i])))
    # each ink's colour in sRGB: the mean of the chosen pixels nearest its centre
    pixels_rgb, pixels_lab = rgb[chosen], lab[chosen]
    centres_lab = np.array([c for c, _ in kept])
    nearest = np.argmin(((pixels_lab[:, None, :] - centres_lab[None]) ** 2).sum(-1), 1)
    return snapped(np.array([pixels_rgb[nearest == i].mean(0) for i in range(len(kept))]))


def piece_color(rgb: np.ndarray, lab: np.ndarray, core: np.ndarray, ink: np.ndarray) -> np.ndarray:
    """A piece's colour: its ink's, unless the median of its core pixels (``core``: inside
    the line, away from the anti-aliased rim) lies more than SAME_INK / 2 from it. Inks are
    merged within SAME_INK, so a dark grey dot (an emoji's eye, #1d1d1b) beside black
    outlines took the black; the strokes' colours are not refined (scan noise), so it
    stayed black. Pieces that are their ink's colour keep it exactly (one ink, one colour
    in the file)."""
    if core.sum() < MIN_PIECE:
        return ink
    own_lab = np.median(lab[core], axis=0)
    if np.linalg.norm(own_lab - to_lab(np.asarray(ink, np.float64)[None, None])[0, 0]) <= SAME_INK / 2:
        return ink
    return snapped(np.median(rgb[core], axis=0))


def coverage(rgb: np.ndarray, background: np.ndarray, inks: np.ndarray):
    """(which ink each pixel is nearest, [H, W] int; its coverage by that ink, [H, W] in
    [0, 1]): the pixel as background + t (ink - background), t least squares in sRGB."""
    h, w = rgb.shape[:2]
    d = (rgb - background).reshape(-1, 3)
    best_t = np.zeros(h * w)
    best = np.zeros(h * w, np.int64)
    best_residual = np.full(h * w, np.inf)
    for i, ink in enumerate(inks):
        v = ink - background
        t = np.clip(d @ v / max(float(v @ v), 1e-9), 0, 1)
        residual = ((d - t[:, None] * v) ** 2).sum(1)
        better = residual < best_residual
        best[better], best_t[better], best_residual[better] = i, t[better], residual[better]
    return best.reshape(h, w), best_t.reshape(h, w)


# ------------------------------------------------------------------------ fitting

def _resampled(points: np.ndarray, closed: bool, step: float = 1.0) -> np.ndarray:
    """The polyline at even steps of arc length (its ends kept)."""
    p = np.concatenate([points, points[:1]]) if closed else points
    seg = np.hypot(*np.diff(p, axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    n = max(int(np.ceil(cum[-1] / step)), 1)
    at = np.linspace(0, cum[-1], n + 1)
    out = np.stack([np.interp(at, cum, p[:, 0]), np.interp(at, cum, p[:, 1])], 1)
    return out[:-1] if closed and len(out) > 3 else out


def _apex(p: np.ndarray, c: int, reach: int, lo: int, hi: int, half_width: float = 0.0) -> tuple[np.ndarray, int]:
    """(Where the lines through the two sides of the corner at p[c] meet, if near p[c],
    else p[c]; how many points either side of it thinning rounded). Each side's points
    2 `reach` to 5 `reach` away. Thinning rounds an acute corner of a wide line (half width
    ``half_width``) further: its inner corner lies a half width over the sine of half
    the angle from the apex, and the skeleton forks (to a spur that pruning removes)
    short of the apex by half the difference; there the sides are judged from beyond the
    inner corner (within p[lo:hi + 1], the neighbouring corners) and the apex taken that
    much further."""
    def side(a, b, lo=0, hi=len(p) - 1):
        q = p[max(a, lo):min(b, hi + 1)]
        if len(q) < 2:
            return None
        centre = q.mean(0)
        _, _, vt = np.linalg.svd(q - centre)
        return centre, vt[0]

    def meet(a, b):
        if a is None or b is None:
            return None
        (pa, da), (pb, db) = a, b
        det = da[0] * -db[1] + db[0] * da[1]
        if abs(det) < 0.3:  # nearly parallel sides: no clear apex
            return None
        t = ((pb - pa)[0] * -db[1] + db[0] * (pb - pa)[1]) / det
        # (and the corner's angle: between the sides as they leave it)
        angle = np.degrees(np.arccos(np.clip(float(_unit(pa - p[c]) @ _unit(pb - p[c])), -1, 1)))
        return pa + t * da, angle
    # the sides a little way off: thinning rounds an acute corner over a half width or more
    found = meet(side(c - 5 * reach, c - 2 * reach), side(c + 2 * reach + 1, c + 5 * reach + 1))
    if found is None:
        return p[c], reach
    limit, drop = 1.5 * reach, reach
    if half_width > 0 and found[1] < ACUTE:
        sin_half = np.sin(np.radians(found[1]) / 2)
        near = max(2 * reach, int(round(half_width / sin_half)))
        again = meet(side(c - near - 3 * reach, c - near, lo, hi), side(c + near + 1, c + near + 3 * reach + 1, lo, hi))
        if again is not None:
            found = again
            limit += half_width * (1 / sin_half - 1) / 2
            drop = max(reach, near // 2)
    x = found[0]
    return (x, drop) if np.hypot(*(x - p[c])) < limit else (p[c], reach)


def fit_open(polylines: list[np.ndarray], tolerance: float, corner_angle: float,
             smoothing: float, half_widths: list[float] | None = None) -> list[np.ndarray]:
    """Cubic segments [S, 4, 2] of each open polyline (points at 1 px steps): cut at its
    corners, each stretch smoothed with its ends held and fitted as bezier.fit_outlines
    fits a closed outline's stretches. ``half_widths``: each line's half width (thinning
    rounds a corner over about that: its apex is found, and its points dropped, that far)."""
    pieces, owner = [], []
    reach = int(round(CORNER_REACH))
    for k, p in enumerate(polylines):
        bounds = [0, *open_corners(Stretches(p, np.array([len(p)])).smoothed(smoothing / 2), corner_angle, reach),
                  len(p) - 1]
        r = 0.0 if half_widths is None else half_widths[k]
        p = p.copy()
        drops = [0]
        for i, c in enumerate(bounds[1:-1], 1):  # a corner at the meeting of its sides' lines (see _apex)
            p[c], cut = _apex(p, c, reach, bounds[i - 1], bounds[i + 1], r)
            drops.append(cut)
        drops.append(0)
        for i, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):
            inner = np.arange(a, b + 1)
            # thinning cuts the corner over about `drop` points: those go
            cut = ((inner - a < drops[i]) & (inner != a) & (a > 0)) | \
                  ((b - inner < drops[i + 1]) & (inner != b) & (b < len(p) - 1))
            if (~cut).sum() >= 2:
                inner = inner[~cut]
            pieces.append(p[inner])
            owner.append(k)
    return fit_pieces(pieces, owner, len(polylines), smoothing, max(1, int(round(TANGENT_REACH))), tolerance)


def _sample(image: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Bilinear samples of a float [H, W] image at points xy [..., 2] (pixel centres at +0.5),
    0 outside."""
    shape = xy.shape[:-1]
    flat = xy.reshape(-1, 2).astype(np.float32) - 0.5
    n = len(flat)
    side = 1024  # cv2.remap takes maps under 32767 on a side: the points as rows of 1024
    rows = max(1, -(-n // side))
    maps = np.zeros((rows * side, 2), np.float32) - 10
    maps[:n] = flat
    out = cv2.remap(image.astype(np.float32), maps[:, 0].reshape(rows, side), maps[:, 1].reshape(rows, side),
                    cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    return out.reshape(-1)[:n].reshape(shape)


def centred(points: np.ndarray, closed: bool, ink: np.ndarray, radius: float) -> tuple[np.ndarray, float | None]:
    """The centerline (1 px steps) moved to the middle of the line, and the line's width:
    across the line at each point, the coverage's centre of mass and its sum (a symmetric
    line's middle and width, to a fraction of a pixel, where the skeleton's pixels are
    half a pixel off). Points where the profile is not one clean line (junctions, ends,
    corners: its sum far from the median) stay where they are. Width None: no clean point."""
    if len(points) < 3:
        return points, None
    smooth = Stretches(points, np.array([len(points)])).smoothed(2.0) if not closed else points
    tangent = np.gradient(smooth, axis=0)
    if closed:
        tangent = np.roll(points, -1, 0) - np.roll(points, 1, 0)
    tangent = _unit(tangent)
    normal = np.stack([-tangent[:, 1], tangent[:, 0]], 1)
    reach = radius + 2.5
    offsets = np.arange(-reach, reach + 1e-9, 0.5)
    profile = _sample(ink, points[:, None, :] + offsets[None, :, None] * normal[:, None, :])
    # a clean profile crosses one line: no ink at its two ends (beyond a scan's noise)
    clean = (profile[:, :2].max(1) < NOISE_FLOOR * 2) & (profile[:, -2:].max(1) < NOISE_FLOOR * 2)
    profile = np.where(profile < NOISE_FLOOR, 0.0, profile)  # noise in the paper adds no width
    mass = profile.sum(1) * 0.5
    clean &= mass > 0.5
    if not clean.any():
        return points, None
    width = float(np.median(mass[clean]))
    shift = np.where(clean, (profile * offsets).sum(1) * 0.5 / np.maximum(mass, 1e-9), 0.0)
    shift = np.clip(shift, -1.0, 1.0)
    return points + shift[:, None] * normal, width


def _extended(points: np.ndarray, ink: np.ndarray, radius: float) -> np.ndarray:
    """An open centerline's ends moved on to a half width short of where the ink ends ahead
    of them (thinning stops short of a line's end; a round cap then reaches the end)."""
    if len(points) < 2:
        return points
    points = points.copy()
    steps = np.arange(0.0, 3 * radius + 3, 0.5)
    for end, inner in ((0, min(4, len(points) - 1)), (-1, -1 - min(4, len(points) - 1))):
        ahead = _unit(points[end] - points[inner])
        profile = _sample(ink, points[end] + steps[:, None] * ahead)
        gone = np.flatnonzero(profile < 0.5)
        if not len(gone):
            continue
        # where the coverage falls through one half, to a fraction of a step
        k = int(gone[0])
        reach = steps[k] if k == 0 else steps[k - 1] + 0.5 * (profile[k - 1] - 0.5) / max(profile[k - 1] - profile[k], 1e-6)
        if reach - radius > 0.25:
            points[end] = points[end] + (reach - radius) * ahead
    return points


def is_dot(chain, width: float) -> bool:
    return not chain.closed and float(np.hypot(*np.ptp(chain.points, axis=0))) < max(DOT_LENGTH * width, 2.0)


def fitted_strokes(chains, radius: np.ndarray, ink: np.ndarray, color: str, s: TraceSettings) -> list[Stroke]:
    """The chains of one ink fitted and given their widths: Strokes. ``ink``: the ink's
    coverage of each pixel, in [0, 1]."""
    h, w = radius.shape
    s = dataclasses.replace(s, lines=max(s.lines, LINE_TOLERANCE), smoothing=max(s.smoothing, SMOOTHING),
                            tolerance=min(s.tolerance, FIT_TOLERANCE))
    out: list[Stroke] = []
    opened, closed = [], []
    for c in chains:
        (closed if c.closed and len(c.points) >= 8 else opened).append(c)
    widths = {}
    for c in opened + closed:
        ix = np.clip(c.points.astype(int), 0, [w - 1, h - 1])
        # the distance transform runs from the centre pixel to the nearest pixel outside:
        # half a pixel past the outline
        widths[id(c)] = max(2 * float(np.median(radius[ix[:, 1], ix[:, 0]])) - 1, 1.0)
        if is_dot(c, widths[id(c)]) and len(c.points) >= 2:
            # a short line's skeleton is a pixel or two: a line where its ends, moved on
            # to the ink's, are a line apart
            longer = _extended(c.points, ink, widths[id(c)] / 2)
            if not is_dot(dataclasses.replace(c, points=longer), widths[id(c)]):
                c.points = longer
        if not is_dot(c, widths[id(c)]):
            points, width = centred(_resampled(c.points, c.closed), c.closed, ink, widths[id(c)] / 2)
            if width is not None:
                widths[id(c)] = width
            c.points = points if c.closed else _extended(points, ink, widths[id(c)] / 2)
    dots = [c for c in opened if is_dot(c, widths[id(c)])]
    # closed chains with corners are fitted as open runs from the middle of a side to it
    # again (so every corner is inside the run, where fit_open places its apex); smooth
    # loops (circles, ovals) as closed outlines
    reach = int(round(CORNER_REACH))
    runs, smooth = [c for c in opened if not any(c is d for d in dots)], []
    for c in closed:
        n = len(c.points)
        wrapped = np.concatenate([c.points[-reach:], c.points, c.points[:reach]])
        corners = [k - reach for k in open_corners(wrapped, s.corner_angle, reach) if reach <= k < n + reach]
        if not corners:
            smooth.append(c)
            continue
        gaps = np.diff(corners + [corners[0] + n])
        at = (corners[int(np.argmax(gaps))] + int(gaps.max()) // 2) % n
        rolled = np.roll(c.points, -at, axis=0)
        runs.append(dataclasses.replace(c, points=np.concatenate([rolled, rolled[:1]])))
        widths[id(runs[-1])] = widths[id(c)]
    for c in dots:
        # a dot's width from its ink: the area of the disc it draws
        centre = c.points.mean(0)
        reach = widths[id(c)] / 2 + 3
        ys, xs = np.mgrid[0:h, 0:w]
        near = np.hypot(xs + 0.5 - centre[0], ys + 0.5 - centre[1]) <= reach
        widths[id(c)] = 2 * float(np.sqrt(ink[near].sum() / np.pi))
        x, y = fmt_many(list(centre), DECIMALS)
        out.append(Stroke("path", {"d": f"M{x} {y}h0"}, 1, widths[id(c)], color))
    if runs:
        fitted = fit_open([c.points for c in runs], s.tolerance, s.corner_angle, s.smoothing,
                          [widths[id(c)] / 2 for c in runs])
        for c, segs in zip(runs, fitted):
            segs = straight_runs(segs, c.crossings, widths[id(c)], c.closed, s.lines)
            points, degrees = open_outline(segs, s.lines)
            if c.closed:
                points, degrees = _closed_layout(points, degrees, s.lines)
            d = format_relative_path_data(points, degrees, [(0, len(degrees), c.closed)], decimals=DECIMALS)
            out.append(Stroke("path", {"d": d}, len(degrees), widths[id(c)], color))
    if smooth:
        loops = [c.points for c in smooth]
        fitted = fit_outlines(loops, s.tolerance, s.corner_angle, s.smoothing, CORNER_REACH)
        for c, loop, segs in zip(smooth, loops, fitted):
            outline = straightened(segs, s.lines) if s.lines > 0 else None
            shape = as_primitive(loop, outline, s.lines, ELLIPSE_TOLERANCE) if outline is not None and s.primitives else None
            if shape is not None:
                numbers = dict(zip(shape.attributes, fmt_many(list(shape.attributes.values()), DECIMALS)))
                out.append(Stroke(shape.tag, numbers, 4, widths[id(c)], color))
                continue
            if outline is None:
                points = np.concatenate([segs[:1, 0], segs[:, 1:].reshape(-1, 2)])
                degrees = [3] * len(segs) + [1]
            else:
                points, degrees = outline.points, outline.degrees
            d = format_relative_path_data(points, degrees, [(0, len(degrees), True)], decimals=DECIMALS)
            out.append(Stroke("path", {"d": d}, len(degrees) - 1, widths[id(c)], color))
    return out


def _closed_layout(points: np.ndarray, degrees: list[int], tolerance: float):
    """An open run that ends where it starts as a closed outline (the Scene's layout: the
    start not stored again, the last segment a line that the Z draws): where the run
    starts and ends on lines that continue each other, those are one line."""
    if len(degrees) > 2 and degrees[0] == 1 and degrees[-1] == 1 and \
            _continues(points[-2], points[0], points[1], tolerance):
        return points[1:-1], degrees[1:-1] + [1]
    if degrees[-1] == 1:
        return points[:-1], degrees
    return points, degrees + [1]  # the Z a line of (nearly) no length


def drawn_mask(chains, radius: np.ndarray) -> np.ndarray:
    """The pixels the chains cover, stroked (round) at their median widths: a quick check of
    how well strokes draw a piece."""
    h, w = radius.shape
    out = np.zeros((h, w), np.uint8)
    for c in chains:
        ix = np.clip(c.points.astype(int), 0, [w - 1, h - 1])
        r = float(np.median(radius[ix[:, 1], ix[:, 0]]))
        pts = np.round(c.points * 4).astype(np.int32)[None]  # 2 bits of sub-pixel precision
        if len(c.points) == 1:  # a dot (polylines draws nothing for one point)
            cv2.circle(out, tuple(int(v) for v in pts[0, 0]), max(1, int(round(4 * (r - 0.5)))), 1, -1,
                       lineType=cv2.LINE_8, shift=2)
            continue
        cv2.polylines(out, pts, c.closed, 1, thickness=max(1, int(round(2 * r - 1))), lineType=cv2.LINE_8, shift=2)
    return out > 0


# --------------------------------------------------------------------- the trace

def _element(document, stroke: Stroke, cap: str, join: str) -> None:
    document.add(stroke.tag, {**stroke.geometry, "fill": "none", "stroke": stroke.color,
                              "stroke-width": fmt_many([stroke.width], DECIMALS)[0],
                              "stroke-linecap": cap, "stroke-linejoin": join})


def _choose_caps(strokes: list[Stroke], w: int, h: int, background, image: np.ndarray) -> tuple[str, str]:
    """The cap and join whose render of the strokes is nearest the image (squared error)."""
    import warnings

    from vecfit.renderer.forward import render_numpy
    from vecfit.scene.arrays import numpy_arrays
    from vecfit.svg.read import scene_of

    def error(cap, join):
        document = new_document(w, h)
        for st in strokes:
            _element(document, st, cap, join)
        with numpy_arrays(), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # (vecfit's own SVG: nothing to warn of)
            scene = scene_of(document)
            rgba = render_numpy(scene, w, h, samples=1, threads=1)
        under = np.ones(3) if background is None else background
        rgb = rgba[..., :3] * rgba[..., 3:] + under * (1 - rgba[..., 3:])
        target = image[..., :3] * image[..., 3:] + under * (1 - image[..., 3:])
        return float(((rgb - target) ** 2).sum())

    # round unless another is clearly better: thinning leaves ends and acute corners short
    # of where they are, which a square cap or a miter covers at first, and the refinement
    # then moves them out (a miter's spike and a square's corners overshoot)
    def best(options, err, clearly_better):
        errors = {o: err(o) for o in options}
        choice = min(errors, key=errors.get)
        return choice if errors[choice] < clearly_better * errors[options[0]] else options[0]

    has_ends = any(st.tag == "path" and not st.geometry["d"].rstrip().lower().endswith("z") for st in strokes)
    cap = best(CAPS, lambda c: error(c, "round"), CLEARLY_BETTER) if has_ends else "round"
    join = best(JOINS, lambda j: error(cap, j), JOIN_CLEARLY_BETTER)
    return cap, join


def trace_strokes(image: np.ndarray, settings: TraceSettings, progress=None) -> TraceResult:
    """Trace ``image`` (checked float32 RGBA [H, W, 4]) with ``settings.style`` strokes or
    mixed (see the module docstring)."""
    from .trace import trace_image  # (trace.py calls this module)

    start = time.perf_counter()
    s = settings
    report = progress or (lambda stage, fraction: None)
    h, w = image.shape[:2]
    rgb, alpha = image[..., :3].astype(np.float64), image[..., 3]
    background = border_color(rgb, alpha)
    report("quantise", 0.0)
    lab = to_lab(rgb)
    opaque = alpha >= OPAQUE
    if background is None:
        ink = opaque
    else:
        ink = opaque & (np.linalg.norm(lab - to_lab(background[None, None]), axis=-1) > INK_CONTRAST)
    inks = ink_colors(rgb, ink, lab.astype(np.float32), int(s.colors), int(s.seed))
    if background is None:  # over transparency each ink covers by its alpha
        which = np.argmin(((lab[..., None, :] - to_lab(inks[None])[0]) ** 2).sum(-1), -1) if len(inks) else \
            np.zeros((h, w), np.int64)
        covered = alpha
    else:
        which, covered = coverage(rgb, background, inks)
    report("regions", 0.2)

    limit = "max_line" if s.style == "mixed" else "max_stroke"  # the setting that bounds line work
    widest = getattr(s, limit) * min(h, w)
    strokes: list[Stroke] = []
    stroked = np.zeros((h, w), bool)   # pixels whose ink the strokes draw
    left_over = np.zeros((h, w), bool)  # ink pixels left to fills
    for i, color in enumerate(inks):
        mask = ((which == i) & (covered >= 0.5) & opaque).astype(np.uint8)
        count, pieces, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
        radius = cv2.distanceTransform(mask, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        ink_cover = np.where((which == i) & opaque, covered, 0.0)
        good = np.zeros((h, w), bool)
        for k in range(1, count):
            if stats[k, cv2.CC_STAT_AREA] < max(MIN_PIECE, s.min_area):
                continue
            x0, y0, bw, bh = (int(v) for v in stats[k, :4])
            pad = 1
            ys, xs = slice(max(y0 - pad, 0), min(y0 + bh + pad, h)), slice(max(x0 - pad, 0), min(x0 + bw + pad, w))
            piece = pieces[ys, xs] == k
            r = np.where(piece, radius[ys, xs], 0)
            chains = centerlines(piece, r) or _dot(piece)
            for c in chains:
                _moved(c, (xs.start, ys.start))
            fits = bool(chains) and _fits(chains, piece, r, (xs.start, ys.start), widest, s.style)
            if chains and not fits:
                # the other thinning, where Zhang-Suen's skeleton misses part of the piece
                other = centerlines(piece, r, "guo-hall")
                for c in other:
                    _moved(c, (xs.start, ys.start))
                if other and _fits(other, piece, r, (xs.start, ys.start), widest, s.style):
                    chains, fits = other, True
            if fits:
                own = piece_color(rgb[ys, xs], lab[ys, xs], piece & (r >= CORE_RADIUS), color)
                chains = chains + _missing_dots(chains, piece, r, (xs.start, ys.start))
                strokes += fitted_strokes(chains, np.where(pieces == k, radius, 0), ink_cover, hex_color(own), s)
                good[ys, xs] |= piece
            else:
                left_over[ys, xs] |= piece
        stroked |= good
    report("fit", 0.6)

    # the pixels the strokes draw (with their anti-aliased rims), taken out of the image
    # handed to the fills
    drawn = cv2.dilate(stroked.astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
    if s.style == "strokes":  # (mixed paints the lines over from their surroundings, areas included)
        drawn &= ~cv2.dilate(left_over.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    warnings_given = []
    thick = int(left_over.sum())
    if not strokes:
        warnings_given.append(f"no line work thin enough for strokes ({limit} "
                              f"{getattr(s, limit):g} of the shorter side): traced as fills")
    elif thick >= max(MIN_PIECE, s.min_area) and s.style == "strokes":
        warnings_given.append(f"{thick} pixels of ink are not line work (too thick, or shapes): traced as fills")
    for message in warnings_given:
        warnings.warn(f"trace --style {s.style}: {message}", VecfitWarning, stacklevel=3)

    fills_settings = dataclasses.replace(s, style="fills")
    if not strokes:
        result = trace_image(image, fills_settings)
        return dataclasses.replace(result, seconds=time.perf_counter() - start, warnings=warnings_given)
    if thick >= max(MIN_PIECE, s.min_area) or (s.style == "mixed" and background is None and thick):
        rest = image.copy()
        if s.style == "mixed":  # the areas run on under the lines: each drawn pixel takes
            # the colour of the nearest pixel not drawn (flat, as the areas are; inpainting's
            # gradients came back as specks)
            _, nearest = cv2.distanceTransformWithLabels(drawn.astype(np.uint8), cv2.DIST_L2, 3,
                                                         labelType=cv2.DIST_LABEL_PIXEL)
            outside = np.flatnonzero(~drawn.reshape(-1))  # label k: the k-th pixel not drawn
            source = outside[np.clip(nearest[drawn] - 1, 0, len(outside) - 1)]
            rest[drawn] = rest.reshape(-1, 4)[source]
        # what the fills trace: the ink left over, its rims, and (mixed) the lines' pixels
        # painted over; the rest is paper (a scan's noise in it came back as a thousand specks)
        keep = cv2.dilate(left_over.astype(np.uint8), np.ones((5, 5), np.uint8)).astype(bool)
        paper = ~(keep | drawn) if s.style == "mixed" else ~keep | drawn
        if background is None:
            rest[paper, 3] = 0
        else:
            rest[paper, :3] = background
        traced = trace_image(rest, fills_settings, covered=stroked if s.style == "mixed" else None)
        document, paths, segments, colors = traced.document, traced.paths, traced.segments, traced.colors
    else:
        document, paths, segments, colors = new_document(w, h), 0, 0, 0
        if background is not None:
            add_rect(document, w, h, hex_color(background))
            colors = 1
    cap, join = _choose_caps(strokes, w, h, background, image)
    for st in strokes:
        _element(document, st, cap, join)
    report("fit", 1.0)
    return TraceResult(document=document, paths=paths + len(strokes),
                       colors=colors + len({st.color for st in strokes}),
                       segments=segments + sum(st.segments for st in strokes),
                       seconds=time.perf_counter() - start, strokes=len(strokes), warnings=warnings_given)


def _moved(chain: Chain, origin) -> None:
    """A piece's chain (points and crossings) moved from the piece's box into the image."""
    chain.points += origin
    chain.crossings[:, :2] += origin


def _drawn_locally(chains, piece: np.ndarray, radius: np.ndarray, origin) -> np.ndarray:
    """What strokes along ``chains`` draw of the piece's box (``origin`` its top left),
    their open ends moved on as the fit moves them (_extended)."""
    inside = piece.astype(np.float32)
    local = [dataclasses.replace(c, points=c.points - origin if c.closed else
                                 _extended(c.points - origin, inside, _half_width(c.points - origin, radius)))
             for c in chains]
    return drawn_mask(local, radius)


def _missing_dots(chains, piece: np.ndarray, radius: np.ndarray, origin) -> list:
    """Dot chains (image coordinates) for the piece's ink that strokes along ``chains`` leave
    undrawn (MISSING_AREA, MISSING_WIDTH): each at the undrawn part's deepest point, the
    centre of the widest disc inside the piece there."""
    hw = np.median([_half_width(c.points - origin, radius) for c in chains])
    near = cv2.dilate(_drawn_locally(chains, piece, radius, origin).astype(np.uint8), np.ones((3, 3), np.uint8))
    undrawn = (piece & ~near.astype(bool)).astype(np.uint8)
    count, parts, stats, _ = cv2.connectedComponentsWithStats(undrawn, connectivity=8)
    dots = []
    for k in range(1, count):
        if stats[k, cv2.CC_STAT_AREA] < MISSING_AREA * np.pi * hw * hw:
            continue
        depth = np.where(parts == k, radius, 0)
        y, x = np.unravel_index(int(np.argmax(depth)), depth.shape)
        at = np.array([x + 0.5, y + 0.5]) + origin
        if depth[y, x] - 0.5 >= MISSING_WIDTH * hw and _beside(chains, at, hw):
            dots.append(Chain(points=at[None], closed=False))
    return dots


def _beside(chains, at: np.ndarray, hw: float) -> bool:
    """Whether ``at`` lies past an open chain's end (thinning stopped short of the line's
    end) or beside the chain, square to it on both sides of the nearest point (within 60
    degrees): a stub standing on a line. Not beyond a corner: thinning leaves an acute
    apex undrawn too, but the fit draws that out (centerline._apex), and dots there cost
    Tabler icons 2-12 dB."""
    best = None
    for c in chains:
        d = np.hypot(*(c.points - at).T)
        i = int(np.argmin(d))
        if best is None or d[i] < best[0]:
            best = (d[i], c, i)
    _, c, i = best
    n, k = len(c.points), max(2, int(round(hw)))
    if not c.closed and (i < k or i >= n - k):
        return True  # (past a line's end, where thinning stopped short)
    before, after = c.points[(i - k) % n], c.points[(i + k) % n]
    away = at - c.points[i]
    norm = float(np.hypot(*away))
    if norm <= 0:
        return False
    for t in (c.points[i] - before, after - c.points[i]):
        length = float(np.hypot(*t))
        if length <= 0 or abs(float(away @ t)) / (norm * length) > 0.5:
            return False
    return True


def _dot(piece: np.ndarray) -> list:
    """A piece whose skeleton thins to nothing (a round blob: a Tabler dot, a full stop)
    as one dot at its centre, which _fits then judges: a dot stroke where the piece is
    round, fills where it is not."""
    ys, xs = np.nonzero(piece)
    if not len(xs):
        return []
    return [Chain(points=np.array([[xs.mean() + 0.5, ys.mean() + 0.5]]), closed=False)]


def _half_width(points: np.ndarray, radius: np.ndarray) -> float:
    """A chain's half width: the median distance to the outline along it, less the half
    pixel the distance transform counts past the outline."""
    ix = np.clip(points.astype(int), 0, [radius.shape[1] - 1, radius.shape[0] - 1])
    return max(float(np.median(radius[ix[:, 1], ix[:, 0]])) - 0.5, 0.5)


def _fits(chains, piece: np.ndarray, radius: np.ndarray, origin, widest: float, style: str = "strokes") -> bool:
    """Whether strokes along ``chains`` draw the ``piece`` (a bool mask whose top left is
    at ``origin``): thin enough (WIDTH_QUANTILE), and covering it (MIN_COVER, intersection
    over union)."""
    along = np.concatenate([c.points for c in chains]) - origin
    ix = np.clip(along.astype(int), 0, [piece.shape[1] - 1, piece.shape[0] - 1])
    radii = radius[ix[:, 1], ix[:, 0]]
    width = 2 * float(np.quantile(radii, WIDTH_QUANTILE[style])) - 1
    dot = style == "strokes" and len(chains) == 1 and is_dot(chains[0], width)
    if width > widest * (DOT_WIDEST if dot else 1.0):
        return False
    if style == "mixed" and 2 * float(np.median(radii)) - 1 < MIN_MIXED_WIDTH:
        return False
    # thinning stops short of a line's ends (a short line's skeleton is a fraction of it):
    # the ends are judged as the strokes draw them, moved on as _extended moves them
    drawn = _drawn_locally(chains, piece, radius, origin)
    # judged a pixel either way: a thin line's width is rounded to whole pixels here
    near_drawn = cv2.dilate(drawn.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    near_piece = cv2.dilate(piece.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    covered = (piece & near_drawn).sum() / max(int(piece.sum()), 1)
    spilled = (drawn & ~near_piece).sum() / max(int(drawn.sum()), 1)
    return covered >= MIN_COVER and spilled <= 1 - MIN_COVER
