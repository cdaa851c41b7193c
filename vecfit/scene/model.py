"""The Scene: plain data holding torch tensors.

A Scene is what the SVG reader produces, what the renderer draws and what the optimiser
changes. Every float that a user may want to optimise is a torch tensor; structure
(segment degrees, fill rules, caps, ...) is plain Python. (Within
``arrays.numpy_arrays()`` the floats are NumPy arrays instead, for readers that only
look: vecfit info; the tensors are made by ``arrays``, which imports torch on first use.)

Coordinates: each shape's geometry is in its own user space. ``Shape.transform`` maps it
into the user space of its group, each ``Group.transform`` into its parent's, and
``Scene.view`` maps the root user space to canvas pixels at the native size
``Scene.width`` x ``Scene.height``. All transforms are 3x3 affine matrices (last row
0 0 1).

Colours are straight (not premultiplied) RGBA in [0, 1].
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, Optional, Union

from typing import TYPE_CHECKING

import numpy as np

from . import arrays

if TYPE_CHECKING:
    import torch

LINE, QUADRATIC, CUBIC = 1, 2, 3
# mix-blend-mode and feBlend modes drawn (renderer/filters.py): the separable ones.
BLEND_MODES = frozenset({"normal", "multiply", "screen", "overlay", "darken", "lighten", "color-dodge",
                         "color-burn", "hard-light", "soft-light", "difference", "exclusion"})


def identity() -> torch.Tensor:
    return arrays.identity()


def as_tensor(x, shape=None) -> torch.Tensor:
    t = arrays.floats(x)
    if shape is not None:
        t = t.reshape(shape)
    return t


# ----------------------------------------------------------------------------- paints

@dataclass
class Solid:
    color: torch.Tensor  # [4] straight RGBA


@dataclass
class LinearGradient:
    start: torch.Tensor    # [2] x1, y1
    end: torch.Tensor      # [2] x2, y2
    offsets: torch.Tensor  # [K] stop offsets, non-decreasing in [0, 1]
    colors: torch.Tensor   # [K, 4] stop colours (stop-opacity folded into alpha)
    transform: torch.Tensor = field(default_factory=identity)  # gradientTransform [3, 3]
    units: str = "objectBoundingBox"  # or "userSpaceOnUse"
    source: Any = None     # id of the <linearGradient> element, for write-back


@dataclass
class RadialGradient:
    center: torch.Tensor   # [2] cx, cy
    radius: torch.Tensor   # [] r
    focal: torch.Tensor    # [2] fx, fy (equal to center when not given)
    offsets: torch.Tensor  # [K]
    colors: torch.Tensor   # [K, 4]
    transform: torch.Tensor = field(default_factory=identity)
    units: str = "objectBoundingBox"
    source: Any = None


Paint = Union[Solid, LinearGradient, RadialGradient]


# -------------------------------------------------------------------------- geometry

@dataclass
class Path:
    """Subpaths of line, quadratic and cubic segments, kept as curves.

    ``points`` holds the subpaths one after the other. A subpath of n segments stores its
    start point, then for each segment its control points and end point (``degree``
    points per segment). A closed subpath's last segment ends at the subpath's start
    point, which is not stored again, so an open subpath stores sum(degrees) + 1 points
    and a closed one sum(degrees). SVG's ``Z`` is an explicit line segment back to the
    start (of zero length when the path already returned there).

    ``widths`` (optional, [P], aligned with ``points``): a full stroke width per stored
    point, in the path's own units like ``Shape.stroke_width``; a closed subpath's last
    segment ends with its start point's width, as it ends at that point. When set, it
    replaces ``Shape.stroke_width`` for this path's stroke: along each segment the width
    is a Bézier of the segment's degree over its control points' widths (as diffvg's
    per-point thickness), and caps and joins take their vertex's width. SVG cannot say
    this: the SVG writer writes the mean width (with a warning).
    """
    points: torch.Tensor                 # [P, 2]
    degrees: np.ndarray                  # [G] int: 1 line, 2 quadratic, 3 cubic
    subpaths: list[tuple[int, int, bool]]  # (first segment, segment count, closed)
    widths: Optional[torch.Tensor] = None  # [P] per-point stroke widths, or None

    def subpath_point_ranges(self) -> list[tuple[int, int]]:
        """(first point, point count) of each subpath in ``points``."""
        out, p = [], 0
        for first, count, closed in self.subpaths:
            n = int(self.degrees[first:first + count].sum()) + (0 if closed else 1)
            out.append((p, n))
            p += n
        return out


@dataclass
class Circle:
    center: torch.Tensor  # [2]
    radius: torch.Tensor  # []


@dataclass
class Ellipse:
    center: torch.Tensor  # [2]
    radii: torch.Tensor   # [2] rx, ry


@dataclass
class Rect:
    p_min: torch.Tensor    # [2] x, y
    p_max: torch.Tensor    # [2] x + width, y + height
    corner_radii: torch.Tensor = field(default_factory=lambda: arrays.zeros(2))  # [2] rx, ry


Geometry = Union[Path, Circle, Ellipse, Rect]


# ------------------------------------------------------------------------- effects

@dataclass
class ClipPath:
    """An SVG <clipPath>: what it lets through is the union of its shapes' fills (each
    with its clip-rule as the shape's fill_rule; paints and opacities are ignored), as
    anti-aliased coverage that multiplies the clipped content's.

    ``content`` holds the clip's shapes and groups; its ``view`` is the clipPath's own
    transform, from the clip's space to the user space of the element it clips (with
    ``units`` "objectBoundingBox", first scaled to that element's bounding box). One
    ClipPath object serves every element that references the <clipPath>, so optimising
    its geometry changes them all, as it would in the file."""
    content: "Scene"
    units: str = "userSpaceOnUse"           # or "objectBoundingBox"
    clip: Optional["ClipPath"] = None        # a clip-path on the <clipPath> itself
    source: Any = None                      # the <clipPath> element's id or handle
    viewport: bool = False                  # the reader's own clip of a nested <svg>'s viewport:
                                            # no element of the file, so never optimised


@dataclass
class Mask:
    """An SVG <mask>: the content's luminance (or alpha, ``kind`` "alpha") inside the mask
    region multiplies the masked content's colour and alpha.

    ``content`` is drawn like a group (paints, opacities and all) in the user space of the
    masked element (its ``view`` is the identity), or in its bounding box's unit square
    with ``content_units`` "objectBoundingBox". ``region`` is x, y, width, height in
    ``units`` (by default the bounding box grown by 10% on each side)."""
    content: "Scene"
    kind: str = "luminance"                  # or "alpha"
    units: str = "objectBoundingBox"
    content_units: str = "userSpaceOnUse"
    region: tuple = (-0.1, -0.1, 1.2, 1.2)
    mask: Optional["Mask"] = None             # a mask on the <mask> itself
    source: Any = None


@dataclass
class FilterStep:
    """One filter primitive: ``kind`` is the element's name without "fe" (GaussianBlur,
    Offset, Flood, ColorMatrix, Composite, Merge, Blend, DropShadow). ``inputs`` are
    "SourceGraphic", "SourceAlpha", a named result, or "" for the previous step's result
    (the source graphic for the first). ``region`` is x, y, width, height, each None where
    not given. ``params`` holds the kind's numbers and keywords."""
    kind: str
    inputs: list
    result: str = ""
    params: dict = field(default_factory=dict)
    region: tuple = (None, None, None, None)
    linear_rgb: bool = True                   # color-interpolation-filters


@dataclass
class Filter:
    """An SVG <filter>: steps run on the element's drawn layer (premultiplied RGBA) in
    canvas pixels, within the filter region. Steps of kinds vecfit does not run were left
    out by the reader (with a warning); a filter with none left draws nothing."""
    steps: list
    units: str = "objectBoundingBox"
    primitive_units: str = "userSpaceOnUse"
    region: tuple = (-0.1, -0.1, 1.2, 1.2)
    source: Any = None


# ----------------------------------------------------------------------- structure

@dataclass
class Group:
    """An SVG <g> (or the root <svg>): a transform and an opacity applied to the
    composite of its children (group opacity is a layer, not a per-shape alpha)."""
    transform: torch.Tensor = field(default_factory=identity)  # [3, 3] to parent's space
    opacity: torch.Tensor = field(default_factory=lambda: arrays.scalar(1.0))
    parent: int = -1          # index into Scene.groups, -1 for the root
    source: Any = None        # id (or other handle) of the element, for write-back
    # Effects on the group's layer, in SVG's order: filter, then clip, then mask, then
    # opacity, then the blend onto what is below (renderer/layers.py). The clip and mask
    # are in the group's user space, after its transform.
    clip: Optional[ClipPath] = None
    mask: Optional[Mask] = None
    filter: Optional[Filter] = None
    blend: str = "normal"          # mix-blend-mode: normal, multiply, screen, ...
    isolate: bool = False          # isolation: isolate (its children blend only within it)


@dataclass
class Shape:
    """One drawn element: geometry with an optional fill and an optional stroke.

    ``dash_array`` and ``dash_offset``: the stroke's ``stroke-dasharray`` and
    ``stroke-dashoffset`` in the geometry's own units (like ``stroke_width``), plain floats
    that are not optimised. None, or a pattern SVG draws solid (a negative value, a zero
    sum), strokes without dashes; an odd-length pattern repeats to even length. The stroke
    is then drawn from the dashes of the geometry (vecfit.scene.dashes); the fill is not
    affected."""
    geometry: Geometry
    fill: Optional[Paint] = None
    stroke: Optional[Paint] = None
    stroke_width: torch.Tensor = field(default_factory=lambda: arrays.scalar(1.0))  # unless Path.widths
    fill_rule: str = "nonzero"     # or "evenodd"
    linecap: str = "butt"          # butt | round | square
    linejoin: str = "miter"        # miter | round | bevel
    miter_limit: float = 4.0
    opacity: torch.Tensor = field(default_factory=lambda: arrays.scalar(1.0))
    fill_opacity: torch.Tensor = field(default_factory=lambda: arrays.scalar(1.0))
    stroke_opacity: torch.Tensor = field(default_factory=lambda: arrays.scalar(1.0))
    transform: torch.Tensor = field(default_factory=identity)  # [3, 3] to group's space
    group: int = -1                # index into Scene.groups, -1 for the root
    source: Any = None             # id (or other handle) of the element, for write-back
    # Effects on the shape as a layer of its own (as on a Group), in the shape's user
    # space, after its transform.
    clip: Optional[ClipPath] = None
    mask: Optional[Mask] = None
    filter: Optional[Filter] = None
    blend: str = "normal"          # mix-blend-mode
    dash_array: Optional[tuple[float, ...]] = None  # stroke-dasharray (own units), or None
    dash_offset: float = 0.0       # stroke-dashoffset (own units)


@dataclass
class Scene:
    width: float                   # native canvas size in pixels
    height: float
    shapes: list[Shape] = field(default_factory=list)
    groups: list[Group] = field(default_factory=list)
    view: torch.Tensor = field(default_factory=identity)  # root user space -> pixels
    skipped: dict[str, list[str]] = field(default_factory=dict)  # kind -> element names

    def has_effects(self) -> bool:
        """Whether a shape or group has a clip, a mask, a filter or a blend mode (drawn in
        layers by renderer/layers.py rather than in one pass of the core)."""
        return any(x.clip is not None or x.mask is not None or x.filter is not None or x.blend != "normal"
                   for x in (*self.shapes, *self.groups))

    def effect_contents(self, viewports: bool = True) -> list[tuple["Scene", bool]]:
        """(content, is a clip) of every distinct clip and mask, nested ones included,
        each once (without the viewport clips of nested <svg> elements if not
        ``viewports``)."""
        out, seen = [], set()

        def visit(effect):
            if effect is None or id(effect) in seen or (not viewports and getattr(effect, "viewport", False)):
                return
            seen.add(id(effect))
            out.append((effect.content, isinstance(effect, ClipPath)))
            visit(getattr(effect, "clip", None))
            visit(getattr(effect, "mask", None))
            for x in (*effect.content.shapes, *effect.content.groups):
                visit(x.clip)
                visit(x.mask)

        for x in (*self.shapes, *self.groups):
            visit(x.clip)
            visit(x.mask)
        return out

    def detached_copy(self) -> "Scene":
        """A copy whose tensors are detached clones (shared tensors stay shared): the
        Scene's values at this moment, kept apart from later changes."""
        return _copied(self, {})

    def parameters(self, _nested: bool = True) -> dict[str, list[torch.Tensor]]:
        """Every optimisable tensor, grouped by parameter kind (those of clips and masks
        included)."""
        kinds: dict[str, list[torch.Tensor]] = {
            "points": [], "radii": [], "colors": [], "stroke_widths": [],
            "opacities": [], "gradient_points": [], "gradient_radii": [],
            "stop_offsets": [], "transforms": [],
        }
        seen: set[int] = set()

        def add(kind, t):
            if id(t) not in seen:
                seen.add(id(t))
                kinds[kind].append(t)

        def add_paint(paint):
            if isinstance(paint, Solid):
                add("colors", paint.color)
            elif isinstance(paint, (LinearGradient, RadialGradient)):
                if isinstance(paint, LinearGradient):
                    add("gradient_points", paint.start)
                    add("gradient_points", paint.end)
                else:
                    add("gradient_points", paint.center)
                    add("gradient_points", paint.focal)
                    add("gradient_radii", paint.radius)
                add("stop_offsets", paint.offsets)
                add("colors", paint.colors)
                add("transforms", paint.transform)

        for shape in self.shapes:
            g = shape.geometry
            if isinstance(g, Path):
                add("points", g.points)
                if shape.stroke is not None and g.widths is not None:
                    add("stroke_widths", g.widths)  # per point: replaces stroke_width
            elif isinstance(g, Circle):
                add("points", g.center)
                add("radii", g.radius)
            elif isinstance(g, Ellipse):
                add("points", g.center)
                add("radii", g.radii)
            elif isinstance(g, Rect):
                add("points", g.p_min)
                add("points", g.p_max)
                add("radii", g.corner_radii)
            add_paint(shape.fill)
            add_paint(shape.stroke)
            if shape.stroke is not None and not (isinstance(g, Path) and g.widths is not None):
                add("stroke_widths", shape.stroke_width)
            add("opacities", shape.opacity)
            add("opacities", shape.fill_opacity)
            add("opacities", shape.stroke_opacity)
            add("transforms", shape.transform)
        for group in self.groups:
            add("opacities", group.opacity)
            add("transforms", group.transform)
        # What clips and masks draw is optimised with the rest (a clip's paints and
        # opacities do not show, so only its geometry and transforms are offered).
        for content, clip_only in (self.effect_contents(viewports=False) if _nested else ()):
            for kind, tensors in content.parameters(_nested=False).items():
                if clip_only and kind not in ("points", "radii", "transforms"):
                    continue
                for t in tensors:
                    add(kind, t)
        return kinds


def _copied(value, memo: dict):
    """``value`` with every tensor and array cloned once (by identity, through ``memo``,
    so that what is shared stays shared). Dataclasses are copied shallowly and their
    fields that hold data replaced (a generic field-by-field rebuild took a third of
    reading a 3,000-path SVG)."""
    key = id(value)
    if key in memo:
        return memo[key]
    if arrays.is_tensor(value):
        out = value.detach().clone()
    elif isinstance(value, np.ndarray):
        out = value.copy()
    elif isinstance(value, list):
        return [_copied(v, memo) for v in value]
    elif isinstance(value, dict):
        return {k: _copied(v, memo) for k, v in value.items()}
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        out = object.__new__(type(value))
        fields = dict(value.__dict__)
        for k, v in fields.items():
            if v is not None and not isinstance(v, _PLAIN):
                fields[k] = _copied(v, memo)
        out.__dict__ = fields
    else:
        return value  # numbers, strings, tuples of them
    memo[key] = out
    return out


_PLAIN = (str, int, float, bool, tuple)
