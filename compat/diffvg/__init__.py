"""``import diffvg``: the enumerations diffvg's compiled module offers to Python scripts
(FilterType, ShapeType, ColorType), from vecfit.pydiffvg. There is no diffvg core here:
rendering goes through ``pydiffvg.RenderFunction``."""
from vecfit.pydiffvg.enums import ColorType, FilterType, OutputType, ShapeType

__all__ = ["ColorType", "FilterType", "OutputType", "ShapeType"]
