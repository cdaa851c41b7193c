"""``--group-by colour``: the shapes of a written SVG gathered into one ``<g>`` per colour,
each an Inkscape layer (``inkscape:groupmode="layer"``, ``inkscape:label`` the colour),
for vinyl cutters, screen printing and plotters, which work a colour at a time.

Grouping must not change the picture, and shapes are drawn in document order. The rule:
the root's shapes are taken in stacking order; a shape joins the last layer of its colour
when no shape in a layer above that one overlaps it (bounding boxes, the stroke's half
width included), since it then moves below shapes it does not touch; otherwise it opens
a new layer of its colour on top. A colour that needs more than one layer is named in a
warning and in the report (``split``). The shape's colour is its fill's (its stroke's
when it has no fill; "gradient" for gradients). The page (vecfit's background rect) and
anything not a shape (defs, styles, the user's own groups: then nothing is grouped, with
a warning) stay where they are.
"""
from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET

import numpy as np

from vecfit.scene import Circle, Ellipse, Path, Rect, Solid
from vecfit.scene.arrays import numpy_arrays, to_numpy

from .document import SvgDocument, element_children
from .dom import local_name
from .numbers import hex_color
from .write import BACKGROUND_ID

INKSCAPE = "http://www.inkscape.org/namespaces/inkscape"
SVG = "http://www.w3.org/2000/svg"
NOT_DRAWN = {"defs", "title", "desc", "metadata", "style", "linearGradient", "radialGradient"}


def shape_box(shape) -> np.ndarray | None:
    """[x0, y0, x1, y1] of a Scene shape in canvas units (its geometry's control points,
    transformed, grown by half its stroke width), or None for an empty one."""
    g = shape.geometry
    if isinstance(g, Path):
        p = np.asarray(to_numpy(g.points), np.float64).reshape(-1, 2)
    elif isinstance(g, Rect):
        p = np.stack([to_numpy(g.p_min), to_numpy(g.p_max)]).astype(np.float64)
    elif isinstance(g, (Circle, Ellipse)):
        c = np.asarray(to_numpy(g.center), np.float64)
        r = np.asarray(to_numpy(g.radius if isinstance(g, Circle) else g.radii), np.float64)
        p = np.stack([c - r, c + r])
    else:
        return None
    if not len(p):
        return None
    m = np.asarray(to_numpy(shape.transform), np.float64)
    if isinstance(g, (Rect, Circle, Ellipse)):  # all four corners, for rotations
        p = np.array([[p[i, 0], p[j, 1]] for i in (0, 1) for j in (0, 1)])
    p = p @ m[:2, :2].T + m[:2, 2]
    pad = 0.0
    if shape.stroke is not None:
        pad = 0.5 * float(np.max(to_numpy(shape.stroke_width))) * float(np.sqrt(abs(np.linalg.det(m[:2, :2]))) or 1)
    return np.concatenate([p.min(0) - pad, p.max(0) + pad])


def _colour_key(shape) -> str:
    paint = shape.fill if shape.fill is not None else shape.stroke
    if isinstance(paint, Solid):
        return hex_color(to_numpy(paint.color))
    return "gradient" if paint is not None else "none"


def _overlaps(box: np.ndarray, boxes: np.ndarray) -> bool:
    if not len(boxes):
        return False
    return bool(((boxes[:, 0] < box[2]) & (box[0] < boxes[:, 2]) &
                 (boxes[:, 1] < box[3]) & (box[1] < boxes[:, 3])).any())


def group_by_colour(svg: bytes) -> tuple[bytes, dict]:
    """The SVG with its root's shapes in colour layers (see the module's docstring), and
    the report: {"layers": [{"colour", "shapes"}...] bottom to top, "split": colours in
    more than one layer, "warnings": lines}."""
    from .read import scene_of

    document = SvgDocument.parse(svg, "<svg>")
    with numpy_arrays(), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = scene_of(document, for_writing=False)
    root = document.root
    by_element = {id(document.handles.get(s.source)): s for s in scene.shapes}
    children = element_children(root)
    others = [c for c in children if local_name(c.tag) not in NOT_DRAWN and id(c) not in by_element]
    if others:
        line = (f"--group-by colour: the SVG has elements that are not shapes at its top level "
                f"(<{local_name(others[0].tag)}>, ...): left ungrouped")
        return svg, {"layers": [], "split": [], "warnings": [line]}
    layers: list[dict] = []  # {"key", "elements"} bottom to top
    top: dict[str, int] = {}  # colour -> index of its topmost layer
    boxes = np.zeros((len(children), 4))  # the grouped shapes' boxes, and their layers
    layer_of = np.zeros(len(children), np.int64)
    placed = 0
    for child in children:
        shape = by_element.get(id(child))
        if shape is None or child.get("id") == BACKGROUND_ID:
            continue
        key, box = _colour_key(shape), shape_box(shape)
        box = np.zeros(4) if box is None else box
        last = top.get(key)
        if last is None or _overlaps(box, boxes[:placed][layer_of[:placed] > last]):
            last = top[key] = len(layers)
            layers.append({"key": key, "elements": []})
        layers[last]["elements"].append(child)
        boxes[placed], layer_of[placed] = box, last
        placed += 1
    if not layers:
        return svg, {"layers": [], "split": [], "warnings": []}

    ET.register_namespace("inkscape", INKSCAPE)
    first = children.index(layers[0]["elements"][0])
    grouped = {id(e) for layer in layers for e in layer["elements"]}
    for e in list(root):
        if id(e) in grouped:
            root.remove(e)
    seen: dict[str, int] = {}
    for n, layer in enumerate(layers):
        key = layer["key"]
        seen[key] = seen.get(key, 0) + 1
        label = key if seen[key] == 1 else f"{key} ({seen[key]})"
        g = ET.Element(f"{{{SVG}}}g" if root.tag.startswith("{") else "g",
                       {f"{{{INKSCAPE}}}groupmode": "layer", f"{{{INKSCAPE}}}label": label})
        g.text = "\n"  # one element a line, as the tracer writes them
        for e in layer["elements"]:
            e.tail = "\n"
            g.append(e)
        g.tail = "\n"
        root.insert(min(first, len(root)) + n, g)
    split = sorted(k for k, n in seen.items() if n > 1)
    lines = []
    if split:
        lines.append(f"--group-by colour: stacking order keeps {len(split)} colour(s) in more than one layer "
                     f"({', '.join(split[:5])}{', ...' if len(split) > 5 else ''}): shapes of other colours "
                     f"between them overlap; {len(layers)} layers for {len(seen)} colours")
    report = {"layers": [{"colour": l["key"], "shapes": len(l["elements"])} for l in layers],
              "split": split, "warnings": lines}
    return document.serialize(), report
