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
from vecfit.scene import LinearGradient, RadialGradient, Scene
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


def renders_without_torch(scene: Scene) -> bool:
    """Whether render_numpy draws ``scene`` as vecfit.render does, so that a command need
    not import torch: not with clip paths, masks or filters (composited in torch,
    renderer/layers.py), dashes (cut in torch, scene/dashes.py), gradients, rotations or
    skews. NumPy packs the float32 values torch packs where every matrix is axis-aligned:
    each entry of a product then sums at most two non-zero terms, which neither library's
    order changes. A 3x3 product with rotations sums three, in another order in each, and
    a gradient's inverse matrix comes from another LAPACK than MKL's: either moved values
    by their last bit in 1 in 6 of the real-world SVGs, and pixels in 4 of 357. One such
    difference remains: a stroke's width is scaled by a square root, which torch takes
    with MKL's vector sqrt, off by the last bit for 1 in 5 float32 values (NumPy's is
    correctly rounded), and a pixel's byte can then differ (tiger: in 6 of 54 renders over
    27 sizes; none in the real-world SVGs)."""
    if scene.has_effects():
        return False
    matrices = [scene.view] + [g.transform for g in scene.groups] + [s.transform for s in scene.shapes]
    if any(to_numpy(m)[0, 1] != 0 or to_numpy(m)[1, 0] != 0 for m in matrices):
        return False
    return not any(s.dash_array is not None or isinstance(s.fill, (LinearGradient, RadialGradient))
                   or isinstance(s.stroke, (LinearGradient, RadialGradient)) for s in scene.shapes)


_D = RenderOptions  # (its defaults)


def render_numpy(scene: Scene, width: int | None = None, height: int | None = None, *,
                 samples: int = _D.samples, mode: str = _D.mode, filter: str = _D.filter,
                 filter_radius: float = _D.filter_radius, seed: int = _D.seed, background=_D.background,
                 threads: int | None = _D.threads, device: str = "cpu") -> np.ndarray:
    """``scene`` (of NumPy arrays, or tensors) rendered as vecfit.renderer.raster.render
    renders it with the same settings, without a gradient: an [H, W, 4] float32 array of
    straight RGBA. Clip paths, masks and filters need the layered renderer (torch): a
    Scene with them is refused (``scene.has_effects()`` says which)."""
    width, height = output_size(scene, width, height)
    if scene.has_effects():
        raise VecfitError("a scene with clip paths, masks or filters renders with vecfit.render")
    options = RenderOptions(width, height, samples=int(samples), mode=mode, filter=filter,
                            filter_radius=float(filter_radius), seed=int(seed), threads=int(threads or 0),
                            background=background_rgba(background))
    structure, floats = packed_for_core(scene, width, height)
    return _core_render(options.core(), devices.resolve(device), structure, floats)[1]
