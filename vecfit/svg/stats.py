"""What a designer sees in an SVG file: how many elements it draws, how many segments they
have (straight and curved), how big the file is, how many colours and translucent paints
it uses and how many of its outlines cross themselves (issue 37: a tracer is judged by the
file as much as by the picture).

The file is read by vecfit's own reader (as NumPy: no torch), so what counts as drawn is
what vecfit draws: <use> instances count once per instance, hidden and display:none
elements and elements with neither fill nor stroke (or opacity 0) not at all, and the
contents of clip paths and masks are not elements that are drawn. Segments are counted as
the file writes them, per element: a <path>'s from its path data, one per drawing command
(an arc is one curve, though vecfit draws it as up to four cubics; ``Z`` is a line where it
draws one, back from elsewhere to the subpath's start); a <rect> 4 lines (a rounded one also
4 arcs, its straight sides only where they have length), a <circle> or <ellipse> 4 arcs, a
<line> 1, a <polyline> of n points n - 1 lines, a <polygon> n (its closing side where it has
length). A full-canvas rect that vecfit's writer puts behind a scene (id
"vecfit-background") is reported as ``background`` and left out of every count but the
bytes and the colours.
"""
from __future__ import annotations

import gzip
import math
import os
import re
import warnings
from pathlib import Path as FilePath

import numpy as np

from vecfit.scene import Circle, Ellipse, LinearGradient, RadialGradient, Rect, Solid
from vecfit.scene.arrays import numpy_arrays, to_numpy
from vecfit.scene.crossings import crossed_outlines

from .document import SvgDocument
from .dom import local_name
from .numbers import hex_color
from .read import scene_of
from .units import NUMBER
from .write import BACKGROUND_ID
_TOKEN = re.compile(rf"[MmZzLlHhVvCcSsQqTtAa]|{NUMBER}|[^\s,]")
_ARGUMENTS = {"m": 2, "l": 2, "h": 1, "v": 1, "c": 6, "s": 4, "q": 4, "t": 2, "a": 7}
_OPAQUE = 1 - 1e-6  # opacities are float32: 1 is 1 exactly, but be lenient


def design_stats(svg) -> dict:
    """The counts of the module's docstring for an SVG given as bytes, as text, or as a
    path (a str that does not start with "<" is a path):

    paths, background (bool), segments (= lines + curves), lines, curves, primitives
    (rect, circle and ellipse elements), bytes (the file's, as given), gzip_bytes (gzip
    level 9, no timestamp), colours (distinct #rrggbb of fills, strokes and gradient
    stops), translucent_paints (elements whose fill or stroke is drawn with an alpha below
    1: opacity times fill- or stroke-opacity times the colour's alpha, or any gradient
    stop's; a group's opacity is the group's, not its elements' paint, and is not counted),
    crossed_outlines (closed subpaths of filled paths that cross themselves:
    vecfit.scene.crossings, at 0.01 px of the file's canvas)."""
    data, name = _svg_bytes(svg)
    document = SvgDocument.parse(data, name)
    with numpy_arrays(), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # what vecfit cannot draw is left out; counted as it draws
        scene = scene_of(document, for_writing=False)
    background = False
    drawn = []
    for shape in scene.shapes:
        if shape.source == BACKGROUND_ID and isinstance(shape.geometry, Rect):
            background = True
        elif (shape.fill is not None or shape.stroke is not None) and float(shape.opacity) > 0:
            drawn.append(shape)
    lines = curves = primitives = 0
    for shape in drawn:
        element = document.handles.get(shape.source)
        straight, curved = _segments(shape.geometry, element)
        lines += straight
        curves += curved
        primitives += isinstance(shape.geometry, (Rect, Circle, Ellipse))
    painted = drawn + [s for s in scene.shapes if s.source == BACKGROUND_ID]
    colours = {c for shape in painted for paint in (shape.fill, shape.stroke) for c in _colours(paint)}
    return {
        "paths": len(drawn),
        "background": background,
        "segments": lines + curves,
        "lines": lines,
        "curves": curves,
        "primitives": primitives,
        "bytes": len(data),
        "gzip_bytes": len(gzip.compress(data, compresslevel=9, mtime=0)),
        "colours": len(colours),
        "translucent_paints": sum(1 for shape in drawn if _translucent(shape)),
        "crossed_outlines": crossed_outlines(scene),
    }


def _svg_bytes(svg) -> tuple[bytes, str]:
    """(the file's bytes, a name for messages); a gzip-compressed file (.svgz) is counted
    uncompressed."""
    if isinstance(svg, bytes):
        data, name = svg, "<svg>"
    elif isinstance(svg, str) and svg.lstrip().startswith("<"):
        data, name = svg.encode("utf-8"), "<svg>"
    elif isinstance(svg, (str, os.PathLike)):
        data, name = FilePath(svg).read_bytes(), str(svg)
    else:
        raise TypeError(f"design_stats takes SVG bytes, text or a path, not {type(svg).__name__}")
    if data[:2] == b"\x1f\x8b":
        data = gzip.decompress(data)
    return data, name


# ----------------------------------------------------------------------- segments

def _segments(geometry, element) -> tuple[int, int]:
    """(lines, curves) of one drawn element, as its file writes them."""
    if isinstance(geometry, Rect):
        (x0, y0), (x1, y1) = to_numpy(geometry.p_min), to_numpy(geometry.p_max)
        rx, ry = (float(v) for v in to_numpy(geometry.corner_radii))
        if rx <= 0 or ry <= 0:
            return 4, 0
        return 2 * int(x1 - x0 > 2 * rx) + 2 * int(y1 - y0 > 2 * ry), 4
    if isinstance(geometry, (Circle, Ellipse)):
        return 0, 4
    if element is not None and local_name(element.tag) == "path":
        return path_data_segments(element.get("d") or "")
    # <line>, <polyline>, <polygon>: lines only; a polygon's closing side where it has length
    points = np.asarray(to_numpy(geometry.points), np.float64)
    count = len(geometry.degrees)
    for (_, _, closed), (start, stored) in zip(geometry.subpaths, geometry.subpath_point_ranges()):
        if closed and (points[start] == points[start + stored - 1]).all():
            count -= 1
    return count, 0


def path_data_segments(d: str) -> tuple[int, int]:
    """(lines, curves) that path data ``d`` draws, one per drawing command: L, H, V and a Z
    that draws (from elsewhere back to the subpath's start) are lines; C, S, Q, T and A
    curves (an arc to the current point draws nothing). Read up to the first error, as SVG
    draws it."""
    tokens = _TOKEN.findall(d)
    lines = curves = 0
    x = y = start_x = start_y = 0.0
    command, i, started = None, 0, False
    while i < len(tokens):
        token = tokens[i]
        if token.isalpha() and token in "MmZzLlHhVvCcSsQqTtAa":
            command, i = token, i + 1
            if command in "Zz":
                if started and not _same_point((x, y), (start_x, start_y)):
                    lines += 1
                x, y = start_x, start_y
                continue
            if command not in "Mm" and not started:
                break  # path data must start with a moveto
        elif command is None or command in "Zz":
            break  # a number without a command
        values, i = _arguments(tokens, i, command.lower())
        if values is None:
            break
        relative, kind = command.islower(), command.lower()
        ox, oy = (x, y) if relative else (0.0, 0.0)
        if kind == "m":
            x, y = ox + values[0], oy + values[1]
            start_x, start_y, started = x, y, True
            command = "l" if relative else "L"  # further pairs are linetos
        elif kind in "lhv":
            lines += 1
            if kind == "l":
                x, y = ox + values[0], oy + values[1]
            elif kind == "h":
                x = ox + values[0]
            else:
                y = oy + values[0]
        else:
            end = (ox + values[-2], oy + values[-1])
            if kind != "a" or not _same_point(end, (x, y)):
                curves += 1
            x, y = end
    return lines, curves


def _same_point(a, b) -> bool:
    """The same point, but for the rounding of relative offsets summed along a path."""
    return all(math.isclose(p, q, rel_tol=1e-9, abs_tol=1e-9) for p, q in zip(a, b))


def _arguments(tokens, i, kind):
    """(the command's numbers, the index after them), or (None, i) at an error. An arc's
    flags are single characters that may run into what follows ("0110 20": 0, 1, 10, 20)."""
    count = _ARGUMENTS[kind]
    values = []
    try:
        while len(values) < count:
            token = tokens[i]
            if kind == "a" and len(values) in (3, 4):
                if token[0] not in "01":
                    return None, i
                values.append(float(token[0]))
                if len(token) > 1:
                    tokens[i] = token[1:]
                    continue
            else:
                values.append(float(token))
            i += 1
    except (IndexError, ValueError):
        return None, i
    return values, i


# ------------------------------------------------------------------------- paints

def _colours(paint) -> list[str]:
    if isinstance(paint, Solid):
        return [hex_color(to_numpy(paint.color))]
    if isinstance(paint, (LinearGradient, RadialGradient)):
        return [hex_color(c) for c in np.asarray(to_numpy(paint.colors)).reshape(-1, 4)]
    return []


def _translucent(shape) -> bool:
    opacity = float(shape.opacity)
    return any(_paint_alpha(paint) * opacity * float(own) < _OPAQUE
               for paint, own in ((shape.fill, shape.fill_opacity), (shape.stroke, shape.stroke_opacity))
               if paint is not None)


def _paint_alpha(paint) -> float:
    """A solid's alpha; a gradient's lowest stop alpha."""
    if isinstance(paint, Solid):
        return float(to_numpy(paint.color)[3])
    return float(np.asarray(to_numpy(paint.colors)).reshape(-1, 4)[:, 3].min())
