"""A Scene as a DXF drawing (through ezdxf), for plotters, cutters and CAD.

- What is drawn: outlines. A stroke is its path's centre line (open subpaths open, closed
  ones closed), each subpath one entity, drawn once; a fill is its closed outlines. A
  shape with a fill and a stroke of one colour is written once. Dashed strokes are cut
  into their dashes.
- Curves: by default polylines (LWPOLYLINE) within ``TOLERANCE_MM`` of the curve: every
  cutter, plotter and CAM program reads them, while SPLINE support is patchy among
  cutter software. ``curves="spline"`` writes each subpath with curves as one exact
  SPLINE instead (a cubic Bézier chain is a clamped cubic B-spline with triple knots),
  and a circle or ellipse as a CIRCLE or ELLIPSE.
- Layers: one per colour, named ``#rrggbb``, coloured with that true colour; a gradient's
  layer is the mean of its stops. Entities are BYLAYER. A stroke's width is kept as the
  nearest DXF lineweight.
- Units: millimetres (``$INSUNITS`` 4), 1 px = 25.4/96 mm as CSS says, so an SVG sized
  in mm or cm keeps its size; inches (``$INSUNITS`` 1) for an SVG sized in inches.
  y is flipped: DXF's y goes up, the drawing keeps its lower left corner at (0, 0).
- Not written: opacity, clip paths, masks and filters (with a warning), gradients'
  colours beyond the layer's.
"""
from __future__ import annotations

import io
import math
import warnings

import numpy as np

from vecfit.scene.dashes import dash_pattern
from vecfit.scene.model import Circle, Ellipse, Scene, Solid
from vecfit.scene.placement import shape_matrices

from vecfit.scene.outline import encloses, f64, flattened, is_dot, num, subpaths, transformed

MM_PER_PX = 25.4 / 96
UNITS = {"mm": (4, MM_PER_PX), "in": (1, 1 / 96)}  # $INSUNITS code, drawing units per px
TOLERANCE_MM = 0.01  # polylines stray at most this far from the curves (a cutter's step is 0.025 mm or more)


def layer_color(paint) -> tuple[int, int, int] | None:
    """The layer's colour of a paint (a gradient's: the mean of its stops); None when the
    paint draws nothing."""
    if paint is None:
        return None
    c = f64(paint.color) if isinstance(paint, Solid) else f64(paint.colors).reshape(-1, 4).mean(axis=0)
    if c[3] <= 0:
        return None
    return tuple(int(round(v * 255)) for v in np.clip(c[:3], 0, 1))


def dashed(points: np.ndarray, pattern: tuple, offset: float) -> list[np.ndarray]:
    """The dashes of a polyline (in the shape's own units, as the pattern)."""
    period = sum(pattern)
    seg = np.diff(points, axis=0)
    lengths = np.hypot(seg[:, 0], seg[:, 1])
    s = np.concatenate([[0], np.cumsum(lengths)])
    total = s[-1]
    if total <= 0:
        return []
    on, out = [], []
    position = -(offset % period)
    i = 0
    while position < total:
        a, b = position, position + pattern[i % len(pattern)]
        if i % 2 == 0 and b > 0:
            on.append((max(a, 0), min(b, total)))
        position = b
        i += 1
    for a, b in on:
        if b <= a:
            continue
        inside = (s > a) & (s < b)
        pts = np.vstack([_at(points, s, a), points[inside], _at(points, s, b)])
        out.append(pts)
    return out


def _at(points, s, d):
    k = int(np.clip(np.searchsorted(s, d, side="right") - 1, 0, len(points) - 2))
    t = (d - s[k]) / (s[k + 1] - s[k]) if s[k + 1] > s[k] else 0.0
    return (points[k] + t * (points[k + 1] - points[k]))[None]


def scene_dxf(scene: Scene, units: str = "mm", curves: str = "polyline") -> bytes:
    """The Scene as DXF text (bytes)."""
    import ezdxf
    from ezdxf.lldxf.const import VALID_DXF_LINEWEIGHTS
    from ezdxf.math import Bezier4P, Vec2, bezier_to_bspline

    code, per_px = UNITS[units]
    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = code
    doc.header["$MEASUREMENT"] = 1 if units == "mm" else 0
    msp = doc.modelspace()
    # pixels -> drawing units, y flipped
    page = np.array([[per_px, 0, 0], [0, -per_px, scene.height * per_px], [0, 0, 1]])
    tolerance = TOLERANCE_MM if units == "mm" else TOLERANCE_MM / 25.4
    layers: dict[tuple, str] = {}
    dropped = set()

    def layer(rgb) -> str:
        if rgb not in layers:
            name = "#%02x%02x%02x" % rgb
            doc.layers.add(name, true_color=ezdxf.rgb2int(rgb))
            layers[rgb] = name
        return layers[rgb]

    def add(paths, attribs, pattern=None, dash_offset=0.0, own=None, own_scale=1.0):
        for s in paths:
            if pattern is not None:  # dashes, measured in the shape's own units
                local = flattened(s, tolerance / own_scale)
                for piece in dashed(local, pattern, dash_offset):
                    pts = piece @ own[:2, :2].T + own[:2, 2]
                    msp.add_lwpolyline(pts[:, :2], dxfattribs=attribs)
                continue
            if is_dot(s):  # a pen's dot (a stroke's cap alone)
                msp.add_point((*s.start, 0), dxfattribs=attribs)
                continue
            has_curves = any(d == 3 for d, _ in s.segments)
            if curves == "spline" and has_curves:
                beziers, a = [], s.start
                for d, c in s.segments:
                    ctrl = c if d == 3 else np.array([a + (c[0] - a) / 3, a + 2 * (c[0] - a) / 3, c[0]])
                    beziers.append(Bezier4P([Vec2(*a), *(Vec2(*p) for p in ctrl)]))
                    a = c[-1]
                if s.closed and np.any(a != s.start):
                    b = s.start
                    beziers.append(Bezier4P([Vec2(*a), Vec2(*(a + (b - a) / 3)), Vec2(*(a + 2 * (b - a) / 3)), Vec2(*b)]))
                spline = msp.add_spline(dxfattribs=attribs)
                spline.apply_construction_tool(bezier_to_bspline(beziers))
            else:
                pts = flattened(s, tolerance)
                if s.closed and len(pts) > 2 and np.allclose(pts[0], pts[-1]):
                    pts = pts[:-1]
                if len(pts) >= 2:
                    msp.add_lwpolyline(pts, close=s.closed, dxfattribs=attribs)

    def conic(geometry, own, attribs) -> bool:
        """With exact curves, a circle or an ellipse as a CIRCLE or ELLIPSE entity (an
        ellipse under any affine map is one); False for anything else."""
        if curves != "spline" or not isinstance(geometry, (Circle, Ellipse)):
            return False
        c = f64(geometry.center).reshape(2)
        r = np.repeat(f64(geometry.radius).reshape(1), 2) if isinstance(geometry, Circle) else f64(geometry.radii)
        axes = own[:2, :2] @ np.diag(r)  # the image of the unit circle: centre + axes @ (cos, sin)
        u, sv, _ = np.linalg.svd(axes)
        centre = (*(own[:2, :2] @ c + own[:2, 2]), 0)
        if sv[1] <= 0:
            return False
        if sv[0] - sv[1] <= 1e-9 * sv[0]:
            msp.add_circle(centre, float(sv[0]), dxfattribs=attribs)
        else:
            msp.add_ellipse(centre, (*(u[:, 0] * sv[0]), 0), float(sv[1] / sv[0]), dxfattribs=attribs)
        return True

    matrices = np.asarray(f64(shape_matrices(scene, scene.width, scene.height)), np.float64) \
        if scene.shapes else np.zeros((0, 3, 3))
    for shape, m in zip(scene.shapes, matrices):
        for effect in ("clip", "mask", "filter"):
            if getattr(shape, effect) is not None:
                dropped.add(effect)
        own = page @ m
        own_scale = math.sqrt(abs(np.linalg.det(own[:2, :2]))) or 1.0
        local = subpaths(shape.geometry)
        if not local:
            continue
        paths = transformed(local, own)
        opacity = num(shape.opacity)
        fill = layer_color(shape.fill) if opacity * num(shape.fill_opacity) > 0 else None
        width = num(shape.stroke_width)
        if getattr(shape.geometry, "widths", None) is not None:
            width = float(np.mean(f64(shape.geometry.widths)))
        stroke = layer_color(shape.stroke) if width > 0 and opacity * num(shape.stroke_opacity) > 0 else None
        pattern = dash_pattern(shape.dash_array)
        if stroke is not None:
            weight = width * own_scale * (100 if units == "mm" else 2540)  # in 1/100 mm
            lw = min(VALID_DXF_LINEWEIGHTS, key=lambda v: abs(v - weight))
            if shape.linecap == "butt":  # a subpath without length draws nothing
                keep = [not is_dot(s) for s in local]
                local = [s for s, k in zip(local, keep) if k]
                paths = [s for s, k in zip(paths, keep) if k]
            if pattern is not None:
                add(local, {"layer": layer(stroke), "lineweight": lw}, pattern, shape.dash_offset, own, own_scale)
            else:
                if not conic(shape.geometry, own, {"layer": layer(stroke), "lineweight": lw}):
                    add(paths, {"layer": layer(stroke), "lineweight": lw})
        # the same outline in the same colour is drawn once
        if fill is not None and not (fill == stroke and pattern is None and all(s.closed for s in paths)):
            if not conic(shape.geometry, own, {"layer": layer(fill)}):
                outlines = [type(s)(s.start, s.segments, True) for s in paths]
                add([s for s in outlines if encloses(s)], {"layer": layer(fill)})
    for g in scene.groups:
        for effect in ("clip", "mask", "filter"):
            if getattr(g, effect) is not None:
                dropped.add(effect)
    if dropped:
        names = {"clip": "clip paths", "mask": "masks", "filter": "filters"}
        warnings.warn("DXF: " + ", ".join(names[d] for d in sorted(dropped)) +
                      " are not applied (the outlines are written whole)", stacklevel=2)
    if not msp:
        warnings.warn("DXF: the drawing has no outlines", stacklevel=2)
    lo = np.array([0.0, 0.0])
    hi = np.array([scene.width, scene.height]) * per_px
    doc.header["$EXTMIN"] = (*lo, 0)
    doc.header["$EXTMAX"] = (*hi, 0)
    stream = io.StringIO()
    doc.write(stream)
    return stream.getvalue().encode("utf-8")
