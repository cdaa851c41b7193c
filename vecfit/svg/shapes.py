"""Geometry of the basic shapes and paths, in the element's own user space.

Each builder returns None when SVG says the element is not rendered (zero or negative
size, missing attributes, no segments). Attribute rules follow SVG 2 as resvg applies
them: rect rx/ry resolve "auto" from each other and clamp to half the size; ellipse rx/ry
likewise; an invalid or negative radius counts as not given.
"""
from __future__ import annotations

import math
import re

from vecfit.scene import Circle, Ellipse, Path, Rect, arrays

from .pathdata import PathDataError, Subpath, parse_path_data, to_arrays
from .units import clamp_array, parse_length, parse_number

_LIST_SPLIT = re.compile(r"[\s,]+")


class Limiter:
    """Makes float32 tensors from float64 values, limiting magnitudes (1e39 would be inf
    in float32); remembers whether it had to."""

    def __init__(self):
        self.clamped = False

    def tensor(self, values):
        a, changed = clamp_array(values)
        self.clamped |= changed
        return arrays.floats(a)


class ShapeReader:
    """Builds geometry for one element; ``problem`` names what was wrong with it, if
    anything was (e.g. path data with an error, drawn up to the error)."""

    def __init__(self, viewport: tuple[float, float], limiter: Limiter, max_segments: int | None = None):
        vw, vh = viewport
        self.refs = {"x": vw, "y": vh, "r": math.sqrt((vw * vw + vh * vh) / 2)}
        self.lim = limiter
        self.problem: str | None = None
        self.max_segments = max_segments  # paths with more are not built
        self.too_many_segments = False
        self.segments = 0  # of what was built (basic shapes count as 4)

    def length(self, element, name: str, axis: str, default=None):
        value = parse_length(element.get(name), self.refs[axis])
        return default if value is None else value

    def build(self, tag: str, element):
        geometry = getattr(self, "_" + tag)(element)
        if geometry is not None and not self.segments:
            self.segments = 4
        return geometry

    # ---------------------------------------------------------------- shapes

    def _rect(self, element):
        w = self.length(element, "width", "x")
        h = self.length(element, "height", "y")
        if w is None or h is None or w <= 0 or h <= 0:
            return None
        x, y = self.length(element, "x", "x", 0.0), self.length(element, "y", "y", 0.0)
        rx = self._radius(element, "rx", "x")
        ry = self._radius(element, "ry", "y")
        # SVG 2: a missing (or invalid) radius takes the other's value; then clamp.
        rx, ry = (rx if rx is not None else ry), (ry if ry is not None else rx)
        rx, ry = min(rx or 0.0, w / 2), min(ry or 0.0, h / 2)
        if rx <= 0 or ry <= 0:
            rx = ry = 0.0  # either radius zero: square corners
        return Rect(p_min=self.lim.tensor([x, y]), p_max=self.lim.tensor([x + w, y + h]),
                    corner_radii=self.lim.tensor([rx, ry]))

    def _radius(self, element, name, axis):
        """A corner or ellipse radius; None for missing, "auto", invalid or negative."""
        value = self.length(element, name, axis)
        return value if value is not None and value >= 0 else None

    def _circle(self, element):
        r = self.length(element, "r", "r")
        if r is None or r <= 0:
            return None
        c = [self.length(element, "cx", "x", 0.0), self.length(element, "cy", "y", 0.0)]
        return Circle(center=self.lim.tensor(c), radius=self.lim.tensor(r))

    def _ellipse(self, element):
        rx = self._radius(element, "rx", "x")
        ry = self._radius(element, "ry", "y")
        rx, ry = (rx if rx is not None else ry), (ry if ry is not None else rx)
        if rx is None or rx <= 0 or ry <= 0:
            return None
        c = [self.length(element, "cx", "x", 0.0), self.length(element, "cy", "y", 0.0)]
        return Ellipse(center=self.lim.tensor(c), radii=self.lim.tensor([rx, ry]))

    def _line(self, element):
        p0 = (self.length(element, "x1", "x", 0.0), self.length(element, "y1", "y", 0.0))
        p1 = (self.length(element, "x2", "x", 0.0), self.length(element, "y2", "y", 0.0))
        return self._path_from([Subpath(points=[p0, p1], degrees=[1])])

    def _polyline(self, element, closed=False):
        points = self._points(element.get("points") or "")
        if len(points) < 2:
            return None
        sub = Subpath(points=points, degrees=[1] * (len(points) - 1))
        if closed:
            sub.degrees.append(1)
            sub.closed = True
        return self._path_from([sub])

    def _polygon(self, element):
        return self._polyline(element, closed=True)

    def _points(self, text: str) -> list[tuple[float, float]]:
        """Coordinate pairs up to the first invalid number (an odd one out is dropped)."""
        values = []
        if self.max_segments is not None and text.count(",") + text.count(" ") > 4 * self.max_segments + 4:
            self.too_many_segments = True  # far too many numbers: not worth reading
            return values
        for item in _LIST_SPLIT.split(text.strip()):
            if not item:
                continue
            v = parse_number(item)
            if v is None:
                self.problem = "invalid points data"
                break
            values.append(v)
        return list(zip(values[0::2], values[1::2]))

    def _path(self, element):
        try:
            subpaths = parse_path_data(element.get("d") or "", self.max_segments)
        except PathDataError as e:
            if e.too_long:
                self.too_many_segments = True
                return None
            self.problem = "invalid path data"
            subpaths = e.subpaths
        return self._path_from(subpaths)

    def _path_from(self, subpaths):
        if not subpaths:
            return None
        points, degrees, table = to_arrays(subpaths)
        self.segments = len(degrees)
        if self.max_segments is not None and self.segments > self.max_segments:
            self.too_many_segments = True
            return None
        return Path(points=self.lim.tensor(points), degrees=degrees, subpaths=table)
