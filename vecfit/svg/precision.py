"""How many decimals a written coordinate needs.

A coordinate is written to a hundredth of a pixel of the canvas up to 1,024 px on its
longer side, and to the same share of the canvas beyond (a 4,096-px canvas: 0.04 px):
finer digits change nothing a renderer shows, and they are most of a refined file's bytes.
A shape drawn through a scale (a 24-unit icon shown at 512 px, a transform) needs as many
more decimals as its units are larger than pixels. ``--precision N`` writes N decimals
everywhere instead.
"""
from __future__ import annotations

import math

import numpy as np

from vecfit.names import MAX_DECIMALS
from vecfit.scene import Scene
from vecfit.scene.arrays import to_numpy
from vecfit.scene.placement import pixel_scales

STEP_PIXELS = 0.01     # the written step, in pixels ...
STEP_CANVAS = 1024     # ... of a canvas up to this long side; beyond, in proportion


def decimals_for(pixels_per_unit: float, long_side: float) -> int:
    """Decimals that place a coordinate, in units of ``pixels_per_unit`` pixels each, to the
    step this module's docstring gives on a canvas of ``long_side`` pixels."""
    if not (math.isfinite(pixels_per_unit) and pixels_per_unit > 0):
        return MAX_DECIMALS
    step = STEP_PIXELS * max(1.0, long_side / STEP_CANVAS) / pixels_per_unit
    return int(min(max(math.ceil(-math.log10(step) - 1e-9), 0), MAX_DECIMALS))


def shape_decimals(scene: Scene, pixels: tuple[int, int] | None = None,
                   precision: int | None = None) -> list[int]:
    """Decimals for each of ``scene.shapes``' coordinates: ``precision`` where given, else
    from each shape's scale on a ``pixels`` (width, height) canvas (default: the Scene's
    own size)."""
    if precision is not None:
        return [int(precision)] * len(scene.shapes)
    width, height = pixels if pixels is not None else (scene.width, scene.height)
    if not scene.shapes:
        return []
    side = max(float(width), float(height))
    return [decimals_for(float(s), side) for s in pixel_scales(scene, width, height)]


def root_decimals(scene: Scene, pixels: tuple[int, int] | None = None, precision: int | None = None) -> int:
    """Decimals for coordinates in the root's user space (clip paths' and masks' shapes,
    placed by what uses them, are written at this precision)."""
    if precision is not None:
        return int(precision)
    width, height = pixels if pixels is not None else (scene.width, scene.height)
    view = np.asarray(to_numpy(scene.view), np.float64)
    sx, sy = width / max(scene.width, 1e-12), height / max(scene.height, 1e-12)
    det = abs(view[0, 0] * view[1, 1] - view[0, 1] * view[1, 0]) * sx * sy
    return decimals_for(math.sqrt(det), max(float(width), float(height)))
