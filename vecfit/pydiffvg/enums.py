"""diffvg's enumerations, with diffvg's names and values (OutputType is pydiffvg's)."""
from __future__ import annotations

from enum import IntEnum


class OutputType(IntEnum):
    color = 1
    sdf = 2


class FilterType(IntEnum):
    box = 0
    tent = 1
    parabolic = 2
    hann = 3


# vecfit's name for each pixel filter (diffvg's "radial parabolic" is separable: the
# product of (1 - (x/r)^2) along x and y).
FILTER_NAMES = {FilterType.box: "box", FilterType.tent: "tent",
                FilterType.parabolic: "parabolic", FilterType.hann: "hann"}


class ShapeType(IntEnum):
    circle = 0
    ellipse = 1
    path = 2
    rect = 3


class ColorType(IntEnum):
    constant = 0
    linear_gradient = 1
    radial_gradient = 2
