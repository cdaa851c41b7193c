"""The parts of clip paths, masks and filters that are attribute values: references,
units, regions and filter steps. (Reading what a clip path or mask draws is the reader's:
read.py.)"""
from __future__ import annotations

import math
import re

from vecfit.limits import MAX_STEPS
from vecfit.scene import Filter, FilterStep

from .color import parse_color
from .dom import href_id, local_name
from .paints import parse_opacity
from .units import parse_fraction, parse_length, parse_numbers

_URL = re.compile(r"""\s*url\(\s*['"]?#([^'")\s]+)['"]?\s*\)\s*$""")
REGION_DEFAULT = (-0.1, -0.1, 1.2, 1.2)

# Filter steps run by renderer/filters.py; the others leave their filter out (drawn
# unfiltered, with a warning).
STEPS = frozenset({"feGaussianBlur", "feOffset", "feFlood", "feColorMatrix", "feComposite", "feMerge",
                   "feBlend", "feDropShadow"})
_UNSUPPORTED_INPUTS = frozenset({"BackgroundImage", "BackgroundAlpha", "FillPaint", "StrokePaint"})
COMPOSITE_OPERATORS = frozenset({"over", "in", "out", "atop", "xor", "arithmetic"})


def func_iri(value) -> str | None:
    """The id in ``url(#id)``, or None for anything else."""
    m = _URL.match(value or "")
    return m.group(1) if m else None


def units_of(element, attribute: str, default: str) -> str:
    value = (element.get(attribute) or "").strip()
    return value if value in ("userSpaceOnUse", "objectBoundingBox") else default


def region(element, units: str, viewport, default=REGION_DEFAULT) -> tuple:
    """x, y, width, height of a mask or filter region: fractions of the bounding box in
    "objectBoundingBox" units, user lengths otherwise (percentages of the viewport)."""
    out = []
    for name, fallback, reference in zip(("x", "y", "width", "height"), default,
                                         (viewport[0], viewport[1], viewport[0], viewport[1])):
        text = element.get(name)
        if units == "objectBoundingBox":
            value = parse_fraction(text)
            out.append(fallback if value is None else value)
        else:
            value = parse_length(text, reference)
            out.append(fallback * reference if value is None else value)
    return tuple(out)


def _subregion(element, units: str, viewport) -> tuple:
    out = []
    for name, reference in zip(("x", "y", "width", "height"), (*viewport, *viewport)):
        text = element.get(name)
        value = parse_fraction(text) if units == "objectBoundingBox" else parse_length(text, reference)
        out.append(value if value is not None and math.isfinite(value) else None)
    return tuple(out)


def with_steps(element, ids):
    """The <filter> whose children are the steps: ``element`` or one it inherits from by
    href (a chain of filters; None if it leads nowhere or loops)."""
    seen = set()
    while element is not None and id(element) not in seen:
        seen.add(id(element))
        if local_name(element.tag) != "filter":
            return None
        if any(isinstance(c.tag, str) for c in element):
            return element
        ref = href_id(element)
        element = ids.get(ref) if ref else None
    return None


def parse_filter(element, ids, computed, viewport, skip, name: str) -> Filter | None:
    """The Filter of a <filter> element. A filter with no steps (or steps that lead
    nowhere) gives a Filter without steps, which SVG draws as nothing; a filter with a
    step vecfit does not run gives None (drawn unfiltered) and a warning through ``skip``."""
    units = units_of(element, "filterUnits", "objectBoundingBox")
    primitive_units = units_of(element, "primitiveUnits", "userSpaceOnUse")
    area = region(element, units, viewport)
    holder = with_steps(element, ids)
    filt = Filter(steps=[], units=units, primitive_units=primitive_units, region=area,
                  source=element.get("id"))
    if holder is None:
        return filt
    names: set[str] = set()
    for child in holder:
        if not isinstance(child.tag, str):
            continue
        tag = local_name(child.tag)
        if tag not in STEPS:
            if tag.startswith("fe"):
                skip("filter", f"{name} ({tag})")
                return None
            continue
        if len(filt.steps) >= MAX_STEPS:
            skip("filter", f"{name} (more than {MAX_STEPS} steps)")
            return None
        step = _step(tag, child, computed(child), names, filt.steps, viewport, primitive_units)
        filt.steps.append(step)
        if step.result:
            names.add(step.result)
    return filt


def _input(element, attribute: str, names: set, steps: list) -> str:
    """An input: SourceGraphic, SourceAlpha, a known result, or "" (the previous step's
    result, the source for the first), as resvg resolves unknown names."""
    text = (element.get(attribute) or "").strip()
    if text in ("SourceGraphic", "SourceAlpha"):
        return text
    if text in _UNSUPPORTED_INPUTS:
        return "SourceGraphic"
    if text in names:
        return text
    return "" if steps else "SourceGraphic"


def _std(element, default: str) -> tuple[float, float]:
    values = parse_numbers(element.get("stdDeviation") or default) or []
    if len(values) == 1:
        values = values * 2
    if len(values) != 2 or not all(math.isfinite(v) for v in values):
        return 0.0, 0.0
    return max(values[0], 0.0), max(values[1], 0.0)


def _number(element, attribute: str, default: float) -> float:
    values = parse_numbers(element.get(attribute))
    return values[0] if values and len(values) == 1 and math.isfinite(values[0]) else default


def _flood(style) -> tuple:
    color = parse_color(style.get("flood-color") or "black")
    if (style.get("flood-color") or "").strip() == "currentColor":
        color = parse_color(style.get("color") or "black")
    color = color or (0.0, 0.0, 0.0, 1.0)
    return (*color[:3], color[3] * parse_opacity(style.get("flood-opacity")))


def _step(tag, element, style, names, steps, viewport, units) -> FilterStep:
    kind = tag[2:]
    linear = (style.get("color-interpolation-filters") or "").strip() != "sRGB"
    params: dict = {}
    inputs = [_input(element, "in", names, steps)]
    if kind == "GaussianBlur":
        params["std"] = _std(element, "0")
    elif kind == "Offset":
        params["dx"], params["dy"] = _number(element, "dx", 0.0), _number(element, "dy", 0.0)
    elif kind == "Flood":
        params["color"] = _flood(style)
        inputs = []
    elif kind == "ColorMatrix":
        kind_name = (element.get("type") or "matrix").strip()
        values = parse_numbers(element.get("values")) or []
        if kind_name not in ("matrix", "saturate", "hueRotate", "luminanceToAlpha") or (
                kind_name == "matrix" and len(values) != 20):
            kind_name, values = "matrix", []
        params["type"], params["values"] = kind_name, values
    elif kind == "Composite":
        operator = (element.get("operator") or "over").strip()
        params["operator"] = operator if operator in COMPOSITE_OPERATORS else "over"
        params["k"] = tuple(_number(element, k, 0.0) for k in ("k1", "k2", "k3", "k4"))
        inputs.append(_input(element, "in2", names, steps))
    elif kind == "Merge":
        inputs = [_input(node, "in", names, steps) for node in element
                  if isinstance(node.tag, str) and local_name(node.tag) == "feMergeNode"]
    elif kind == "Blend":
        params["mode"] = (element.get("mode") or "normal").strip()
        inputs.append(_input(element, "in2", names, steps))
    elif kind == "DropShadow":
        params["std"] = _std(element, "2")
        params["dx"], params["dy"] = _number(element, "dx", 2.0), _number(element, "dy", 2.0)
        params["color"] = _flood(style)
    result = (element.get("result") or "").strip()
    return FilterStep(kind=kind, inputs=inputs, result=result, params=params,
                      region=_subregion(element, units, viewport), linear_rgb=linear)
