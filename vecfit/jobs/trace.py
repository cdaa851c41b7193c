"""The trace job: a raster image traced into an SVG (vecfit.initial.tracer), then refined against
it with the same loop as `vecfit refine` (vecfit.jobs.fit.fit_and_write)."""
from __future__ import annotations

import contextlib
import dataclasses
import warnings

import numpy as np

from vecfit.errors import VecfitError, VecfitWarning
from vecfit.initial.tracer import TraceSettings, trace_image
from vecfit.initial.tracer.background import border_colour, corners_rival, without_background
from vecfit.io.colors import fitting_background
from vecfit.io.compositing import composite
from vecfit.scene import Rect, Solid
from vecfit.scene.arrays import numpy_arrays
from vecfit.svg.numbers import hex_color

from .config import settings_of
from .fit import OPAQUE, fit_and_write, generated_scene, load_target
from .palette import parse_palette, traced_on_palette
from .protocol import Inputs, Outputs, listener


def run(inputs: Inputs, config: dict, outputs: Outputs, progress=None) -> dict:
    """`vecfit trace`: trace the image, refine the trace (optimize.iterations 0 writes the
    trace as it is, with its report), write SVG, report and comparison."""
    inputs.need("trace", "image")
    target_path, progress = inputs.name("image"), listener(progress)
    outputs.check_against(inputs)
    target, orientation = load_target(inputs.image, return_orientation=True)
    settings = settings_of(TraceSettings, config["trace"], seed=config["optimize"]["seed"])
    palette = parse_palette(config["optimize"]["palette"])
    if palette is not None and palette.auto is not None and config["optimize"]["iterations"] == 0:
        # written as traced: N colour classes, each painted flat (the fit would otherwise
        # start from the full trace and fit N shared colours: vecfit/jobs/palette.py)
        settings = dataclasses.replace(settings, colors=min(settings.colors, palette.auto), palette=True)
    traced_image, removed = target, None
    if settings.remove_background:
        traced_image, removed = _background_removed(config, target, progress)
    progress.status(f"tracing {target_path} ({target.shape[1]}x{target.shape[0]})")
    if palette is None or palette.auto is not None:
        traced = trace_image(traced_image, settings)
    else:
        traced = traced_on_palette(traced_image, settings, palette.colors)
    progress.status(f"traced: {traced.paths} paths, {traced.segments} segments, {traced.colors} colours "
                    f"in {traced.seconds:.1f} s")
    # Written as it is, the trace is read as NumPy: rendered and written without torch.
    with numpy_arrays() if config["optimize"]["iterations"] == 0 else contextlib.nullcontext():
        scene = generated_scene(traced.document)
    if not scene.shapes:
        raise VecfitError(f"{target_path}: nothing to trace (the image is fully transparent)")
    # The tracer's backdrop (an opaque rect past the canvas's edges) stays opaque, so the
    # canvas stays covered; the regions above may turn translucent (blending neighbours is
    # worth ~2 dB on photos).
    backdrop = [s.fill.color for s in scene.shapes[:1]
                if isinstance(s.geometry, Rect) and isinstance(s.fill, Solid)]
    hooks = ()
    if settings.style != "fills":
        # strokes' cubics kept from folding back (vecfit/fitting/tame.py); the traced inks and
        # paper (flat, snapped to black and white) kept: refined against a scan, they took
        # its blur and noise (paper #fafafa, ink 3% translucent: 1.5 dB of 28 on a scan)
        from vecfit.fitting.tame import tame_stroke_cubics
        hooks = (tame_stroke_cubics,)
        # no half-size start (coarse): there a line's width and place are a half-pixel guess;
        # joins judged on 4 x 4 samples (refine.toml, simplify_samples)
        config = {**config, "optimize": {**config["optimize"], "alpha": "fixed", "coarse": 0.0,
                                         "simplify_samples": config["optimize"]["simplify_samples"] or 4,
                                         "target_blur": _line_art_blur(config["optimize"], target),
                                         "lr": {**config["optimize"]["lr"], "colors": 0.0}}}
    return fit_and_write(scene, traced.document, target, config, outputs, progress, keep_alpha=backdrop, generated=True,
                         removed_background=removed, hooks=hooks,
                         inputs={"command": "trace", "target": str(target_path), "orientation": orientation,
                                 "style": settings.style,
                                 "trace": {"paths": traced.paths, "segments": traced.segments,
                                           "colors": traced.colors, "seconds": traced.seconds,
                                           "strokes": traced.strokes, "warnings": traced.warnings},
                                 **({} if removed is None else {"removed_background": hex_color(removed)})})


def _line_art_blur(optimize: dict, target: np.ndarray) -> float:
    """optimize.target_blur for line art: "auto" is the target's own blur (a scan's;
    about 0 for a render: vecfit/fitting/blur.py) in pixels of the image the fit sees
    (optimize.max_size), rounded to 0.05 px; a number is taken as given."""
    if optimize["target_blur"] != "auto":
        return optimize["target_blur"]
    from vecfit.fitting.blur import BLUR_FLOOR, estimate_blur
    h, w = target.shape[:2]
    scale = min(1.0, optimize["max_size"] / max(h, w)) if optimize["max_size"] else 1.0
    sigma = estimate_blur(composite(target, (1.0, 1.0, 1.0))) * scale
    return round(round(sigma / 0.05) * 0.05, 2) if sigma >= BLUR_FLOOR else 0.0


def _background_removed(config: dict, target, progress):
    """trace --remove-background (initial/tracer/background.py): the image to trace (the
    background transparent) and the colour removed (RGBA, fitted over and not written;
    None, and the image as it is, for a target that already has transparency)."""
    if float(target[..., 3].min()) < OPAQUE:
        progress.status("remove-background: the image already has transparency; nothing removed")
        return target, None
    given = config["optimize"]["background"].strip().lower()
    if given in ("auto", "none"):
        colour = border_colour(target[..., :3])
        rival = corners_rival(target[..., :3], colour)
        if rival is not None:
            warnings.warn(f"remove-background: the image's border is mostly {hex_color(colour)}, which is "
                          f"removed, but two of its corners are {hex_color(rival)}; if that is the page, "
                          f"give --background {hex_color(rival)}", VecfitWarning)
    else:
        colour = np.array(fitting_background(given)[:3])
    return without_background(target, colour), (*map(float, colour), 1.0)
