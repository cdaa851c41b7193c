"""What the tracer takes and gives: its settings (with their checks) and its result."""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, fields

from vecfit.errors import VecfitError
from vecfit.io.configs import defaults
from vecfit.names import STYLES


@dataclass
class TraceSettings:
    """Knobs of trace_image. Their defaults are configs/trace.toml's (``defaults()``),
    chosen by measuring PSNR, path and segment counts on skimage's astronaut, chelsea,
    coffee and rocket (benchmarks/trace.py)."""

    colors: int
    """k of the colour quantisation: the colour classes regions start from (regions are
    then painted with their own mean colour, so the picture has more colours than k)."""
    paths: int
    """Path budget: at most this many shapes, besides the background (over an opaque image,
    the largest region is one full-canvas rect, as the page under a designer's drawing)."""
    min_area: float
    """Speckle removal: regions smaller than this many pixels are merged into neighbours."""
    tolerance: float
    """Largest distance in pixels between an outline and its Bézier fit."""
    corner_angle: float
    """An outline turning sharper than this (degrees; 180 is straight) gets a corner."""
    blur: float
    """Gaussian blur (sigma, pixels) of the image before quantisation; 0 for none."""
    overlap: int
    """Pixels each shape reaches under the shapes drawn on top of it (closes seams)."""
    smoothing: float
    """Gaussian sigma (pixels) by which outlines are smoothed before fitting, to iron out
    the pixel staircase."""
    merge_thin: bool
    """Merge one-pixel-wide slivers that are blends of their neighbours (the anti-aliased
    rim between two flat colours) like speckles."""
    subpixel: bool
    """Place edges between pixels where the target's anti-aliasing says they lie."""
    palette: bool
    """Paint each region with its colour class's average colour, so the picture has at
    most `colors` colours (a poster look), instead of the region's own mean colour
    (closer to the image)."""
    lines: float
    """A cubic whose control points lie within this many pixels of its chord is written as
    a line, and lines that continue each other as one (0: every segment a cubic)."""
    primitives: bool
    """A shape whose outline is an axis-aligned rectangle, circle or ellipse (within
    ``lines`` pixels, or the fit's tolerance for curves) is written as that element."""
    compound: bool
    """On flat art (icons, logos, emoji: most pixels in flat areas), keep every region and
    draw the regions of one colour as one path of several pieces, the budget then counting
    colours (groups.py); photographs keep a path per region."""
    remove_background: bool
    """Leave the image's flat background out of the SVG (the border's dominant colour, or
    [optimize] background): no shape covers it, and shapes are fitted against it as
    against transparency (background.py; the trace job)."""
    style: str
    """fills: every region a filled outline; strokes: line work as stroked paths along its
    centerline (centerline.py), fills only where no stroke fits; mixed: fills for areas and
    strokes for the line work over them."""
    max_stroke: float
    """strokes: the widest line traced as a stroke, as a fraction of the image's shorter
    side (thicker ink is traced as fills)."""
    max_line: float
    """mixed: the widest line work stroked over the fills, as a fraction of the image's
    shorter side (areas of colour are wider than outlines)."""
    seed: int
    """Seed of the k-means sampling and initialisation: equal seeds give equal output."""

    def __post_init__(self):
        check_settings(self)  # the one check: every TraceSettings made (defaults, a job's, replace) is sound

    @classmethod
    def defaults(cls, **changes) -> "TraceSettings":
        """The defaults of configs/trace.toml ([trace], and [optimize]'s seed), with ``changes``."""
        table = {**defaults("trace", "trace"), "seed": defaults("trace", "optimize")["seed"]}
        return cls(**{**table, **changes})


@dataclass
class TraceResult:
    document: "SvgDocument"  # the traced SVG (vecfit.svg.document)
    paths: int        # number of shapes written, besides the background rect
    colors: int       # number of distinct fill colours (the background's included)
    segments: int     # their segments (lines and curves; a rect, circle or ellipse counts 4)
    seconds: float
    strokes: int = 0  # of the paths, those drawn as strokes (--style strokes, mixed)
    warnings: list = field(default_factory=list)  # what the trace warned of (VecfitWarning)

    @property
    def svg(self) -> str:
        """The traced SVG as text."""
        return self.document.text()


def check_settings(s: TraceSettings) -> None:
    """Raise VecfitError naming the first setting that makes no sense."""

    def bad(name, why):
        raise VecfitError(f"trace setting {name}={getattr(s, name)!r}: {why}")

    if s.style not in STYLES:
        bad("style", "must be one of " + ", ".join(STYLES))
    for f in fields(s):
        if f.name == "style":
            continue
        v = getattr(s, f.name)
        if isinstance(v, bool) != (f.type in ("bool", bool)):
            bad(f.name, "must be " + ("true or false" if f.type in ("bool", bool) else "a number"))
        if not isinstance(v, numbers.Real) or not math.isfinite(v):
            bad(f.name, "must be a finite number")
    for name in ("colors", "paths", "overlap", "seed"):
        if int(getattr(s, name)) != getattr(s, name):
            bad(name, "must be a whole number")
    if s.colors < 1:
        bad("colors", "must be at least 1")
    if s.paths < 1:
        bad("paths", "must be at least 1")
    if s.min_area < 0:
        bad("min_area", "must not be negative")
    if s.tolerance <= 0:
        bad("tolerance", "must be positive")
    if not 0 < s.corner_angle <= 180:
        bad("corner_angle", "must be in (0, 180] degrees")
    for name in ("blur", "overlap", "smoothing", "lines"):
        if getattr(s, name) < 0:
            bad(name, "must not be negative")
    for name in ("max_stroke", "max_line"):
        if not 0 < getattr(s, name) <= 1:
            bad(name, "must be in (0, 1]")
    if s.seed < 0:
        bad("seed", "must not be negative")
