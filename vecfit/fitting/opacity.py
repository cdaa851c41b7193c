"""Which colours' opacity a fit may change (``optimize.alpha``).

A designer expects flat, opaque colours wherever the picture is opaque: a fill written
with ``fill-opacity="0.9994"`` is noise to clean up, and two translucent shapes crossed
to imitate a third are a trick to undo. So, by default (``auto``), a colour's alpha is
optimised only where translucency is real:

- the target has translucent areas (an alpha channel with more than anti-aliased rims
  between opaque and transparent pixels): every colour's alpha is free;
- the target is continuous-tone (a photograph: most pixels differ from a neighbour):
  every colour's alpha is free too. Flat colours cannot make a photograph's soft edges,
  and translucent shapes blending their neighbours can (opaque colours cost a 1,000-path
  trace of chelsea 0.9 dB; benchmarks/RESULTS.md), while nobody edits a photograph's
  thousand shapes by hand. Flat art (icons, logos, flags, emoji, cartoons) has most of
  its pixels in flat areas, even rendered with anti-aliasing;
- else only colours that were already translucent when the fit began (the user's SVG had
  them so, in refine, edit and retarget) keep a free alpha; opaque colours stay opaque.

``free`` optimises every colour's alpha (vecfit's behaviour before this rule), ``fixed``
none (edits recolour and must not fade a shape out instead of moving it).
"""
from __future__ import annotations

import cv2
import numpy as np

from vecfit.io.tone import is_flat_art
from vecfit.scene import Scene
from vecfit.scene.arrays import to_numpy


# A pixel is clear at or below CLEAR, opaque at or above SOLID; between them it is
# translucent. An anti-aliased edge between an opaque shape and a clear background is
# translucent too, but only along a rim that has both opaque and clear pixels within
# RIM pixels; translucent pixels beyond such rims make a translucent area.
CLEAR, SOLID = 0.02, 0.98
RIM = 2
# A target needs this share of its pixels (and at least MIN_PIXELS) in translucent areas
# to count as translucent: a few stray pixels of a scan's alpha do not.
MIN_SHARE, MIN_PIXELS = 0.001, 16

def translucent_pixels(alpha: np.ndarray) -> np.ndarray:
    """[H, W] bool: the translucent pixels of a straight alpha channel that are not on an
    anti-aliased rim between opaque and clear pixels."""
    a = np.asarray(alpha, np.float32)
    partial = (a > CLEAR) & (a < SOLID)
    if not partial.any():
        return partial
    kernel = np.ones((2 * RIM + 1, 2 * RIM + 1), np.uint8)
    near_solid = cv2.dilate((a >= SOLID).astype(np.uint8), kernel) > 0
    # Beyond the canvas is clear: a shape the canvas's edge cuts through has a rim of
    # partial pixels along that edge (a logo's letters cut at the bottom row).
    clear = np.pad(a <= CLEAR, RIM, constant_values=True).astype(np.uint8)
    near_clear = cv2.dilate(clear, kernel)[RIM:-RIM, RIM:-RIM] > 0
    return partial & ~(near_solid & near_clear)


def has_translucent_areas(alpha: np.ndarray) -> bool:
    """Whether a target's alpha channel has translucency beyond anti-aliased rims."""
    count = int(translucent_pixels(alpha).sum())
    return count >= max(MIN_PIXELS, MIN_SHARE * np.asarray(alpha).size)


def translucency_wanted(image: np.ndarray, opaque: bool) -> bool:
    """Whether ``auto`` lets every colour's alpha change for this target ([H, W, 4]
    straight RGBA; ``opaque``: fitted over a background, so its alpha is not compared):
    it has translucent areas, or it is continuous-tone."""
    if not opaque and has_translucent_areas(image[..., 3]):
        return True
    return not is_flat_art(image[..., :3])


def colors_kept_opaque(scene: Scene, mode: str, target_translucent: bool) -> list:
    """The colour tensors (Scene.parameters()['colors']) whose alpha must not change, by
    ``mode`` (settings.ALPHA_MODES) and whether the target wants translucency
    (translucency_wanted)."""
    colors = scene.parameters().get("colors", [])
    if mode == "free" or (mode == "auto" and target_translucent):
        return []
    if mode == "fixed":
        return list(colors)
    translucent = _translucent_colors(scene)
    return [c for c in colors if id(c) not in translucent]


def _translucent_colors(scene: Scene) -> set[int]:
    """ids of the colour tensors drawn with an opacity below 1: their own alpha, or the
    fill-opacity, stroke-opacity or opacity of a shape that paints with them."""
    out = set()

    def below_one(t) -> bool:
        return bool((np.asarray(to_numpy(t), np.float64) < 1.0).any())

    for shape in scene.shapes:
        for paint, opacity in ((shape.fill, shape.fill_opacity), (shape.stroke, shape.stroke_opacity)):
            color = getattr(paint, "color", getattr(paint, "colors", None))
            if color is not None and (below_one(opacity) or below_one(shape.opacity)):
                out.add(id(color))
    for color in scene.parameters().get("colors", []):
        if below_one(to_numpy(color).reshape(-1, 4)[:, 3]):
            out.add(id(color))
    return out


def make_opaque(scene: Scene) -> None:
    """Every colour of a generated Scene (a trace, random strokes) made opaque, in place:
    for targets without translucent areas, where ``auto`` keeps opaque colours opaque."""
    import torch

    with torch.no_grad():
        for c in scene.parameters().get("colors", []):
            c.view(-1, 4)[:, 3] = 1.0
