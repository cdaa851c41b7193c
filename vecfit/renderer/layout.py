"""The layout of the core's scene arrays, as the core defines it (csrc/scene/scene.h).

Read once from the compiled core (``_core.layout()``), so that Python keeps no copy of
it: the enums the integer tables hold, under the names the packer uses, and ``COLUMNS``,
the row width of every table a scene dict passed to the core holds (by its key).
"""
from __future__ import annotations

from vecfit import _core

_LAYOUT = _core.layout()

SHAPE_PATH: int = _LAYOUT["shape_kinds"]["path"]
SHAPE_ELLIPSE: int = _LAYOUT["shape_kinds"]["ellipse"]
DRAW_FILL: int = _LAYOUT["draw_kinds"]["fill"]
DRAW_STROKE: int = _LAYOUT["draw_kinds"]["stroke"]
FILL_RULES: dict[str, int] = dict(_LAYOUT["fill_rules"])
CAPS: dict[str, int] = dict(_LAYOUT["caps"])
JOINS: dict[str, int] = dict(_LAYOUT["joins"])
PAINT_SOLID: int = _LAYOUT["paint_kinds"]["solid"]
PAINT_LINEAR: int = _LAYOUT["paint_kinds"]["linear"]
PAINT_RADIAL: int = _LAYOUT["paint_kinds"]["radial"]
COLUMNS: dict[str, int] = dict(_LAYOUT["columns"])

__all__ = ["SHAPE_PATH", "SHAPE_ELLIPSE", "DRAW_FILL", "DRAW_STROKE", "FILL_RULES", "CAPS", "JOINS",
           "PAINT_SOLID", "PAINT_LINEAR", "PAINT_RADIAL", "COLUMNS"]
