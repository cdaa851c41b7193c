"""Paint values (``fill``/``stroke``) and the gradients they reference.

svgelements turns gradient fills into solid black, so gradients are read here from the
element tree: attributes and stops inherited through href/xlink:href chains, percentages,
stop offsets clamped and made non-decreasing, stop-opacity folded into the stop colour.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from vecfit.scene import LinearGradient, RadialGradient, Solid, as_tensor

from .color import RGBA, parse_color
from .dom import href_id, local_name
from .units import clamp, clamp_array, parse_fraction, parse_length, parse_transform

# (possessive, as units.NUMBER: "\s*" beside "\s*" with an empty quote between tried every
# split of a run of spaces)
_URL = re.compile(r"url\(\s*+(['\"]?+)\s*+#([^'\")\s]++)\s*+\1\s*+\)\s*+(.*)$", re.IGNORECASE)
GRADIENTS = ("linearGradient", "radialGradient")
_COMMON = ("gradientUnits", "gradientTransform", "spreadMethod")
BLACK = (0.0, 0.0, 0.0, 1.0)


@dataclass
class PaintValue:
    """A parsed ``fill`` or ``stroke``: none, a colour, currentColor, or url(#ref) with an
    optional fallback (itself none, a colour or currentColor)."""
    kind: str                       # "none" | "color" | "current" | "url"
    color: RGBA | None = None
    ref: str | None = None
    fallback: "PaintValue | None" = None


def parse_paint(text) -> PaintValue | None:
    """None when ``text`` is not a valid paint."""
    if text is None:
        return None
    text = text.strip()
    m = _URL.match(text)
    if m:
        fallback = parse_paint(m.group(3)) if m.group(3) else None
        if m.group(3) and (fallback is None or fallback.kind == "url"):
            return None
        return PaintValue("url", ref=m.group(2), fallback=fallback)
    low = text.lower()
    if low == "none":
        return PaintValue("none")
    if low == "currentcolor":
        return PaintValue("current")
    color = parse_color(text)
    return PaintValue("color", color=color) if color is not None else None


def parse_opacity(text, default: float = 1.0) -> float:
    """opacity-like values: a number or a percentage, clamped to [0, 1]."""
    value = parse_fraction(text)
    if value is None or math.isnan(value):
        return default
    return min(max(value, 0.0), 1.0)


def solid(color: RGBA) -> Solid:
    return Solid(color=as_tensor(color))


class Paints:
    """Turns paint values into Scene paints, resolving gradient references by id.

    ids: element id -> element; stop_style: a stop element -> its computed properties;
    viewport: (width, height) that userSpaceOnUse percentages refer to; skip: (kind, name)
    -> None, to report what is not supported.
    """

    def __init__(self, ids, stop_style, viewport, skip):
        self.ids = ids
        self.stop_style = stop_style
        self.viewport = viewport
        self.skip = skip
        self._cache: dict[str, object] = {}

    def resolve(self, value: PaintValue | None, current_color: RGBA, element_name: str):
        """A Solid, LinearGradient or RadialGradient, or None for no paint."""
        if value is None or value.kind == "none":
            return None
        if value.kind == "color":
            return solid(value.color)
        if value.kind == "current":
            return solid(current_color)
        target = self.ids.get(value.ref)
        tag = local_name(target.tag) if target is not None else None
        if tag in GRADIENTS:
            return self.gradient(value.ref)
        if tag == "pattern":
            self.skip("pattern", element_name)
        # A missing or unusable reference: the fallback if any, else nothing (SVG).
        if value.fallback is not None:
            return self.resolve(value.fallback, current_color, element_name)
        if tag != "pattern":
            self.skip("paint reference", f"{element_name} (#{value.ref})")
        return None

    def gradient(self, gid: str):
        if gid not in self._cache:
            self._cache[gid] = self._build(gid)
        return self._cache[gid]

    # ------------------------------------------------------------------ gradients

    def _chain(self, gid: str) -> list:
        """The gradient and those it references through href, cycles cut."""
        chain, seen = [], set()
        element = self.ids.get(gid)
        while element is not None and local_name(element.tag) in GRADIENTS and id(element) not in seen:
            seen.add(id(element))
            chain.append(element)
            element = self.ids.get(href_id(element))
        return chain

    def _attribute(self, chain, name: str):
        """The first value of ``name`` along the chain; type-specific attributes only from
        gradients of the same type as the first."""
        kind = local_name(chain[0].tag)
        for element in chain:
            if name in _COMMON or local_name(element.tag) == kind:
                value = element.get(name)
                if value is not None:
                    return value
        return None

    def _build(self, gid: str):
        chain = self._chain(gid)
        stops = next((s for s in (self._stops(g) for g in chain) if s), [])
        if not stops:
            return None  # no stops: the same as none
        offsets = np.array([o for o, _ in stops])
        colors = np.array([c for _, c in stops])
        if len(stops) == 1:
            return solid(tuple(colors[0]))
        attr = lambda name: self._attribute(chain, name)  # noqa: E731
        user = attr("gradientUnits") == "userSpaceOnUse"
        spread = (attr("spreadMethod") or "pad").strip()
        if spread in ("reflect", "repeat"):
            self.skip("spreadMethod", f"{gid} ({spread})")
        transform = parse_transform(attr("gradientTransform"))
        transform = np.eye(3) if transform is None else clamp_array(transform)[0]
        common = dict(offsets=as_tensor(offsets), colors=as_tensor(colors),
                      transform=as_tensor(transform),
                      units="userSpaceOnUse" if user else "objectBoundingBox", source=gid)
        coord = self._coordinate_parser(user, gid)
        if local_name(chain[0].tag) == "linearGradient":
            x1, y1 = coord(attr("x1"), 0.0, "x"), coord(attr("y1"), 0.0, "y")
            x2, y2 = coord(attr("x2"), 1.0, "x"), coord(attr("y2"), 0.0, "y")
            if (x1, y1) == (x2, y2):
                return solid(tuple(colors[-1]))  # SVG: the last stop's colour
            return LinearGradient(start=as_tensor([x1, y1]), end=as_tensor([x2, y2]), **common)
        cx, cy, r = coord(attr("cx"), 0.5, "x"), coord(attr("cy"), 0.5, "y"), coord(attr("r"), 0.5, "r")
        fx = coord(attr("fx"), None, "x")
        fy = coord(attr("fy"), None, "y")
        fr = coord(attr("fr"), 0.0, "r")
        if fr != 0:
            self.skip("fr", gid)
        if r < 0:
            return None  # an error in SVG: the paint is not used
        if r == 0:
            return solid(tuple(colors[-1]))  # SVG: the last stop's colour
        return RadialGradient(center=as_tensor([cx, cy]), radius=as_tensor(r),
                              focal=as_tensor([cx if fx is None else fx, cy if fy is None else fy]),
                              **common)

    def _coordinate_parser(self, user_space: bool, gid: str):
        """Gradient coordinates: fractions of the bounding box (numbers or percentages) in
        objectBoundingBox units; lengths, with percentages of the viewport, in user space."""
        vw, vh = self.viewport
        refs = {"x": vw, "y": vh, "r": math.sqrt((vw * vw + vh * vh) / 2)}

        def parse(text, default, axis):
            value = None
            if text is not None:
                value = (parse_length(text, refs[axis]) if user_space
                         else parse_fraction(text))
            if value is None:
                if default is None:
                    return None
                # Defaults are percentages (0%, 50%, 100%) of the box or the viewport.
                value = default * refs[axis] if user_space else default
            if clamp(value) != value:
                self.skip("out-of-range numbers", gid)
            return clamp(value)
        return parse

    def _stops(self, gradient) -> list[tuple[float, RGBA]]:
        """(offset, colour with stop-opacity folded in) of the gradient's own stops."""
        stops, last = [], 0.0
        for element in gradient:
            if local_name(element.tag) != "stop":
                continue
            style = self.stop_style(element)
            offset = parse_fraction(element.get("offset"))
            offset = 0.0 if offset is None or math.isnan(offset) else min(max(offset, 0.0), 1.0)
            last = max(last, offset)  # offsets never decrease
            text = style.get("stop-color")
            if text is not None and text.strip().lower() == "currentcolor":
                text = style.get("color")
            color = parse_color(text) or BLACK
            alpha = color[3] * parse_opacity(style.get("stop-opacity"))
            stops.append((last, (color[0], color[1], color[2], alpha)))
        return stops
