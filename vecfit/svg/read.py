"""SVG file -> Scene.

The reader walks the XML element tree itself: svgelements (used here for transform lists)
loses gradients, group opacity and nested viewports, and we need to know which element
each shape and group came from. Styles cascade and inherit as in ``style.py``; paints and
gradients are resolved in ``paint.py``; geometry is built in ``shapes.py``.

Structure kept: every <g> (and <a>), every <use> and nested <svg> becomes a Group, in
document order, with its own transform and opacity; shapes keep their own transform
and opacity. The root <svg> becomes a Group only when it has an opacity or a transform.
Shapes and groups are kept even when they draw nothing (no fill and no stroke), so that
the Scene has one shape per drawable element; ``source`` is the element's id, or its
position "/i/j/k" in the document when it has no unique id.
"""
from __future__ import annotations

import math
import re

import numpy as np

from vecfit import limits
from vecfit.errors import SvgError
from vecfit.scene import BLEND_MODES, ClipPath, Filter, Group, Mask, Path, Rect, Scene, Shape, arrays
from vecfit.scene.dashes import DashBudget, dash_pattern, outline_path

from .effects import func_iri, parse_filter, region, units_of
from .paints import BLACK, Paints, parse_opacity, parse_paint, solid
from .color import parse_color
from .document import SvgDocument
from .dom import href_id, is_svg, local_name
from .loops import looping_references
from .shapes import Limiter, ShapeReader
from .skips import Skips, VecfitWarning
from .units import (parse_length, parse_number, parse_transform, parse_viewbox, translate,
                    view_transform)

__all__ = ["load_svg", "read_svg", "scene_of", "VecfitWarning"]

SHAPES = frozenset({"rect", "circle", "ellipse", "line", "polyline", "polygon", "path"})
CONTAINERS = frozenset({"g", "a"})
# Elements that are never drawn where they stand (referenced, metadata, or styling).
NOT_DRAWN = frozenset({
    "defs", "style", "title", "desc", "metadata", "script", "symbol", "linearGradient",
    "radialGradient", "stop", "clipPath", "mask", "pattern", "marker", "filter", "view",
    "cursor", "font", "font-face", "color-profile",
})
CAPS = ("butt", "round", "square")
JOINS = {"miter": "miter", "miter-clip": "miter", "arcs": "miter", "round": "round",
         "bevel": "bevel"}
DEFAULT_SIZE = 100.0  # resvg's size for a root with neither width/height nor viewBox
# Elements, counting what entities and <use> instances expand to: a guard against
# reference and entity bombs (uses of groups of uses ..., entities of entities) that would
# take hours and all memory. (Module-level names so that tests can lower them.)
MAX_ELEMENTS = limits.MAX_ELEMENTS
MAX_SEGMENTS = limits.MAX_SEGMENTS
MAX_NESTING = limits.MAX_NESTING
MAX_EFFECT_NESTING = limits.MAX_EFFECT_NESTING


def load_svg(path) -> Scene:
    """Read the SVG file at ``path`` into a Scene.

    Raises SvgError for a file that cannot be read as SVG. What is not supported is left
    out (or drawn approximately) with one VecfitWarning per kind, and listed in
    ``scene.skipped``. An SVG without drawable shapes gives an empty Scene. (To write the
    Scene back, read it with ``read_svg``, which also keeps the document.)
    """
    return scene_of(SvgDocument.read(path), for_writing=False)


def read_svg(path) -> tuple[Scene, SvgDocument]:
    """The SVG file at ``path`` as a Scene and the document it was read from (to write the
    Scene back into with ``write_svg``); see ``load_svg``."""
    document = SvgDocument.read(path)
    return scene_of(document), document


def scene_of(document: SvgDocument, for_writing: bool = True) -> Scene:
    """The Scene that ``document`` draws. ``for_writing``: records on the document what the
    writer needs (the Scene as read, a copy of every tensor, and the viewport); rendering
    alone (load_svg) does without that copy."""
    reader = Reader(document)
    try:
        scene = reader.read()
    except RecursionError:
        raise SvgError(document.name, f"elements nested too deeply (at most {MAX_NESTING} levels)") from None
    reader.skips.warn(document.name)
    if for_writing:
        document.original = scene.detached_copy()
        document.viewport = reader.viewport
    return scene


def _name(element) -> str:
    """How messages name an element: its id, else its tag."""
    return element.get("id") or local_name(element.tag)


def _singular(m: np.ndarray | None) -> bool:
    return m is not None and abs(m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]) == 0


class Reader:
    def __init__(self, document: SvgDocument):
        self.document = document
        self.path = document.name
        self.root = document.root
        self.skips = Skips()
        self.ids = document.ids
        self._elements = 0  # elements walked so far, <use> instances included
        self._segments = 0
        self._dash_budget = DashBudget()  # the scene's dashes (limits.MAX_DASHES)
        elements = sum(1 for e in self.root.iter() if isinstance(e.tag, str))
        if elements > MAX_ELEMENTS:  # entity expansion can make millions from a small file
            self._too_many_elements()
        for selector in document.sheet.unsupported:
            self.skips.add("css-selector", selector)
        self.cascade = document.cascade
        self.width, self.height, self.view, self.viewport = self._root_size()
        self.paints = Paints(self.ids, document.computed, self.viewport, self.skips.add)
        self.shapes: list[Shape] = []
        self.groups: list[Group] = []
        # Clip paths, masks and filters read so far (by element: one object per element,
        # shared by every reference), those being read (a reference to one of them is a
        # loop), and whether a clip path's content is being read.
        self._effects: dict[tuple[str, int], object] = {}
        self._reading: tuple[int, ...] = ()
        self._in_clip = False
        self._loops = looping_references(self.root, self.ids, document.computed)

    # --------------------------------------------------------------- document

    def _root_size(self):
        """(width, height) in px, the view matrix, and the viewport size that user-space
        percentages refer to."""
        root = self.root
        vb = parse_viewbox(root.get("viewBox"))
        if vb is not None and not all(math.isfinite(v) for v in vb):
            raise SvgError(self.path, f"invalid viewBox {root.get('viewBox')!r} (not finite)")
        if vb is not None and (vb[2] <= 0 or vb[3] <= 0):
            raise SvgError(self.path, f"invalid viewBox {root.get('viewBox')!r} (zero or negative size)")
        # Percentages (the default 100%) have no outer viewport to refer to: as not given.
        w = parse_length(root.get("width"))
        h = parse_length(root.get("height"))
        for name, value in (("width", w), ("height", h)):
            if value is not None and not (0 < value < math.inf):
                raise SvgError(self.path, f"invalid root {name} {root.get(name)!r}")
        if w is None and h is None:
            w, h = (vb[2], vb[3]) if vb else (DEFAULT_SIZE, DEFAULT_SIZE)
        elif w is None:
            w = h * vb[2] / vb[3] if vb else DEFAULT_SIZE
        elif h is None:
            h = w * vb[3] / vb[2] if vb else DEFAULT_SIZE
        if not (limits.MIN_CANVAS <= w <= limits.MAX_CANVAS and limits.MIN_CANVAS <= h <= limits.MAX_CANVAS):
            raise SvgError(self.path, f"the canvas is {w:g} x {h:g} px; each side must be between "
                                      f"{limits.MIN_CANVAS:g} and {limits.MAX_CANVAS:g} px")
        view = view_transform(vb, w, h, root.get("preserveAspectRatio")) if vb else np.eye(3)
        viewport = (vb[2], vb[3]) if vb else (w, h)
        return float(w), float(h), view, viewport

    def _too_many_elements(self):
        raise SvgError(self.path, f"the SVG expands to more than {MAX_ELEMENTS} elements "
                                  f"(entities or <use> references; the limit is {MAX_ELEMENTS})")

    def read(self) -> Scene:
        style = self.cascade.computed(self.root, None)
        group = -1
        if (style.get("display") or "").strip() != "none":
            transform = parse_transform(self.root.get("transform"))
            opacity = parse_opacity(style.get("opacity"))
            if not _singular(transform):
                effects = self._layer_effects(self.root, style)
                if opacity < 1 or transform is not None or effects != NO_EFFECTS:
                    group = self._group(transform, opacity, -1, self.root, effects)
                self._children(self.root, style, group, ())
        lim = Limiter()
        view = lim.tensor(self.view)
        if lim.clamped:
            self.skips.add("out-of-range numbers", _name(self.root))
        return Scene(width=self.width, height=self.height, shapes=self.shapes, groups=self.groups,
                     view=view, skipped=self.skips.as_dict())

    # ------------------------------------------------------------------- walk

    def _children(self, element, style, group, stack, depth=0):
        if depth >= MAX_NESTING:
            raise SvgError(self.path, f"elements nested too deeply (at most {MAX_NESTING} levels)")
        for child in element:
            self._element(child, style, group, stack, depth + 1)

    def _element(self, element, parent_style, group, stack, depth=0):
        if not is_svg(element):
            return  # comments, and other namespaces (editor metadata)
        tag = local_name(element.tag)
        if tag in NOT_DRAWN:
            return
        self._elements += 1
        if self._elements > MAX_ELEMENTS:
            self._too_many_elements()
        if tag not in SHAPES and tag not in CONTAINERS and tag not in ("use", "svg", "switch"):
            self.skips.add(tag, _name(element))  # text, image, foreignObject, unknown, ...
            return
        style = self.cascade.computed(element, parent_style)
        if (style.get("display") or "").strip() == "none":
            return
        transform = parse_transform(element.get("transform"))
        if _singular(transform):
            return  # SVG: a non-invertible transform draws nothing
        if self._in_clip and tag not in SHAPES and tag != "use":
            return  # a clip path draws only shapes, directly or through <use>
        effects = self._layer_effects(element, style)
        if tag in CONTAINERS:
            g = self._group(transform, parse_opacity(style.get("opacity")), group, element, effects)
            self._children(element, style, g, stack, depth)
        elif tag == "switch":
            g = self._group(transform, parse_opacity(style.get("opacity")), group, element, effects)
            child = _switch_choice(element)
            if child is not None:
                self._element(child, style, g, stack, depth + 1)
        elif tag == "use":
            self._use(element, style, transform, group, stack, depth, effects)
        elif tag == "svg":
            self._nested_svg(element, element, style, transform, group, stack, depth, effects)
        else:
            self._shape(tag, element, style, transform, group, effects)

    # ---------------------------------------------------- clip paths, masks, filters

    def _layer_effects(self, element, style) -> tuple:
        """(clip, mask, filter, blend mode, isolated) of an element. A reference that leads
        nowhere (or back to the clip path or mask being read) is left out with a warning,
        as resvg does; a filter reference that leads nowhere gives a filter without steps:
        SVG draws the element as nothing."""
        name = _name(element)
        clip = self._reference(style, "clip-path", "clipPath", name, self._clip_path, element)
        if self._in_clip:
            return clip, None, None, "normal", False  # a clip path's shapes take none of the rest
        blend = (style.get("mix-blend-mode") or "normal").strip()
        if blend not in BLEND_MODES:
            self.skips.add("mix-blend-mode", f"{name} ({blend[:20]})")
            blend = "normal"
        isolate = (style.get("isolation") or "").strip() == "isolate"
        mask = self._reference(style, "mask", "mask", name, self._mask, element)
        value = (style.get("filter") or "none").strip()
        filt = None
        if value != "none":
            ref = func_iri(value)
            target = self.ids.get(ref) if ref else None
            if ref is None:
                self.skips.add("filter", f"{name} ({value[:40]})")
            elif target is None or local_name(target.tag) != "filter":
                self.skips.add("filter reference", f"{name} (no <filter> #{ref})")
                filt = _NO_FILTER
            else:
                key = ("filter", id(target))
                if key not in self._effects:
                    self._effects[key] = parse_filter(target, self.ids, self.document.computed, self.viewport,
                                                      self.skips.add, name)
                filt = self._effects[key]
        return clip, mask, filt, blend, isolate

    def _reference(self, style, prop: str, tag: str, name: str, build, element=None):
        value = (style.get(prop) or "none").strip()
        if value == "none":
            return None
        if element is not None and (id(element), prop) in self._loops:
            self.skips.add(prop, f"{name} ({value[:40]} leads back to itself)")
            return None
        ref = func_iri(value)
        if ref is None:
            self.skips.add(prop, f"{name} ({value[:40]})")  # CSS shapes and other forms
            return None
        target = self.ids.get(ref)
        if target is None or not is_svg(target) or local_name(target.tag) != tag:
            self.skips.add(prop, f"{name} (no <{tag}> #{ref})")
            return None
        if id(target) in self._reading:
            self.skips.add(prop, f"{name} (#{ref} refers back to itself)")
            return None
        if len(self._reading) >= MAX_EFFECT_NESTING:
            self.skips.add(prop, f"{name} (nested more than {MAX_EFFECT_NESTING} deep)")
            return None
        key = (tag, id(target))
        if key not in self._effects:
            self._reading += (id(target),)
            try:
                self._effects[key] = build(target)
            finally:
                self._reading = self._reading[:-1]
        return self._effects[key]

    def _content(self, element, clip: bool) -> Scene:
        """What a <clipPath> or <mask> draws, as a Scene of its own (in the user space of
        the element that references it)."""
        saved = self.shapes, self.groups, self._in_clip
        self.shapes, self.groups, self._in_clip = [], [], clip
        try:
            self._children(element, self.document.computed(element), -1, ())
            return Scene(width=self.width, height=self.height, shapes=self.shapes, groups=self.groups)
        finally:
            self.shapes, self.groups, self._in_clip = saved

    def _clip_path(self, element) -> ClipPath:
        transform = parse_transform(element.get("transform"))
        content = self._content(element, clip=True)
        if _singular(transform):
            content.shapes, content.groups = [], []  # draws nothing: lets nothing through
        elif transform is not None:
            content.view = arrays.floats(transform)
        clip = ClipPath(content=content, units=units_of(element, "clipPathUnits", "userSpaceOnUse"),
                        source=self.document.handle_of(element))
        clip.clip = self._reference(self.document.computed(element), "clip-path", "clipPath", _name(element),
                                    self._clip_path, element)
        return clip

    def _mask(self, element) -> Mask:
        style = self.document.computed(element)
        units = units_of(element, "maskUnits", "objectBoundingBox")
        kind = "alpha" if (style.get("mask-type") or "").strip() == "alpha" else "luminance"
        mask = Mask(content=self._content(element, clip=False), kind=kind, units=units,
                    content_units=units_of(element, "maskContentUnits", "userSpaceOnUse"),
                    region=region(element, units, self.viewport), source=self.document.handle_of(element))
        mask.mask = self._reference(style, "mask", "mask", _name(element), self._mask, element)
        return mask

    def _viewport_clip(self, width: float, height: float, inverse_view) -> ClipPath:
        """The clip of a nested <svg> or <symbol> instance to its viewport (overflow
        hidden): a rect 0, 0, width, height before the viewBox's mapping."""
        lim = Limiter()  # (a viewport of 1e400 px, a viewBox of 1e-300: clamped, as numbers are)
        rect = Shape(geometry=Rect(p_min=arrays.zeros(2), p_max=lim.tensor(np.array([width, height]))),
                     fill=solid(BLACK))
        view = arrays.identity() if inverse_view is None else lim.tensor(np.asarray(inverse_view))
        return ClipPath(content=Scene(width=self.width, height=self.height, shapes=[rect], view=view), viewport=True)

    def _group(self, transform, opacity, parent, element, effects=None) -> int:
        lim = Limiter()
        m = arrays.identity() if transform is None else lim.tensor(transform)
        if lim.clamped:
            self.skips.add("out-of-range numbers", _name(element))
        if self._in_clip:
            opacity = 1.0  # a clip path's content has no opacity
        clip, mask, filt, blend, isolate = effects or NO_EFFECTS
        self.groups.append(Group(transform=m, opacity=arrays.scalar(opacity), parent=parent,
                                 source=self.document.handle_of(element), clip=clip, mask=mask, filter=filt,
                                 blend=blend, isolate=isolate))
        return len(self.groups) - 1

    # ------------------------------------------------------------- references

    def _use(self, element, style, transform, group, stack, depth, effects):
        name = _name(element)
        ref = href_id(element)
        target = self.ids.get(ref) if ref else None
        if target is None or not is_svg(target):
            self.skips.add("use", f"{name} (no element #{ref})" if ref else f"{name} (no local href)")
            return
        if id(target) in stack or any(e is element for e in target.iter()):
            self.skips.add("use", f"{name} (recursive)")
            return
        if self._in_clip and local_name(target.tag) not in SHAPES:
            return  # in a clip path, a <use> draws a shape or nothing
        x = parse_length(element.get("x"), self.viewport[0]) or 0.0
        y = parse_length(element.get("y"), self.viewport[1]) or 0.0
        m = (transform if transform is not None else np.eye(3)) @ translate(x, y)
        g = self._group(m, parse_opacity(style.get("opacity")), group, element, effects)
        stack = stack + (id(target),)
        tag = local_name(target.tag)
        if tag in ("symbol", "svg"):
            # The use's width and height, when given, set the viewport of the instance.
            target_style = self.cascade.computed(target, style)
            if (target_style.get("display") or "").strip() != "none":
                self._nested_svg(target, element, target_style, None, g, stack, depth + 1)
        else:
            self._element(target, style, g, stack, depth + 1)

    def _nested_svg(self, element, sizer, style, transform, group, stack, depth, effects=None):
        """A nested <svg> or an instanced <symbol>: a group mapping its viewBox onto its
        viewport (width and height from ``sizer``, the element or the <use>)."""
        vw, vh = self.viewport
        tag = local_name(element.tag)
        x = 0.0 if tag == "symbol" else parse_length(element.get("x"), vw) or 0.0
        y = 0.0 if tag == "symbol" else parse_length(element.get("y"), vh) or 0.0
        w = parse_length(sizer.get("width") or element.get("width") or "100%", vw)
        h = parse_length(sizer.get("height") or element.get("height") or "100%", vh)
        if w is None or h is None or w <= 0 or h <= 0:
            return
        m = (transform if transform is not None else np.eye(3)) @ translate(x, y)
        vb = parse_viewbox(element.get("viewBox"))
        inverse_view = None
        if vb is not None:
            if vb[2] <= 0 or vb[3] <= 0:
                return
            view = view_transform(vb, w, h, element.get("preserveAspectRatio"))
            if not np.isfinite(view).all() or _singular(view):
                return  # (a viewBox of inf or 1e-300: as a non-invertible transform, nothing)
            m = m @ view
            inverse_view = np.linalg.inv(view)
        clip, mask, filt, blend, isolate = effects or NO_EFFECTS
        if (style.get("overflow") or "hidden").strip() in ("hidden", "scroll") and not self._in_clip:
            viewport = self._viewport_clip(w, h, inverse_view)
            viewport.clip, clip = clip, viewport
        g = self._group(m, parse_opacity(style.get("opacity")), group, element, (clip, mask, filt, blend, isolate))
        self._children(element, style, g, stack, depth)

    # ----------------------------------------------------------------- shapes

    def _shape(self, tag, element, style, transform, group, effects=None):
        name = _name(element)
        lim = Limiter()
        reader = ShapeReader(self.viewport, lim, max_segments=MAX_SEGMENTS - self._segments)
        geometry = reader.build(tag, element)
        self._segments += reader.segments
        if reader.too_many_segments or self._segments > MAX_SEGMENTS:
            raise SvgError(self.path, f"more than {MAX_SEGMENTS} path segments (the limit)")
        if reader.problem:
            self.skips.add(reader.problem, name)
        if geometry is None or (style.get("visibility") or "").strip() in ("hidden", "collapse"):
            return
        current = parse_color(style.get("color")) or BLACK
        fill = self._paint(style, "fill", "black", current, name)
        stroke = self._paint(style, "stroke", "none", current, name)
        width = parse_length(style.get("stroke-width"), self._diagonal())
        width = 1.0 if width is None else width
        if width <= 0:
            stroke = None  # SVG: zero or negative width draws no stroke
        rule_property = "fill-rule"
        if self._in_clip:  # a clip path's shapes are filled, opaque, with their clip-rule
            fill, stroke, rule_property = solid(BLACK), None, "clip-rule"
            style = {k: v for k, v in style.items() if k not in ("opacity", "fill-opacity")}
        # A shape with neither paint is kept: it draws nothing, but the Scene stays one
        # shape per drawable element (counts, write-back).
        self._note_shape_effects(tag, style, name, stroked=stroke is not None)
        dash_array, dash_offset = self._dashes(style, geometry, width, name) if stroke is not None else (None, 0.0)
        shape = Shape(
            geometry=geometry, fill=fill, stroke=stroke,
            stroke_width=lim.tensor(width),
            fill_rule="evenodd" if (style.get(rule_property) or "").strip() == "evenodd" else "nonzero",
            linecap=_choice(style.get("stroke-linecap"), CAPS, "butt"),
            linejoin=JOINS.get((style.get("stroke-linejoin") or "").strip(), "miter"),
            miter_limit=_miter_limit(style.get("stroke-miterlimit")),
            opacity=arrays.scalar(parse_opacity(style.get("opacity"))),
            fill_opacity=arrays.scalar(parse_opacity(style.get("fill-opacity"))),
            stroke_opacity=arrays.scalar(parse_opacity(style.get("stroke-opacity"))),
            transform=arrays.identity() if transform is None else lim.tensor(transform),
            group=group, source=self.document.handle_of(element),
            dash_array=dash_array, dash_offset=dash_offset,
            **dict(zip(("clip", "mask", "filter", "blend"), (effects or NO_EFFECTS)[:4])))
        if lim.clamped:
            self.skips.add("out-of-range numbers", name)
        self.shapes.append(shape)

    def _paint(self, style, prop, default, current, name):
        text = style.get(prop)
        value = parse_paint(text) if text is not None else None
        if value is None:  # missing or invalid: the property's initial value
            value = parse_paint(default)
        return self.paints.resolve(value, current, name)

    def _dashes(self, style, geometry, width, name) -> tuple[tuple[float, ...] | None, float]:
        """stroke-dasharray (lengths, percentages of the diagonal; an invalid list or one SVG
        draws solid: None) and stroke-dashoffset, in user units. A pattern that would take
        the scene past limits.MAX_DASHES dashes (DashBudget) is noted and drawn solid."""
        items = re.split(r"\s*,\s*|\s+", (style.get("stroke-dasharray") or "none").strip())
        diagonal, values = self._diagonal(), []
        for item in items:
            values.append(parse_length(item, diagonal))
            if values[-1] is None:
                break  # the list is invalid: the rest need not be read
        if items == ["none"] or any(v is None for v in values) or (pattern := dash_pattern(values)) is None:
            return None, 0.0
        offset = parse_length(style.get("stroke-dashoffset"), self._diagonal())
        # (rects and ellipses become paths in torch: a NumPy reading imports it here)
        outline = outline_path(arrays.as_torch(geometry) if arrays.making_numpy() and not isinstance(geometry, Path)
                               else geometry)
        if outline is not None and not self._dash_budget.take(outline, pattern, width):
            self.skips.add("stroke-dasharray", name)
            return None, 0.0
        return pattern, offset if offset is not None and math.isfinite(offset) else 0.0

    def _note_shape_effects(self, tag, style, name, stroked):
        if tag in ("path", "line", "polyline", "polygon") and any(
                (style.get(f"marker-{k}") or "none").strip() != "none" for k in ("start", "mid", "end")):
            self.skips.add("marker", name)

    def _diagonal(self) -> float:
        vw, vh = self.viewport
        return math.sqrt((vw * vw + vh * vh) / 2)


# (clip, mask, filter, blend mode, isolated) of an element without them.
NO_EFFECTS = (None, None, None, "normal", False)
# A filter reference that leads nowhere: SVG (and resvg) then draws the element as nothing.
_NO_FILTER = Filter(steps=[])


def _choice(text, allowed, default):
    value = (text or "").strip()
    return value if value in allowed else default


def _miter_limit(text) -> float:
    value = parse_number(text)
    return value if value is not None and 1 <= value < math.inf else 4.0


def _switch_choice(element):
    """The child a <switch> draws: the first SVG element whose conditions hold (no
    required extensions; systemLanguage, if given, includes English). foreignObject,
    which vecfit cannot draw, is passed over for the SVG fallback that follows it."""
    for child in element:
        if not is_svg(child) or local_name(child.tag) == "foreignObject":
            continue
        if (child.get("requiredExtensions") or "").strip():
            continue
        languages = child.get("systemLanguage")
        if languages is not None and not any(
                lang.strip().lower().split("-")[0] == "en" for lang in languages.split(",")):
            continue
        return child
    return None
