"""svg_to_scene and save_svg, on vecfit's SVG reader and number formatting.

Where these differ from diffvg's (deliberately: diffvg's are wrong there):
- svg_to_scene reads everything vecfit's reader reads: <ellipse> (diffvg drops it), rect
  x/y (diffvg ignores them), radial gradients' centre and radius, viewBox, nested
  transforms, <use>, CSS classes, arcs;
- save_svg writes every shape of a group (diffvg writes the first only) and radial
  gradients (diffvg cannot).
What diffvg's model cannot hold is approximated and listed here: caps and joins are
round; opacity, fill-opacity and group opacities are folded into the colours' alpha; a
radial gradient's focal point is dropped, and under a rotated or skewed transform its
radii are the transform's scale along x and y; a <g>'s opacity over overlapping shapes is
applied per shape. A group with both a fill and a stroke draws its stroke under its fill
(diffvg's order): save_svg writes the stroke as its own element, before the fill.
"""
from __future__ import annotations

import warnings

import numpy as np
import torch

from vecfit.io.files import atomic_write_text
from vecfit import scene as vs
from vecfit.scene.geometry import local_bbox, rect_path
from vecfit.svg.numbers import finite, fmt
from vecfit.svg.pathdata import format_path_data
from vecfit.svg.read import load_svg

from .shapes import Circle, Ellipse, LinearGradient, Path, Polygon, RadialGradient, Rect, ShapeGroup


# ------------------------------------------------------------------------------ reading

def _canvas_matrix(scene: vs.Scene, shape: vs.Shape) -> torch.Tensor:
    m = shape.transform.double()
    g = shape.group
    while g >= 0:
        m = scene.groups[g].transform.double() @ m
        g = scene.groups[g].parent
    return scene.view.double() @ m


def _opacity(scene: vs.Scene, shape: vs.Shape) -> float:
    a = float(shape.opacity)
    g = shape.group
    while g >= 0:
        a *= float(scene.groups[g].opacity)
        g = scene.groups[g].parent
    return a


def _t(x) -> torch.Tensor:
    return torch.as_tensor(np.asarray(x, dtype=np.float64), dtype=torch.float32).clone()


def _gradient_matrix(paint, geometry, m: torch.Tensor) -> torch.Tensor:
    """Gradient space -> canvas."""
    g = m @ paint.transform.double()
    if paint.units == "objectBoundingBox":
        box = local_bbox(geometry)
        if box is not None:
            lo, hi = (b.detach().double() for b in box)
            bbox = torch.tensor([[float(hi[0] - lo[0]), 0, float(lo[0])], [0, float(hi[1] - lo[1]), float(lo[1])],
                                 [0, 0, 1]], dtype=torch.float64)
            g = m @ bbox @ paint.transform.double()
    return g


def _read_paint(paint, alpha: float, geometry, m: torch.Tensor):
    if paint is None:
        return None
    if isinstance(paint, vs.Solid):
        c = paint.color.detach().double().clone()
        c[3] *= alpha
        return c.float()
    colors = paint.colors.detach().double().clone()
    colors[:, 3] *= alpha
    offsets = paint.offsets.detach().float().clone()
    g = _gradient_matrix(paint, geometry, m)
    A, b = g[:2, :2], g[:2, 2]
    if isinstance(paint, vs.LinearGradient):
        s, e = paint.start.detach().double(), paint.end.detach().double()
        d = e - s
        begin = A @ s + b
        n2 = float(d @ d)
        if n2 == 0 or abs(float(torch.linalg.det(A))) < 1e-12:
            return LinearGradient(begin.float(), begin.float(), offsets, colors.float())
        k = torch.linalg.solve(A.T, d) / n2  # t = (p - begin) . k, exactly
        return LinearGradient(begin.float(), (begin + k / float(k @ k)).float(), offsets, colors.float())
    c, r = paint.center.detach().double(), float(paint.radius)
    radius = torch.stack([torch.linalg.norm(A[:, 0]), torch.linalg.norm(A[:, 1])]) * r
    return RadialGradient((A @ c + b).float(), radius.float(), offsets, colors.float())


def _paths_of(geometry: vs.Path, widths) -> list[Path]:
    """One diffvg Path per subpath; a closing line of zero length is dropped (diffvg's
    closed paths wrap their last segment round to the first point)."""
    out = []
    pts = geometry.points.detach().float()
    for (first, count, closed), (p0, n) in zip(geometry.subpaths, geometry.subpath_point_ranges()):
        p = pts[p0:p0 + n].clone()
        degrees = [int(d) for d in geometry.degrees[first:first + count]]
        w = None if widths is None else widths[p0:p0 + n].detach().float().clone() / 2
        if closed and len(degrees) > 1 and degrees[-1] == 1 and float(torch.linalg.norm(p[-1] - p[0])) < 1e-6:
            degrees.pop()
            p = p[:-1]
            w = None if w is None else w[:-1]
        if not degrees:
            continue
        path = Path(torch.tensor([d - 1 for d in degrees], dtype=torch.int32), p.contiguous(), bool(closed))
        if w is not None:
            path.stroke_width = w
        out.append(path)
    return out


def _read_shapes(geometry) -> list:
    if isinstance(geometry, vs.Circle):
        return [Circle(_t(float(geometry.radius)), geometry.center.detach().float().clone())]
    if isinstance(geometry, vs.Ellipse):
        return [Ellipse(geometry.radii.detach().float().clone(), geometry.center.detach().float().clone())]
    if isinstance(geometry, vs.Rect):
        if float(geometry.corner_radii.min()) <= 0:
            return [Rect(geometry.p_min.detach().float().clone(), geometry.p_max.detach().float().clone())]
        pts, degrees = rect_path(geometry)
        geometry = vs.Path(points=pts.detach(), degrees=np.array(degrees), subpaths=[(0, len(degrees), True)])
    return _paths_of(geometry, geometry.widths)


def svg_to_scene(filename):
    """An SVG file -> (canvas_width, canvas_height, shapes, shape_groups), through
    vecfit's SVG reader (raises vecfit.SvgError naming the file when it cannot be read)."""
    scene = load_svg(filename)
    shapes, groups = [], []
    for shape in scene.shapes:
        m = _canvas_matrix(scene, shape)
        alpha = _opacity(scene, shape)
        parts = _read_shapes(shape.geometry)
        if not parts:
            continue
        ids = torch.arange(len(shapes), len(shapes) + len(parts), dtype=torch.int32)
        half = shape.stroke_width.detach().float().clone() / 2
        for p in parts:
            if not (isinstance(p, Path) and p.stroke_width.dim() > 0 and p.stroke_width.numel() > 1):
                p.stroke_width = half.clone()
            p.id = str(shape.source) if isinstance(shape.source, str) else ''
        shapes.extend(parts)
        m32 = m.float()
        even_odd = shape.fill_rule == "evenodd"
        fill = _read_paint(shape.fill, alpha * float(shape.fill_opacity), shape.geometry, m)
        stroke = _read_paint(shape.stroke, alpha * float(shape.stroke_opacity), shape.geometry, m)
        if fill is not None:
            groups.append(ShapeGroup(ids, fill, use_even_odd_rule=even_odd, shape_to_canvas=m32.clone()))
        if stroke is not None and float(shape.stroke_width) > 0:
            groups.append(ShapeGroup(ids.clone(), None, use_even_odd_rule=even_odd, stroke_color=stroke,
                                     shape_to_canvas=m32.clone()))
    w, h = scene.width, scene.height
    return (int(round(w)) if abs(w - round(w)) < 1e-9 else w, int(round(h)) if abs(h - round(h)) < 1e-9 else h,
            shapes, groups)


# ------------------------------------------------------------------------------ writing

DECIMALS = 6


def _num(v) -> str:
    return fmt(v, DECIMALS)


def _color(c, use_gamma: bool) -> tuple[str, float]:
    a = np.clip(finite(c), 0.0, 1.0)
    rgb = a[:3] ** (1 / 2.2) if use_gamma else a[:3]
    return "rgb({})".format(", ".join(str(int(round(x * 255))) for x in rgb)), float(a[3]) if len(a) > 3 else 1.0


def _matrix3(m) -> np.ndarray:
    a = finite(m)
    if a.shape == (2, 3):
        a = np.vstack([a, [0, 0, 1]])
    return a


def _matrix_attr(a: np.ndarray) -> str:
    return "matrix({})".format(" ".join(_num(v) for v in (a[0, 0], a[1, 0], a[0, 1], a[1, 1], a[0, 2], a[1, 2])))


def _path_d(shape) -> str:
    if isinstance(shape, Circle):
        shape = Ellipse(torch.as_tensor(shape.radius).reshape(1).expand(2), shape.center)
    if isinstance(shape, Ellipse):
        (rx, ry), (cx, cy) = finite(shape.radius), finite(shape.center)
        return (f"M{_num(cx + rx)} {_num(cy)} A{_num(rx)} {_num(ry)} 0 1 1 {_num(cx - rx)} {_num(cy)} "
                f"A{_num(rx)} {_num(ry)} 0 1 1 {_num(cx + rx)} {_num(cy)} Z")
    if isinstance(shape, Rect):
        (x0, y0), (x1, y1) = finite(shape.p_min), finite(shape.p_max)
        return f"M{_num(x0)} {_num(y0)} H{_num(x1)} V{_num(y1)} H{_num(x0)} Z"
    pts = finite(shape.points)
    closed = bool(shape.is_closed)
    if isinstance(shape, Polygon):
        degrees = [1] * (len(pts) if closed else len(pts) - 1)
    else:  # diffvg's closed path: its last segment ends at the first point, as a Scene's
        degrees = [int(k) + 1 for k in np.asarray(finite(shape.num_control_points))]
    return format_path_data(pts, degrees, [(0, len(degrees), closed)], decimals=DECIMALS)


def _element(shapes_in_group) -> tuple[str, dict]:
    if len(shapes_in_group) == 1:
        s = shapes_in_group[0]
        if isinstance(s, Circle):
            (cx, cy), r = finite(s.center), float(finite(s.radius))
            return "circle", {"cx": _num(cx), "cy": _num(cy), "r": _num(r)}
        if isinstance(s, Ellipse):
            (cx, cy), (rx, ry) = finite(s.center), finite(s.radius)
            return "ellipse", {"cx": _num(cx), "cy": _num(cy), "rx": _num(rx), "ry": _num(ry)}
        if isinstance(s, Rect):
            (x0, y0), (x1, y1) = finite(s.p_min), finite(s.p_max)
            return "rect", {"x": _num(x0), "y": _num(y0), "width": _num(x1 - x0), "height": _num(y1 - y0)}
    return "path", {"d": " ".join(_path_d(s) for s in shapes_in_group)}


def _escape(text: str) -> str:
    return (text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;"))


def _attrs(d: dict) -> str:
    return " ".join(f'{k}="{_escape(str(v))}"' for k, v in d.items())


class _Defs:
    def __init__(self, use_gamma: bool):
        self.lines: list[str] = []
        self.use_gamma = use_gamma

    def paint(self, paint, inverse: np.ndarray | None) -> tuple[str, float]:
        """(the fill or stroke attribute's value, its opacity)."""
        if isinstance(paint, torch.Tensor):
            return _color(paint, self.use_gamma)
        gid = f"gradient_{len(self.lines)}"
        if isinstance(paint, LinearGradient):
            (x1, y1), (x2, y2) = finite(paint.begin), finite(paint.end)
            attrs = {"id": gid, "gradientUnits": "userSpaceOnUse", "x1": _num(x1), "y1": _num(y1),
                     "x2": _num(x2), "y2": _num(y2)}
            tag, m = "linearGradient", inverse
        else:
            (cx, cy), (rx, ry) = finite(paint.center), finite(paint.radius)
            ellipse = np.array([[rx, 0, cx], [0, ry, cy], [0, 0, 1]])
            attrs = {"id": gid, "gradientUnits": "userSpaceOnUse", "cx": "0", "cy": "0", "r": "1"}
            tag, m = "radialGradient", ellipse if inverse is None else inverse @ ellipse
        if m is not None:
            attrs["gradientTransform"] = _matrix_attr(m)
        stops = []
        for offset, color in zip(finite(paint.offsets).reshape(-1), finite(paint.stop_colors).reshape(-1, 4)):
            c, a = _color(color, self.use_gamma)
            stops.append(f'    <stop offset="{_num(offset)}" stop-color="{c}" stop-opacity="{_num(a)}"/>')
        self.lines.append(f"  <{tag} {_attrs(attrs)}>\n" + "\n".join(stops) + f"\n  </{tag}>")
        return f"url(#{gid})", 1.0


def save_svg(filename, width, height, shapes, shape_groups, use_gamma=False, background=None):
    """Write shapes and groups as an SVG that vecfit (and any SVG viewer) draws as
    pydiffvg renders them; written atomically. ``use_gamma``: colours raised to 1/2.2.
    ``background`` (as later diffvg versions take it): an RGB or RGBA colour, written as a
    rect under everything."""
    defs, body = _Defs(use_gamma), []
    if background is not None:
        rgba = finite(background).reshape(-1)
        value, opacity = _color(np.concatenate([rgba, [1.0]]) if rgba.size == 3 else rgba, use_gamma)
        attrs = {"x": "0", "y": "0", "width": _num(width), "height": _num(height), "fill": value}
        if opacity < 1:
            attrs["fill-opacity"] = _num(opacity)
        body.append(f"  <rect {_attrs(attrs)}/>")
    for group in shape_groups:
        members = [shapes[int(i)] for i in finite(group.shape_ids).reshape(-1)]
        if not members or (group.fill_color is None and group.stroke_color is None):
            continue
        m = _matrix3(group.shape_to_canvas)
        identity = np.allclose(m, np.eye(3))
        inverse = None if identity else np.linalg.inv(m)
        tag, geometry = _element(members)
        common = {} if identity else {"transform": _matrix_attr(m)}
        name = group.id or (members[0].id if len(members) == 1 else "")
        if group.stroke_color is not None:  # under the fill, as diffvg draws it
            value, opacity = defs.paint(group.stroke_color, inverse)
            widths = [finite(s.stroke_width).reshape(-1) for s in members]
            if any(w.size > 1 for w in widths):
                warnings.warn("save_svg: per-point stroke widths are written as their mean", stacklevel=2)
            full_width = 2 * float(np.mean(np.concatenate(widths)))
            attrs = {**geometry, **common, "fill": "none", "stroke": value, "stroke-width": _num(full_width),
                     "stroke-linecap": "round", "stroke-linejoin": "round"}
            if opacity < 1:
                attrs["stroke-opacity"] = _num(opacity)
            if name and group.fill_color is None:
                attrs = {"id": name, **attrs}
            body.append(f"  <{tag} {_attrs(attrs)}/>")
        if group.fill_color is not None:
            value, opacity = defs.paint(group.fill_color, inverse)
            attrs = {**geometry, **common, "fill": value,
                     "fill-rule": "evenodd" if group.use_even_odd_rule else "nonzero"}
            if opacity < 1:
                attrs["fill-opacity"] = _num(opacity)
            if name:
                attrs = {"id": name, **attrs}
            body.append(f"  <{tag} {_attrs(attrs)}/>")
    head = (f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{_num(width)}" '
            f'height="{_num(height)}" viewBox="0 0 {_num(width)} {_num(height)}">')
    parts = [head]
    if defs.lines:
        parts += ["  <defs>", *defs.lines, "  </defs>"]
    parts += body + ["</svg>", ""]
    atomic_write_text(filename, "\n".join(parts))
