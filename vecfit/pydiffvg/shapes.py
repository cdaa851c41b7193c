"""diffvg's scene objects: plain attribute holders, as pydiffvg defines them (same names,
argument order and defaults). Callers reassign attributes between renders; nothing is
checked or copied here (RenderFunction.serialize_scene reads them).

Units as diffvg's: coordinates in canvas pixels before ``shape_to_canvas``; a
``stroke_width`` is *half* the SVG stroke width (the stroke is every point within that
distance of the outline: round caps and joins).
"""
from __future__ import annotations

import torch

from vecfit.svg.pathdata import PathDataError, parse_path_data, to_arrays

from .enums import FilterType


class Circle:
    def __init__(self, radius, center, stroke_width=torch.tensor(1.0), id=''):
        self.radius = radius
        self.center = center
        self.stroke_width = stroke_width
        self.id = id


class Ellipse:
    def __init__(self, radius, center, stroke_width=torch.tensor(1.0), id=''):
        self.radius = radius  # [2] rx, ry
        self.center = center
        self.stroke_width = stroke_width
        self.id = id


class Path:
    """One subpath: ``num_control_points[i]`` (0, 1 or 2: line, quadratic, cubic) per
    segment; a closed path's last segment ends at ``points[0]``, which is not repeated.
    ``stroke_width``: a scalar, or one (half) width per point."""

    def __init__(self, num_control_points, points, is_closed, stroke_width=torch.tensor(1.0), id='',
                 use_distance_approx=False):
        self.num_control_points = num_control_points
        self.points = points
        self.is_closed = is_closed
        self.stroke_width = stroke_width
        self.id = id
        self.use_distance_approx = use_distance_approx  # accepted; vecfit's distances are exact


class Polygon:
    def __init__(self, points, is_closed, stroke_width=torch.tensor(1.0), id=''):
        self.points = points
        self.is_closed = is_closed
        self.stroke_width = stroke_width
        self.id = id


class Rect:
    def __init__(self, p_min, p_max, stroke_width=torch.tensor(1.0), id=''):
        self.p_min = p_min
        self.p_max = p_max
        self.stroke_width = stroke_width
        self.id = id


class ShapeGroup:
    """Shapes drawn as one: their fills form one compound region (winding numbers add up
    across the shapes), their strokes one stroke; the stroke is drawn under the fill.
    ``shape_to_canvas``: a 3x3 (or 2x3) affine matrix."""

    def __init__(self, shape_ids, fill_color, use_even_odd_rule=True, stroke_color=None,
                 shape_to_canvas=torch.eye(3), id=''):
        self.shape_ids = shape_ids
        self.fill_color = fill_color
        self.use_even_odd_rule = use_even_odd_rule
        self.stroke_color = stroke_color
        self.shape_to_canvas = shape_to_canvas
        self.id = id


class LinearGradient:
    """In canvas coordinates; stop colours straight RGBA [K, 4]."""

    def __init__(self, begin=torch.tensor([0.0, 0.0]), end=torch.tensor([0.0, 0.0]),
                 offsets=torch.tensor([0.0]), stop_colors=torch.tensor([0.0, 0.0, 0.0, 0.0])):
        self.begin = begin
        self.end = end
        self.offsets = offsets
        self.stop_colors = stop_colors


class RadialGradient:
    """In canvas coordinates: an axis-aligned ellipse of radii ``radius`` [2]."""

    def __init__(self, center=torch.tensor([0.0, 0.0]), radius=torch.tensor([0.0, 0.0]),
                 offsets=torch.tensor([0.0]), stop_colors=torch.tensor([0.0, 0.0, 0.0, 0.0])):
        self.center = center
        self.radius = radius
        self.offsets = offsets
        self.stop_colors = stop_colors


class PixelFilter:
    def __init__(self, type, radius=torch.tensor(0.5)):
        self.type = type
        self.radius = radius


def from_svg_path(path_str, shape_to_canvas=torch.eye(3), force_close=False):
    """SVG path data -> a list of Paths, one per subpath, their points mapped by
    ``shape_to_canvas``. Arcs become cubics; a subpath that ends where it began (or every
    subpath, with ``force_close``) is closed. Read with vecfit's path-data parser: data
    with an error gives the subpaths before it, as SVG draws them."""
    try:
        subpaths = parse_path_data(path_str)
    except PathDataError as e:
        subpaths = e.subpaths
    m = torch.as_tensor(shape_to_canvas, dtype=torch.float32)
    out = []
    for sub in subpaths:
        points, degrees, _ = to_arrays([sub])
        pts = torch.tensor(points, dtype=torch.float32)
        degrees = list(degrees)
        closed = sub.closed
        if closed and len(degrees) > 1 and degrees[-1] == 1:
            # vecfit stores Z as a line back to the start; diffvg wraps the last segment
            # round to points[0] instead, so a zero-length closing line is dropped.
            if torch.linalg.norm(pts[-1] - pts[0]) < 1e-5:
                degrees.pop()
                pts = pts[:-1]
        elif not closed and len(degrees) > 0:
            if torch.linalg.norm(pts[-1] - pts[0]) < 1e-5:
                degrees, pts, closed = degrees, pts[:-1], True
            elif force_close:
                degrees.append(1)
                closed = True
        if not degrees:
            continue
        h = torch.cat([pts, torch.ones(len(pts), 1)], dim=1) @ m.T
        pts = h[:, :2] / h[:, 2:3] if m.shape[0] == 3 else h
        out.append(Path(torch.tensor([d - 1 for d in degrees], dtype=torch.int32), pts.contiguous(), closed))
    return out


__all__ = ["Circle", "Ellipse", "FilterType", "LinearGradient", "Path", "PixelFilter", "Polygon",
           "RadialGradient", "Rect", "ShapeGroup", "from_svg_path"]
