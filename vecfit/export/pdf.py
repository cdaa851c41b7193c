"""A Scene as a one-page PDF, written directly (PDF 1.4's operators say what SVG says).

- Page: the SVG's canvas, 1 px = 0.75 pt (CSS's 96 px to 72 pt per inch); y flipped.
- Paths: lines and cubics as they are (quadratics raised to cubics, exact), circles and
  ellipses as four quarter-ellipse cubics (as the SVG writer writes them). Fill rules
  ``f``/``f*``; strokes with their width, caps, joins, miter limit and dashes (``w J j M d``).
- Paints: solid colours; gradients as shading patterns (type 2 axial, type 3 radial, the
  stops as a stitching function of linear pieces; pad, SVG's default, by ``Extend``).
  Stop alphas that vary become a soft mask of the same gradient in grey.
- Opacity: ``ca``/``CA`` where one paint is drawn; a shape with fill and stroke under an
  opacity, and a group's opacity, as a transparency group (SVG's layer) drawn at that
  alpha. Blend modes as the ExtGState's ``BM`` (the names are SVG's, capitalised).
- Clip paths: one shape as ``W n``/``W* n`` (vector clipping); several (a union, which
  ``W`` cannot say) as a soft mask of their white fills. Masks as luminosity or alpha
  soft masks (PDF weighs luminosity as its renderer does, not exactly as SVG).
- Filters are not drawn: the element is drawn without its filter, with a warning.
"""
from __future__ import annotations

import warnings
import zlib

import numpy as np

from vecfit.scene.dashes import dash_pattern
from vecfit.scene.model import ClipPath, LinearGradient, Scene, Solid

from vecfit.scene.outline import (Subpath, bbox, encloses, f64, group_chain, is_dot, num, scene_bbox, shape_to, subpaths,
                      transformed, unit_box)

PT_PER_PX = 0.75
CAPS = {"butt": 0, "round": 1, "square": 2}
JOINS = {"miter": 0, "round": 1, "bevel": 2}
BLEND = {"multiply": "Multiply", "screen": "Screen", "overlay": "Overlay", "darken": "Darken",
         "lighten": "Lighten", "color-dodge": "ColorDodge", "color-burn": "ColorBurn",
         "hard-light": "HardLight", "soft-light": "SoftLight", "difference": "Difference",
         "exclusion": "Exclusion"}


def n(x: float) -> str:
    """A PDF real: fixed point (PDF has no exponents), 7 significant digits."""
    x = float(x)
    if not np.isfinite(x) or abs(x) < 1e-9:
        return "0"
    return np.format_float_positional(x, precision=7, unique=False, fractional=False, trim="-")


def matrix(m: np.ndarray) -> str:
    return " ".join(n(v) for v in (m[0, 0], m[1, 0], m[0, 1], m[1, 1], m[0, 2], m[1, 2]))


def path_ops(paths) -> str:
    """Path construction operators of the subpaths."""
    out = []
    for s in paths:
        out.append(f"{n(s.start[0])} {n(s.start[1])} m")
        segments = s.segments
        # A closed subpath's last line back to the start is what h draws.
        if s.closed and segments and segments[-1][0] == 1 and np.array_equal(segments[-1][1][-1], s.start):
            segments = segments[:-1]
        for d, c in segments:
            if d == 1:
                out.append(f"{n(c[0, 0])} {n(c[0, 1])} l")
            else:
                out.append(" ".join(f"{n(x)} {n(y)}" for x, y in c) + " c")
        if s.closed:
            out.append("h")
    return "\n".join(out)


def _caps(dots: list, cap: str, width: float) -> list:
    """The caps a stroke draws on subpaths without length: a disc with round caps, a
    square along the axes with square caps (as resvg and tiny-skia), nothing with butt."""
    r = width / 2
    out = []
    for d in dots:
        c = d.start
        if cap == "round":
            k = 0.5522847498307936 * r
            pts = c + np.array([[r, 0], [r, k], [k, r], [0, r], [-k, r], [-r, k], [-r, 0],
                                [-r, -k], [-k, -r], [0, -r], [k, -r], [r, -k], [r, 0]])
            out.append(Subpath(pts[0], [(3, pts[i:i + 3]) for i in (1, 4, 7, 10)], True))
        elif cap == "square":
            pts = c + np.array([[-r, -r], [r, -r], [r, r], [-r, r]])
            out.append(Subpath(pts[0], [(1, pts[i:i + 1]) for i in (1, 2, 3)], True))
    return out


class _Lazy:
    """A value computed when first asked for (``_value``)."""

    def __init__(self, make):
        self.make, self.done, self.value = make, False, None


def _value(x):
    if isinstance(x, _Lazy):
        if not x.done:
            x.value, x.done = x.make(), True
        return x.value
    return x


class _Stream:
    """A content stream being written: its text, and the CTM relative to its start
    (``rel``) and to the page (``base @ rel``), which patterns and form boxes need."""

    def __init__(self, base: np.ndarray):
        self.parts: list[str] = []
        self.base = base
        self.rel = np.eye(3)
        self.saved: list[np.ndarray] = []

    def q(self):
        self.parts.append("q")
        self.saved.append(self.rel.copy())

    def Q(self):
        self.parts.append("Q")
        self.rel = self.saved.pop()

    def cm(self, m: np.ndarray):
        if not np.allclose(m, np.eye(3), atol=0, rtol=0):
            self.parts.append(matrix(m) + " cm")
            self.rel = self.rel @ m

    def add(self, text: str):
        if text:
            self.parts.append(text)


class PdfWriter:
    def __init__(self, scene: Scene):
        self.scene = scene
        self.objects: list[bytes | None] = []
        self.ext: dict[tuple, str] = {}      # ExtGState entries -> name
        self.resources = {"ExtGState": {}, "Pattern": {}, "XObject": {}, "Shading": {}}
        self.warned: set[str] = set()
        self.w_pt = scene.width * PT_PER_PX
        self.h_pt = scene.height * PT_PER_PX
        self.resources_ref = self.reserve()

    # ----------------------------------------------------------------- objects
    def reserve(self) -> int:
        self.objects.append(None)
        return len(self.objects)

    def put(self, body: bytes | str, ref: int | None = None) -> int:
        body = body.encode("latin-1") if isinstance(body, str) else body
        if ref is None:
            self.objects.append(body)
            return len(self.objects)
        self.objects[ref - 1] = body
        return ref

    def stream(self, dictionary: str, data: str) -> int:
        raw = zlib.compress(data.encode("latin-1"), 6)
        return self.put(f"<< {dictionary} /Filter /FlateDecode /Length {len(raw)} >>\nstream\n".encode("latin-1")
                        + raw + b"\nendstream")

    def name(self, kind: str, ref: int) -> str:
        prefix = {"ExtGState": "G", "Pattern": "P", "XObject": "X", "Shading": "S"}[kind]
        key = f"{prefix}{len(self.resources[kind])}"
        self.resources[kind][key] = ref
        return key

    def gs(self, **entries) -> str:
        """``/Gn gs`` for an ExtGState with these entries (shared between equal ones)."""
        key = tuple(sorted(entries.items()))
        if key not in self.ext:
            body = " ".join(f"/{k} {v}" for k, v in key)
            self.ext[key] = self.name("ExtGState", self.put(f"<< /Type /ExtGState {body} >>"))
        return f"/{self.ext[key]} gs"

    def warn(self, message: str):
        if message not in self.warned:
            self.warned.add(message)
            warnings.warn(message, stacklevel=4)

    # ------------------------------------------------------------------ page
    def write(self) -> bytes:
        flip = np.array([[PT_PER_PX, 0, 0], [0, -PT_PER_PX, self.h_pt], [0, 0, 1]])
        page = _Stream(np.eye(3))
        page.cm(flip @ f64(self.scene.view))
        self.draw_scene(self.scene, page)
        content = self.stream("", "\n".join(page.parts))
        res = " ".join(f"/{kind} << " + " ".join(f"/{k} {v} 0 R" for k, v in d.items()) + " >>"
                       for kind, d in self.resources.items() if d)
        self.put(f"<< {res} >>", self.resources_ref)
        catalog = self.reserve()
        pages = self.reserve()
        page_ref = self.put(f"<< /Type /Page /Parent {pages} 0 R /MediaBox [0 0 {n(self.w_pt)} {n(self.h_pt)}] "
                            f"/Resources {self.resources_ref} 0 R /Contents {content} 0 R "
                            f"/Group << /S /Transparency /CS /DeviceRGB >> >>")
        self.put(f"<< /Type /Pages /Kids [{page_ref} 0 R] /Count 1 >>", pages)
        self.put(f"<< /Type /Catalog /Pages {pages} 0 R >>", catalog)
        info = self.put("<< /Producer (vecfit) >>")
        out = bytearray(b"%PDF-1.4\n%\xe2\xe3\xcf\xd3\n")
        offsets = []
        for i, body in enumerate(self.objects):
            offsets.append(len(out))
            out += f"{i + 1} 0 obj\n".encode() + body + b"\nendobj\n"
        xref = len(out)
        out += f"xref\n0 {len(self.objects) + 1}\n0000000000 65535 f \n".encode()
        out += b"".join(f"{o:010d} 00000 n \n".encode() for o in offsets)
        out += (f"trailer\n<< /Size {len(self.objects) + 1} /Root {catalog} 0 R /Info {info} 0 R >>\n"
                f"startxref\n{xref}\n%%EOF\n").encode()
        return bytes(out)

    # ---------------------------------------------------------------- layers
    def form(self, inner: _Stream, group: str = "/Group << /S /Transparency /CS /DeviceRGB >>") -> int:
        """A form XObject of ``inner``'s content; its box covers the page in its space."""
        box = self.page_box(inner.base)
        return self.stream(f"/Type /XObject /Subtype /Form /BBox [{' '.join(n(v) for v in box)}] "
                           f"/Resources {self.resources_ref} 0 R {group}", "\n".join(inner.parts))

    def page_box(self, base: np.ndarray) -> list[float]:
        """The page's corners in the space whose map to the page is ``base``."""
        try:
            inv = np.linalg.inv(base)
        except np.linalg.LinAlgError:
            return [0, 0, 0, 0]
        c = np.array([[0, 0, 1], [self.w_pt, 0, 1], [0, self.h_pt, 1], [self.w_pt, self.h_pt, 1]]) @ inv.T
        lo, hi = c[:, :2].min(axis=0), c[:, :2].max(axis=0)
        pad = 0.01 * (hi - lo) + 1e-6
        return [*(lo - pad), *(hi + pad)]

    def layer(self, out: _Stream, draw, **gs_entries):
        """``draw(stream)`` as a transparency group painted with these ExtGState entries
        (opacity, blend mode, soft mask)."""
        inner = _Stream(out.base @ out.rel)
        draw(inner)
        ref = self.form(inner)
        out.q()
        out.add(self.gs(**gs_entries) if gs_entries else "")
        out.add(f"/{self.name('XObject', ref)} Do")
        out.Q()

    def soft_mask(self, out: _Stream, draw, kind: str = "Luminosity") -> int:
        """An SMask dictionary (its ref) whose group is ``draw(stream)`` in ``out``'s
        current space, on a black backdrop."""
        inner = _Stream(out.base @ out.rel)
        draw(inner)
        ref = self.form(inner, "/Group << /S /Transparency /CS /DeviceRGB >>")
        return self.put(f"<< /Type /Mask /S /{kind} /G {ref} 0 R >>")

    # ----------------------------------------------------------------- scene
    def draw_scene(self, scene: Scene, out: _Stream):
        """The scene's shapes in paint order, each inside its groups (a group opened
        where its first shape comes and closed after its last)."""
        shapes = scene.shapes
        i = 0
        while i < len(shapes):
            i = self.draw_run(scene, out, i, -1)

    def draw_run(self, scene: Scene, out: _Stream, i: int, group: int) -> int:
        """Draws shapes from ``i`` on while they are inside ``group``; returns the next."""
        shapes = scene.shapes
        while i < len(shapes):
            chain = group_chain(scene, shapes[i].group)
            if group >= 0 and group not in chain:
                return i
            below = chain[chain.index(group) + 1:] if group >= 0 else chain
            if below:
                child = below[0]
                state = {"next": i}

                def run(stream, child=child):
                    state["next"] = self.draw_run(scene, stream, i, child)
                self.draw_group(scene, out, scene.groups[child], child, run)
                i = state["next"]
            else:
                self.draw_shape(scene, out, shapes[i])
                i += 1
        return i

    def effects(self, out: _Stream, draw, box, element, opacity: float):
        """Draws ``draw`` (in ``out``'s current space, the element's own) under the
        element's (a Shape's or Group's) clip, mask, blend mode and ``opacity``."""
        if element.filter is not None:
            self.warn("PDF: filters are not drawn (the elements are drawn without them)")
        entries = {}
        if opacity < 1:
            entries["ca"] = n(max(opacity, 0))
        if element.blend in BLEND:
            entries["BM"] = "/" + BLEND[element.blend]
        mask = element.mask
        clip = element.clip
        out.q()
        clip_entries = self.clip(out, clip, box) if clip is not None else {}
        if mask is not None:
            entries["SMask"] = f"{self.mask(out, mask, box)} 0 R"
        if clip_entries:  # a union of shapes: a soft mask, on a layer of its own
            inner_draw, inner_entries = draw, entries
            entries = clip_entries

            def draw(stream, inner_draw=inner_draw, inner_entries=inner_entries):
                if inner_entries:
                    self.layer(stream, inner_draw, **inner_entries)
                else:
                    inner_draw(stream)
        if entries or getattr(element, "isolate", False):  # (a Group's isolation)
            self.layer(out, draw, **entries)
        else:
            draw(out)
        out.Q()

    def draw_group(self, scene: Scene, out: _Stream, group, index: int, run):
        out.q()
        out.cm(f64(group.transform))
        box = _Lazy(lambda: scene_bbox(scene, index))  # for bounding-box units only
        self.effects(out, run, box, group, num(group.opacity))
        out.Q()

    def draw_shape(self, scene: Scene, out: _Stream, shape):
        paths = subpaths(shape.geometry)
        if not paths:
            return
        fill = shape.fill
        width = num(shape.stroke_width)
        if getattr(shape.geometry, "widths", None) is not None:
            width = float(np.mean(f64(shape.geometry.widths)))
        stroke = shape.stroke if width > 0 else None
        if fill is None and stroke is None:
            return
        out.q()
        out.cm(f64(shape.transform))
        box = _Lazy(lambda: bbox(paths))  # for bounding-box units only: sampling costs
        # (PDF viewers draw a fill without area as a hairline, and no cap on a subpath
        # without length: both are said here as SVG draws them)
        fill_ops = path_ops([s for s in paths if encloses(s)])
        stroke_ops = path_ops([s for s in paths if not is_dot(s)])
        dots = "" if dash_pattern(shape.dash_array) else path_ops(
            _caps([s for s in paths if is_dot(s)], shape.linecap, width))  # (a dot has no dashes)
        opacity = num(shape.opacity)
        both = fill is not None and stroke is not None and opacity < 1

        def draw(stream):
            # a shape with fill and stroke under an opacity is one layer at that opacity
            k = 1.0 if both else opacity
            if fill is not None and fill_ops:
                self.paint(stream, fill_ops, fill, k * num(shape.fill_opacity), box,
                           "f*" if shape.fill_rule == "evenodd" else "f", False)
            if stroke is not None and stroke_ops:
                self.paint(stream, stroke_ops, stroke, k * num(shape.stroke_opacity), box, "S", True,
                           self.stroke_state(shape, width))
            if stroke is not None and dots:
                self.paint(stream, dots, stroke, k * num(shape.stroke_opacity), box, "f", False)

        # the opacity is a layer's only where fill and stroke overlap
        self.effects(out, draw, box, shape, opacity if both else 1.0)
        out.Q()

    @staticmethod
    def stroke_state(shape, width: float) -> str:
        parts = [f"{n(width)} w", f"{CAPS.get(shape.linecap, 0)} J", f"{JOINS.get(shape.linejoin, 0)} j",
                 f"{n(max(shape.miter_limit, 1.0))} M"]
        pattern = dash_pattern(shape.dash_array)
        if pattern is not None:
            parts.append(f"[{' '.join(n(v) for v in pattern)}] {n(shape.dash_offset)} d")
        return " ".join(parts)

    def paint(self, out: _Stream, ops: str, paint, alpha: float, box, op: str, stroke: bool, state: str = ""):
        """One painting of the path: ``op`` (f, f*, S) with ``paint`` at ``alpha``."""
        a_key = "CA" if stroke else "ca"
        if isinstance(paint, Solid):
            c = f64(paint.color)
            a = alpha * c[3]
            if a <= 0:
                return
            rgb = " ".join(n(v) for v in np.clip(c[:3], 0, 1))
            out.q()
            out.add(self.gs(**{a_key: n(min(a, 1))}) if a < 1 else "")
            out.add(state)
            out.add(f"{rgb} {'RG' if stroke else 'rg'}\n{ops}\n{op}")
            out.Q()
            return
        m = self.gradient_matrix(paint, box)
        colors = f64(paint.colors).reshape(-1, 4)
        offsets = np.clip(f64(paint.offsets).reshape(-1), 0, 1)
        if m is None or not len(colors):
            return  # a bounding box of no area: SVG draws nothing with it
        coords = self.coords(paint)
        if coords is None:  # no length or no radius: the last stop's colour
            self.paint(out, ops, Solid(colors[-1]), alpha, box, op, stroke, state)
            return
        out.q()
        alphas = colors[:, 3]
        entries = {}
        if np.ptp(alphas) > 1e-6:
            shading = self.shading(paint, coords, offsets, alphas[:, None], "DeviceGray")

            def gray(stream):
                stream.cm(m)
                stream.add(f"/{self.name('Shading', shading)} sh")
            entries["SMask"] = f"{self.soft_mask(out, gray)} 0 R"
            a = alpha
        else:
            a = alpha * alphas[0]
        if a <= 0:
            out.Q()
            return
        if a < 1:
            entries[a_key] = n(a)
        out.add(self.gs(**entries) if entries else "")
        shading = self.shading(paint, coords, offsets, colors[:, :3], "DeviceRGB")
        pattern = self.put(f"<< /Type /Pattern /PatternType 2 /Shading {shading} 0 R /Matrix [{matrix(out.rel @ m)}] >>")
        name = self.name("Pattern", pattern)
        out.add(state)
        out.add(f"/Pattern {'CS' if stroke else 'cs'} /{name} {'SCN' if stroke else 'scn'}\n{ops}\n{op}")
        out.Q()

    @staticmethod
    def gradient_matrix(paint, box) -> np.ndarray | None:
        """Gradient space -> the shape's space: gradientTransform, then the bounding box."""
        m = f64(paint.transform)
        if paint.units == "objectBoundingBox":
            unit = unit_box(_value(box))
            if unit is None:
                return None
            m = unit @ m
        return m

    @staticmethod
    def coords(paint):
        if isinstance(paint, LinearGradient):
            a, b = f64(paint.start), f64(paint.end)
            return None if np.allclose(a, b) else [*a, *b]
        c, f, r = f64(paint.center), f64(paint.focal), num(paint.radius)
        if r <= 0:
            return None
        d = f - c
        if np.hypot(*d) > 0.999 * r:  # a focus outside the circle moves onto it (SVG 1.1)
            f = c + d * (0.999 * r / np.hypot(*d))
        return [*f, 0.0, *c, r]

    def shading(self, paint, coords, offsets, values: np.ndarray, space: str) -> int:
        """A shading of the stops: a stitching function of linear pieces over [0, 1],
        flat before the first stop and after the last (pad)."""
        ts = [0.0] + list(offsets) + [1.0]
        vs = [values[0]] + list(values) + [values[-1]]
        pieces, bounds = [], []
        for i in range(len(ts) - 1):
            if ts[i + 1] - ts[i] <= 1e-9:
                continue  # no width: the colour jumps here
            if pieces:
                bounds.append(ts[i])
            c0 = " ".join(n(v) for v in np.clip(vs[i], 0, 1))
            c1 = " ".join(n(v) for v in np.clip(vs[i + 1], 0, 1))
            pieces.append(f"<< /FunctionType 2 /Domain [0 1] /C0 [{c0}] /C1 [{c1}] /N 1 >>")
        if not pieces:  # every stop at one offset
            c = " ".join(n(v) for v in np.clip(vs[-1], 0, 1))
            pieces = [f"<< /FunctionType 2 /Domain [0 1] /C0 [{c}] /C1 [{c}] /N 1 >>"]
        function = (f"<< /FunctionType 3 /Domain [0 1] /Functions [{' '.join(pieces)}] "
                    f"/Bounds [{' '.join(n(b) for b in bounds)}] /Encode [{' '.join(['0 1'] * len(pieces))}] >>")
        kind = 2 if isinstance(paint, LinearGradient) else 3
        return self.put(f"<< /ShadingType {kind} /ColorSpace /{space} /Coords [{' '.join(n(v) for v in coords)}] "
                        f"/Function {function} /Extend [true true] >>")

    # ------------------------------------------------------------ clip, mask
    def clip(self, out: _Stream, clip: ClipPath, box) -> dict:
        """Applies the clip in ``out``'s current space: one shape by W n (returns {}),
        several as the ExtGState entries of a soft mask (returned)."""
        if clip.clip is not None:
            nested = self.clip(out, clip.clip, box)
            if nested:  # (rare) a clipped clip of several shapes: drawn on its own layer
                self.warn("PDF: a clip path on a clip path of several shapes is drawn unclipped by the outer one")
        if clip.units == "objectBoundingBox":
            unit = unit_box(_value(box))
            if unit is None:
                out.add("0 0 m h W n")  # nothing shows
                return {}
        else:
            unit = np.eye(3)
        content = clip.content
        to_clip = unit @ f64(content.view)
        shapes = [s for s in content.shapes if subpaths(s.geometry)]
        if len(shapes) <= 1:
            if not shapes:
                out.add("0 0 m h W n")
                return {}
            s = shapes[0]
            paths = transformed(subpaths(s.geometry), to_clip @ shape_to(content, s))
            out.add(path_ops(paths) + ("\nW* n" if s.fill_rule == "evenodd" else "\nW n"))
            return {}

        def white(stream):
            for s in shapes:
                paths = transformed(subpaths(s.geometry), to_clip @ shape_to(content, s))
                stream.add("1 1 1 rg\n" + path_ops(paths) + ("\nf*" if s.fill_rule == "evenodd" else "\nf"))
        return {"SMask": f"{self.soft_mask(out, white)} 0 R"}

    def mask(self, out: _Stream, mask, box) -> int:
        """The SMask of an SVG mask: its content drawn in the element's space (or its
        bounding box's), inside the mask region."""
        unit = unit_box(_value(box)) if "objectBoundingBox" in (mask.units, mask.content_units) else None
        region = np.asarray(mask.region, np.float64)

        def draw(stream):
            r = region
            if mask.units == "objectBoundingBox":
                if unit is None:
                    return
                r = np.concatenate([unit[:2, :2] @ r[:2] + unit[:2, 2], np.diag(unit)[:2] * r[2:]])
            stream.add(f"{n(r[0])} {n(r[1])} {n(r[2])} {n(r[3])} re W n")
            if mask.content_units == "objectBoundingBox":
                if unit is None:
                    return
                stream.cm(unit)
            stream.cm(f64(mask.content.view))
            self.draw_scene(mask.content, stream)
        if mask.mask is not None:
            self.warn("PDF: a mask on a mask is not drawn")
        return self.soft_mask(out, draw, "Alpha" if mask.kind == "alpha" else "Luminosity")


def scene_pdf(scene: Scene) -> bytes:
    """The Scene as a PDF file's bytes (warns of what it cannot draw)."""
    return PdfWriter(scene).write()
