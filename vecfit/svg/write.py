"""Scene -> SVG: write a Scene's current values back into a copy of its SvgDocument.

Each Shape's and Group's element is found by its ``source`` handle (the document's
handle map, the one the reader named them by), and what the Scene models is written
into that element; everything else (ids, classes, unknown attributes, unsupported
content, comments) stays as it was.

By default only values that differ from the Scene as it was read are written, so an
unchanged Scene reproduces the document's content (re-serialised by ElementTree);
``full=True`` writes every modelled value (useful to check the writer).

Style precedence: a property that the element's ``style`` attribute or a matching CSS
rule sets is written into the ``style`` attribute (merged with what is there), anything
else as a presentation attribute.
"""
from __future__ import annotations

import gzip
import warnings
import xml.etree.ElementTree as ET

import numpy as np

from vecfit.errors import VecfitError
from vecfit.io.files import atomic_write_bytes
from vecfit.scene.arrays import to_numpy
from vecfit.scene import (Circle, Ellipse, LinearGradient, Path, RadialGradient, Rect,
                                   Scene, Solid)

from .paints import GRADIENTS
from .document import SvgDocument
from .dom import local_name
from .numbers import finite, fmt, hex_color, matrix
from .pathdata import format_relative_path_data
from .precision import MAX_DECIMALS, root_decimals, shape_decimals
from .skips import VecfitWarning
from .style import INHERITED
from .units import parse_length, parse_viewbox, translate

__all__ = ["svg_bytes", "write_bytes", "write_svg"]

# Initial values of the properties written here (used to decide whether a property can be
# dropped instead of written).
INITIAL = {"opacity": "1", "fill-opacity": "1", "stroke-opacity": "1", "stop-opacity": "1",
           "fill": "black", "stroke": "none", "stroke-width": "1"}
OPACITY_DECIMALS = 3
# The id of a background rect vecfit writes (here, and as the tracer's backdrop): it is the
# page, not a shape of the drawing (stats.py counts it apart, as trace's budget does).
BACKGROUND_ID = "vecfit-background"


def path_data(path: Path, decimals: int = 4) -> str:
    """A Scene path's ``d``: relative m/l/h/v/q/c/z after an absolute M per subpath (see
    ``pathdata.format_relative_path_data``)."""
    return format_relative_path_data(finite(path.points), path.degrees, path.subpaths, decimals)


def opacity_text(value) -> str | None:
    """An opacity as written: 3 decimals at most (a thousandth is below what 8-bit colour
    shows), None where it rounds to 1 (opaque: nothing to write)."""
    v = min(max(float(finite(value)), 0.0), 1.0)
    text = fmt(v, OPACITY_DECIMALS)
    return None if text == "1" else text[1:] if text.startswith("0.") else text  # .5, as path data


# ---------------------------------------------------------------------- comparison

def _same(a, b) -> bool:
    if a is None or b is None:
        return a is b
    return a.shape == b.shape and np.array_equal(to_numpy(a), to_numpy(b))  # tensors or NumPy


def _same_geometry(a, b) -> bool:
    if type(a) is not type(b):
        return False
    if isinstance(a, Path):
        return (_same(a.points, b.points) and np.array_equal(a.degrees, b.degrees)
                and list(a.subpaths) == list(b.subpaths))
    if isinstance(a, Circle):
        return _same(a.center, b.center) and _same(a.radius, b.radius)
    if isinstance(a, Ellipse):
        return _same(a.center, b.center) and _same(a.radii, b.radii)
    return (_same(a.p_min, b.p_min) and _same(a.p_max, b.p_max)
            and _same(a.corner_radii, b.corner_radii))


def _same_paint_ref(a, b) -> bool:
    """The same kind of paint (and colour, or gradient element)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, Solid):
        return _same(a.color, b.color)
    if isinstance(a, (LinearGradient, RadialGradient)):
        return a.source == b.source
    return True


def _same_gradient(a, b) -> bool:
    if type(a) is not type(b):
        return False
    common = (_same(a.offsets, b.offsets) and _same(a.colors, b.colors)
              and _same(a.transform, b.transform) and a.units == b.units)
    if isinstance(a, LinearGradient):
        return common and _same(a.start, b.start) and _same(a.end, b.end)
    return (common and _same(a.center, b.center) and _same(a.radius, b.radius)
            and _same(a.focal, b.focal))


# ------------------------------------------------------------------------ styles

def _split_style(text: str | None) -> list[list[str]]:
    """style attribute -> [[name, value]] (raw, in order)."""
    out = []
    for item in (text or "").split(";"):
        name, sep, value = item.partition(":")
        if sep and name.strip():
            out.append([name.strip(), value.strip()])
    return out


class _Styles:
    """Properties written so that they compute to the wanted value in ``doc``."""

    def __init__(self, doc: SvgDocument):
        self.doc = doc
        self.cascade = doc.cascade
        self.parents = doc.parents
        self.computed = doc.computed

    def set_property(self, element, name: str, value: str | None):
        """Make ``name`` compute to ``value`` on ``element``; None: its initial value, by
        removing the element's own declarations where that suffices."""
        decls = _split_style(element.get("style"))
        in_style = any(n.lower() == name for n, _ in decls)
        normal, important = self.cascade.sheet.declarations_for(element, local_name(element.tag))
        from_css = any(n == name for n, _ in normal + important)
        if any(n == name for n, _ in important):
            warnings.warn(f"{name} of {element.get('id') or local_name(element.tag)} is set by "
                          f"an !important CSS rule: the written value may not apply",
                          stacklevel=3)
        if value is None:
            parent = self.parents.get(id(element))
            inherited = (name in INHERITED and parent is not None
                         and self.computed(parent).get(name) not in (None, INITIAL.get(name)))
            if not (from_css or inherited):
                if in_style:
                    self._set_style(element, [d for d in decls if d[0].lower() != name])
                element.attrib.pop(name, None)
                return
            value = INITIAL[name]
        if in_style or from_css:
            if in_style:
                for d in decls:
                    if d[0].lower() == name:
                        d[1] = value
            else:
                decls.append([name, value])
            self._set_style(element, decls)
            if name in element.attrib:
                element.set(name, value)  # kept consistent, though the style wins
        else:
            element.set(name, value)

    @staticmethod
    def _set_style(element, decls):
        if decls:
            element.set("style", ";".join(f"{n}:{v}" for n, v in decls))
        else:
            element.attrib.pop("style", None)


# -------------------------------------------------------------------------- writer

def write_svg(scene: Scene, document, out_path, *, full: bool = False, background=None,
              canvas: tuple[float, float] | None = None, precision: int | None = None,
              pixels: tuple[int, int] | None = None) -> None:
    """Write ``scene``'s values into a copy of ``document`` (the SvgDocument the scene was
    read from, or the path of its file) and save it atomically at ``out_path``.

    background: an RGB(A) colour to put behind everything as a first ``<rect>`` covering
    the viewBox (for scenes optimised over a background they do not cover themselves).

    canvas: a new (width, height) in pixels for the root element (`vecfit retarget`); its
    viewBox is resized with it, so a user unit keeps its size in pixels.

    precision: decimals of the coordinates written; None: what a ``pixels`` (width,
    height) canvas needs (vecfit/svg/precision.py; default the Scene's own size).

    Raises VecfitError for non-finite values (nothing is written then) or a scene that
    does not match the document.
    """
    write_bytes(out_path, svg_bytes(scene, document, full=full, background=background, canvas=canvas,
                                    precision=precision, pixels=pixels))


def write_bytes(out_path, payload: bytes) -> None:
    """SVG bytes (svg_bytes) saved atomically at ``out_path``, gzip-compressed for .svgz."""
    if str(out_path).endswith(".svgz"):
        payload = gzip.compress(payload)
    atomic_write_bytes(out_path, payload)


def svg_bytes(scene: Scene, document, *, full: bool = False, background=None,
              canvas: tuple[float, float] | None = None, precision: int | None = None,
              pixels: tuple[int, int] | None = None) -> bytes:
    """What ``write_svg`` writes, as UTF-8 bytes."""
    from .read import read_svg, scene_of  # the reader records the Scene as read

    for tensors in scene.parameters().values():
        for t in tensors:
            finite(t)
    if not isinstance(document, SvgDocument):
        document = read_svg(document)[1]
    elif document.original is None:
        scene_of(document)
    original = document.original
    shapes, groups = _written(scene)
    shapes_before, groups_before = _written(original)
    if (len(shapes_before) != len(shapes) or len(groups_before) != len(groups)
            or any(a.source != b.source for a, b in zip(shapes_before, shapes))
            or any(a.source != b.source for a, b in zip(groups_before, groups))):
        raise VecfitError(f"{document.name}: the scene was not read from this file "
                          f"(its shapes and groups do not match)")

    if precision is not None and not 0 <= int(precision) <= MAX_DECIMALS:
        raise VecfitError(f"precision must be 0 to {MAX_DECIMALS} decimals, not {precision}")
    decimals = shape_decimals(scene, pixels, precision)
    decimals += [root_decimals(scene, pixels, precision)] * (len(shapes) - len(decimals))
    doc = document.copy()
    writer = _Writer(doc, document.viewport, full)

    done: set = set()
    for shape, orig, places in zip(shapes, shapes_before, decimals):
        if shape.source is None or shape.source in done:
            # (None: a shape of the reader's own, not of the file: the viewport clip of a
            # nested <svg>; <use> instances of an element already written)
            continue
        if writer.shape(shape, orig, places):
            done.add(shape.source)
    if writer.averaged:
        names = ", ".join(str(a) for a in writer.averaged[:5]) + (", ..." if len(writer.averaged) > 5 else "")
        warnings.warn(f"SVG has no per-point stroke widths: {len(writer.averaged)} path(s) ({names}) "
                      f"written with the mean of their widths as stroke-width", VecfitWarning, stacklevel=3)
    done = set()
    for group, orig in zip(groups, groups_before):
        if group.source is None or group.source in done:
            continue
        if writer.group(group, orig):
            done.add(group.source)
    gradients_before = {}
    for s in shapes_before:
        for p in (s.fill, s.stroke):
            if isinstance(p, (LinearGradient, RadialGradient)):
                gradients_before.setdefault(p.source, p)
    written = set()
    for s in shapes:
        for p in (s.fill, s.stroke):
            if isinstance(p, (LinearGradient, RadialGradient)) and p.source not in written:
                before = gradients_before.get(p.source)
                if full or before is None or not _same_gradient(p, before):
                    writer.gradient(p, before)
                written.add(p.source)

    if canvas is not None:
        _set_canvas(doc.root, canvas, (original.width, original.height))
    if background is not None:
        _add_background(doc.root, background)
    return doc.serialize()


def _written(scene: Scene) -> tuple[list, list]:
    """The shapes and groups whose elements the writer updates: the drawing's, then those
    of its clip paths and masks (optimised clip geometry goes back into the clip path)."""
    shapes, groups = list(scene.shapes), list(scene.groups)
    for content, _ in scene.effect_contents():
        shapes += content.shapes
        groups += content.groups
    return shapes, groups


def _set_canvas(root, size, before) -> None:
    """The root's width and height set to ``size`` (px) and its viewBox scaled alike, from
    its origin: content keeps its scale, the canvas grows or shrinks to the right and
    bottom."""
    (w, h), (w0, h0) = size, before
    if not all(v > 0 and np.isfinite(v) for v in (w, h, w0, h0)):
        raise VecfitError(f"cannot set the canvas to {w}x{h}")
    box = parse_viewbox(root.get("viewBox"))
    if box is not None and box[2] > 0 and box[3] > 0:
        x, y, bw, bh = box
        root.set("viewBox", f"{fmt(x)} {fmt(y)} {fmt(bw * w / w0)} {fmt(bh * h / h0)}")
    root.set("width", fmt(w))
    root.set("height", fmt(h))


def _add_background(root, color) -> None:
    """A full-canvas rect, drawn first, named so that it is recognisable (and not added
    twice when a file written so is refined again: the rect is then part of the scene)."""
    if any(e.get("id") == BACKGROUND_ID for e in root.iter()):
        return
    ns = root.tag[:root.tag.index("}") + 1] if root.tag.startswith("{") else ""
    box = parse_viewbox(root.get("viewBox"))
    rect = ET.Element(f"{ns}rect")
    if box is not None and box[2] > 0 and box[3] > 0:
        x, y, w, h = box
        rect.attrib.update(x=fmt(x), y=fmt(y), width=fmt(w), height=fmt(h))
    else:
        rect.attrib.update(x="0", y="0", width="100%", height="100%")
    rect.set("id", BACKGROUND_ID)
    rect.set("fill", hex_color(color))
    # (the root's own paint is inherited: Tabler's icons set stroke="currentColor" on it,
    # which drew a black frame round the page)
    rect.set("stroke", "none")
    alpha = opacity_text(color[3]) if len(color) > 3 else None
    if alpha is None and ("fill-opacity" in root.attrib or "fill-opacity" in root.get("style", "")):
        alpha = "1"
    if alpha is not None:
        rect.set("fill-opacity", alpha)
    rect.tail = root.text
    root.insert(0, rect)


class _Writer:
    def __init__(self, doc: SvgDocument, viewport, full: bool):
        self.doc = _Styles(doc)
        self.handles = doc.handles
        self.root = doc.root
        self.by_id = doc.element_by_id
        self.viewport = viewport
        self.full = full
        self.averaged = []  # sources of paths whose per-point widths were averaged

    def _element(self, source):
        element = self.handles.get(source)
        if element is None:
            raise VecfitError(f"no element {source!r} in the source SVG")
        return element

    # ------------------------------------------------------------------ shapes

    def shape(self, shape, orig, decimals: int = 4) -> bool:
        """Write what changed, coordinates with ``decimals`` decimals; True when anything
        was written."""
        full, e, wrote = self.full, self._element(shape.source), False
        if full or not _same_geometry(shape.geometry, orig.geometry):
            self._geometry(e, shape.geometry, decimals)
            wrote = True
        for prop, paint, opacity, paint0, opacity0 in (
                ("fill", shape.fill, shape.fill_opacity, orig.fill, orig.fill_opacity),
                ("stroke", shape.stroke, shape.stroke_opacity, orig.stroke, orig.stroke_opacity)):
            if full or not _same_paint_ref(paint, paint0) or not _same(opacity, opacity0):
                self._paint(e, prop, paint, opacity)
                wrote = True
        width = shape.stroke_width
        if shape.stroke is not None and isinstance(shape.geometry, Path) and shape.geometry.widths is not None:
            # SVG has one stroke-width per element: per-point widths are averaged.
            width = shape.geometry.widths.detach().double().mean()
            self.averaged.append(shape.source)
        if shape.stroke is not None and (full or not _same(width, orig.stroke_width)):
            self.doc.set_property(e, "stroke-width", fmt(finite(width), decimals))
            wrote = True
        if full or not _same(shape.opacity, orig.opacity):
            self._opacity(e, "opacity", shape.opacity)
            wrote = True
        for prop, attr in (("fill-rule", "fill_rule"), ("stroke-linecap", "linecap"),
                           ("stroke-linejoin", "linejoin")):
            if getattr(shape, attr) != getattr(orig, attr):
                self.doc.set_property(e, prop, getattr(shape, attr))
                wrote = True
        if shape.miter_limit != orig.miter_limit:
            self.doc.set_property(e, "stroke-miterlimit", fmt(shape.miter_limit, 6))
        if shape.dash_array != orig.dash_array or shape.dash_offset != orig.dash_offset:
            dashes = shape.dash_array
            self.doc.set_property(e, "stroke-dasharray", "none" if not dashes else " ".join(fmt(v, 4) for v in dashes))
            self.doc.set_property(e, "stroke-dashoffset", fmt(shape.dash_offset, 4))
            wrote = True
        if not _same(shape.transform, orig.transform) or (full and e.get("transform") is not None):
            self._transform(e, finite(shape.transform))
            wrote = True
        return wrote

    def _opacity(self, e, prop, value):
        self.doc.set_property(e, prop, opacity_text(value))

    def _paint(self, e, prop, paint, opacity):
        op = float(finite(opacity))
        if paint is None:
            self.doc.set_property(e, prop, "none")
            return
        if isinstance(paint, Solid):
            color = finite(paint.color)
            self.doc.set_property(e, prop, hex_color(color))
            op *= float(color[3])
        else:
            if paint.source is None:
                raise VecfitError("a gradient paint without a source element cannot be written")
            self.doc.set_property(e, prop, f"url(#{paint.source})")
        self.doc.set_property(e, f"{prop}-opacity", opacity_text(op))

    def _transform(self, e, m):
        if np.array_equal(m, np.eye(3)) and e.get("transform") is None:
            return
        e.set("transform", matrix(m))

    def _geometry(self, e, g, decimals: int):
        tag = local_name(e.tag)
        if isinstance(g, Rect):
            p0, p1, r = finite(g.p_min), finite(g.p_max), finite(g.corner_radii)
            for name, v in (("x", p0[0]), ("y", p0[1]), ("width", p1[0] - p0[0]),
                            ("height", p1[1] - p0[1])):
                e.set(name, fmt(v, decimals))
            for name, v in (("rx", r[0]), ("ry", r[1])):
                if v != 0 or e.get(name) is not None:
                    e.set(name, fmt(v, decimals))
        elif isinstance(g, Circle):
            c = finite(g.center)
            e.set("cx", fmt(c[0], decimals))
            e.set("cy", fmt(c[1], decimals))
            e.set("r", fmt(finite(g.radius), decimals))
        elif isinstance(g, Ellipse):
            c, r = finite(g.center), finite(g.radii)
            for name, v in (("cx", c[0]), ("cy", c[1]), ("rx", r[0]), ("ry", r[1])):
                e.set(name, fmt(v, decimals))
        else:
            self._path(e, tag, g, decimals)

    def _path(self, e, tag, g: Path, decimals: int):
        pts = finite(g.points)
        degrees = [int(d) for d in g.degrees]
        lines = all(d == 1 for d in degrees) and len(g.subpaths) == 1
        closed = bool(g.subpaths[0][2]) if g.subpaths else False
        pairs = lambda: " ".join(f"{fmt(x, decimals)},{fmt(y, decimals)}" for x, y in pts)  # noqa: E731
        if tag == "line" and lines and not closed and len(degrees) == 1:
            for name, v in zip(("x1", "y1", "x2", "y2"), pts.reshape(-1)):
                e.set(name, fmt(v, decimals))
            return
        if tag == "polyline" and lines and not closed and len(pts) >= 2:
            e.set("points", pairs())
            return
        if tag == "polygon" and lines and closed and len(pts) >= 2:
            e.set("points", pairs())
            return
        if tag != "path":  # the structure changed: becomes a <path>, attributes kept
            e.tag = e.tag[: len(e.tag) - len(tag)] + "path"
            for name in ("x1", "y1", "x2", "y2", "points"):
                e.attrib.pop(name, None)
        e.set("d", path_data(g, decimals))

    # ------------------------------------------------------------------ groups

    def group(self, group, orig) -> bool:
        e, wrote = self._element(group.source), False
        if self.full or not _same(group.opacity, orig.opacity):
            self._opacity(e, "opacity", group.opacity)
            wrote = True
        if not _same(group.transform, orig.transform) or (self.full and e.get("transform")):
            m = finite(group.transform)
            tag = local_name(e.tag)
            if tag == "use":
                x = parse_length(e.get("x"), self.viewport[0]) or 0.0
                y = parse_length(e.get("y"), self.viewport[1]) or 0.0
                m = m @ translate(-x, -y)
            elif tag in ("svg", "symbol") and e is not self.root:
                # The group's transform includes the viewBox mapping: not writable as is.
                if not _same(group.transform, orig.transform):
                    warnings.warn(f"the transform of <{tag}> {group.source} is not written back",
                                  stacklevel=3)
                return wrote
            self._transform(e, m)
            wrote = True
        return wrote

    # --------------------------------------------------------------- gradients

    def gradient(self, paint, before):
        from .dom import href_id
        chain, seen = [], set()
        e = self.handles.get(paint.source)
        if e is None:
            e = self.by_id(paint.source)
        while e is not None and local_name(e.tag) in GRADIENTS and id(e) not in seen:
            seen.add(id(e))
            chain.append(e)
            e = self.by_id(href_id(e))
        if not chain:
            raise VecfitError(f"no gradient element #{paint.source} in the source SVG")
        g = chain[0]
        full = self.full or before is None
        if isinstance(paint, LinearGradient):
            fields = ((("x1", "y1"), paint.start, before and before.start),
                      (("x2", "y2"), paint.end, before and before.end))
        else:
            fields = ((("cx", "cy"), paint.center, before and before.center),
                      (("r",), paint.radius.reshape(1), before and before.radius.reshape(1)),
                      (("fx", "fy"), paint.focal, before and before.focal))
        for names, value, old in fields:
            if full or not _same(value, old):
                for name, v in zip(names, finite(value).reshape(-1)):
                    g.set(name, fmt(v, 6))
        if full or not _same(paint.transform, before.transform):
            m = finite(paint.transform)
            has = any(x.get("gradientTransform") is not None for x in chain)
            if has or not np.array_equal(m, np.eye(3)):
                g.set("gradientTransform", matrix(m))
        if full or not (_same(paint.offsets, before.offsets) and _same(paint.colors, before.colors)):
            holder = next((x for x in chain if any(local_name(s.tag) == "stop" for s in x)), None)
            if holder is None:
                raise VecfitError(f"gradient #{paint.source} has no stops to write")
            stops = [s for s in holder if isinstance(s.tag, str) and local_name(s.tag) == "stop"]
            offsets, colors = finite(paint.offsets), finite(paint.colors)
            if len(stops) != len(offsets):
                raise VecfitError(f"gradient #{paint.source}: {len(offsets)} stops in the scene, "
                                  f"{len(stops)} in the file")
            for s, o, c in zip(stops, offsets, colors):
                s.set("offset", fmt(min(max(o, 0.0), 1.0), 4))
                self.doc.set_property(s, "stop-color", hex_color(c))
                self.doc.set_property(s, "stop-opacity", opacity_text(c[3]))
