"""pydiffvg on vecfit: diffvg's Python API (``import pydiffvg``) over vecfit's renderer.

Code written for diffvg's ``pydiffvg`` runs unchanged: the same classes, functions,
argument orders and defaults (see README "Coming from diffvg"). What differs, and why:

- Rendering is vecfit's: exact curves, SVG-correct strokes (the stroke of a diffvg shape
  is every point within ``stroke_width``, i.e. round caps and joins), and straight
  (not premultiplied) RGBA out, as diffvg gives.
- ``num_samples_x`` and ``num_samples_y`` may differ in diffvg; vecfit samples N x N per
  pixel with N the larger of the two. ``use_prefiltering=True`` is vecfit's analytical
  mode at one sample per pixel. The box filter always covers exactly the pixel (its
  radius is ignored); tent, parabolic and Hann filters use the radius (at least 0.5).
- The filter radius's gradient (taken only when the radius requires grad): in Monte Carlo
  mode the core's estimate of the filtered image's derivative, from samples of its own
  (one more pass); in the analytical mode a central difference of two more renders.
  A pixel gathers its N x N samples from the filter's whole support, where diffvg splats
  each sample onto every pixel centre within the radius: a filter several pixels wide
  averages N^2 samples here and about (2r)^2 N^2 there, so its image is noisier at few
  samples (apps/optimize_pixel_filter.py reaches the target's radius on both, but its
  loss, with new samples each step, stays near 0.6x its start here).
- ``RenderFunction.render_grad`` (the per-pixel translation gradient) is a central
  difference of the image over a small translation of the scene (five renders).
- ``background_image`` is composited under the filtered image per pixel (diffvg does it
  per sample; the same for the box filter).
- ``svg_to_scene`` and ``save_svg`` are vecfit's reader and a writer of its own: they keep
  ellipses, rect positions and radial gradients that diffvg's lose (see pydiffvg.svg).
- ``OutputType.sdf`` (H x W x 1, or N x 1 at ``eval_positions``) is the signed distance
  to the nearest boundary of any group's fill or stroke, negative inside one, in canvas
  units, from vecfit's analytical coverage (see pydiffvg.sdf); ``eval_positions`` takes
  one small render per point (hundreds of points, not millions).
- Colour output at ``eval_positions`` (N x 4) is the colour at each point itself (a
  1 x 1 analytical render of the scene magnified 1000 times about it; see
  pydiffvg.points); ``background_image`` does not apply there.
"""
from __future__ import annotations

from .device import get_device, get_use_gpu, set_device, set_use_gpu
from .enums import ColorType, FilterType, OutputType, ShapeType
from .image import imwrite
from .render import RenderFunction, set_print_timing
from .shapes import (Circle, Ellipse, LinearGradient, Path, PixelFilter, Polygon, RadialGradient, Rect,
                     ShapeGroup, from_svg_path)
from .svg import save_svg, svg_to_scene

__all__ = ["Circle", "ColorType", "Ellipse", "FilterType", "LinearGradient", "OutputType", "Path",
           "PixelFilter", "Polygon", "RadialGradient", "Rect", "RenderFunction", "ShapeGroup", "ShapeType",
           "from_svg_path", "get_device", "get_use_gpu", "imwrite", "save_svg", "set_device",
           "set_print_timing", "set_use_gpu", "svg_to_scene"]
