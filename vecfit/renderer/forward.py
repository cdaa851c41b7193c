"""The compiled core's forward pass on a packed Scene, without torch: the image size, the
packing checked for the core, and the call. vecfit.renderer.raster builds the
differentiable render on these; ``render_numpy`` renders a Scene of NumPy arrays
(vecfit.scene.arrays.numpy_arrays) where no gradient is wanted, e.g. a trace written as
it is, which then never imports torch."""
from __future__ import annotations

import math

import numpy as np

from vecfit import _core
from vecfit.errors import NonFiniteScene, VecfitError
from vecfit.limits import MAX_PIXELS
from vecfit.scene import Scene
from vecfit.scene.arrays import to_numpy
from vecfit.scene.ops import ops_for

from . import device as devices
from .options import RenderOptions, background_rgba
from .pack import pack_scene
from .stopwatch import add_core_phases, phase


def output_size(scene: Scene, width: int | None, height: int | None) -> tuple[int, int]:
    """Pixel size to render at: the scene's own size, or the given width and/or height
    (given only one, the other keeps the scene's aspect ratio, rounded to a pixel).
    VecfitError for a scene without a finite positive size, or a size over MAX_PIXELS."""
    sw, sh = float(scene.width), float(scene.height)
    if not (0 < sw < math.inf and 0 < sh < math.inf):
        raise VecfitError(f"the canvas size {sw:g} x {sh:g} is not a positive finite size")
    w = float(sw if width is None and height is None else width if width is not None else height * sw / sh)
    h = float(sh if width is None and height is None else height if height is not None else width * sh / sw)
    if math.isfinite(w * h):
        w, h = max(1.0, float(round(w))), max(1.0, float(round(h)))  # floats: printed with :g
    if not w * h <= MAX_PIXELS:
        raise VecfitError(f"{w:.10g} x {h:.10g} pixels is too large to render "
                          f"(at most {MAX_PIXELS // 1_000_000} million pixels)")
    return int(w), int(h)


FLOAT_INPUTS = ("points", "point_widths", "ellipses", "draw_params", "paint_params", "stop_offsets",
                "stop_colors", "layer_opacity")


def _core_render(options, device: int, structure: dict, floats, keep: bool = False):
    """The core's forward pass on the packed arrays (``options``: the core's
    RenderOptions): (the arrays it saw, image), and with ``keep`` the scene as the core
    prepared it, for the backward pass of these arrays."""
    scene = dict(structure)
    for name, t in zip(FLOAT_INPUTS, floats):
        scene[name] = to_numpy(t)
    try:
        with phase("call forward"):
            if keep:
                image, prepared = _core.render_keeping(scene, options, device)
            else:
                image = _core.render(scene, options, device)
        add_core_phases()
        return (scene, image, prepared) if keep else (scene, image)
    except ValueError as e:  # the core refused the scene (e.g. layers nested too deeply)
        raise VecfitError(str(e)) from None
    except RuntimeError as e:  # the GPU failed (out of memory, driver)
        raise VecfitError(f"rendering on {devices.device_name(device)} failed: {e}") from None


def packed_for_core(scene: Scene, width: int, height: int) -> tuple[dict, list]:
    """The scene packed at width x height: the integer tables (structure) and the float
    arrays in FLOAT_INPUTS order (differentiable), checked to be finite."""
    with phase("pack"):
        arrays = pack_scene(scene, width, height).arrays()
    ops = ops_for(scene.view)
    floats = [ops.f32(arrays[name]) for name in FLOAT_INPUTS]
    check_finite(floats)
    return {k: v for k, v in arrays.items() if k not in FLOAT_INPUTS}, floats


def check_finite(floats) -> None:
    """NonFiniteScene unless every float array (FLOAT_INPUTS order) is finite."""
    for name, value in zip(FLOAT_INPUTS, floats):
        if not np.isfinite(to_numpy(value)).all():
            raise NonFiniteScene(f"the scene has non-finite values ({name})")


def render_numpy(scene: Scene, width: int | None = None, height: int | None = None, *, samples: int = 2,
                 seed: int = 0, background=None, threads: int | None = None, device: str = "cpu") -> np.ndarray:
    """``scene`` (of NumPy arrays, or tensors) rendered in "mc" mode with the box filter, as
    vecfit.renderer.raster.render renders it with those settings: an [H, W, 4] float32
    array of straight RGBA. Clip paths, masks and filters need the layered renderer
    (torch): a Scene with them is refused."""
    width, height = output_size(scene, width, height)
    if scene.has_effects():
        raise VecfitError("a scene with clip paths, masks or filters renders with vecfit.render")
    options = RenderOptions(width, height, samples=int(samples), seed=int(seed), threads=int(threads or 0),
                            background=background_rgba(background))
    structure, floats = packed_for_core(scene, width, height)
    return _core_render(options.core(), devices.resolve(device), structure, floats)[1]
