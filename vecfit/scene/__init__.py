"""The Scene and its geometry: plain data of torch tensors, below the renderer and the SVG
reader and writer, which both speak it. ``model`` holds the types, ``geometry`` a shape's
own-space geometry, ``placement`` where shapes land on a canvas, ``summary`` what
`vecfit info` lists, ``arrays`` where the floats are made (tensors, or NumPy arrays for
a reading without torch)."""
from .model import (BLEND_MODES, CUBIC, LINE, QUADRATIC, Circle, ClipPath, Ellipse, Filter, FilterStep,
                    Geometry, Group, LinearGradient, Mask, Paint, Path, RadialGradient, Rect, Scene, Shape,
                    Solid, as_tensor, identity)

__all__ = ["BLEND_MODES", "CUBIC", "LINE", "QUADRATIC", "Circle", "ClipPath", "Ellipse", "Filter", "FilterStep",
           "Geometry", "Group", "LinearGradient", "Mask", "Paint", "Path", "RadialGradient", "Rect", "Scene",
           "Shape", "Solid", "as_tensor", "identity"]
