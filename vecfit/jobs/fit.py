"""The job every optimising command ends in: a Scene fitted to a target image, then its
SVG, report and comparison picture written next to each other. `vecfit refine` starts it
from the user's SVG, `vecfit trace` and `vecfit paint` from SVGs of their own making."""
from __future__ import annotations

import dataclasses
import time
import warnings
from pathlib import Path

import numpy as np

from vecfit.errors import VecfitError
from vecfit.fitting.metrics import compare, to_rgb
from vecfit.fitting.result import Result
from vecfit.fitting.settings import Settings
from vecfit.io.colors import fitting_background
from vecfit.io.images import downscaled, read_image
from vecfit.io.report import save_comparison
from vecfit.scene import Scene
from vecfit.scene.arrays import is_tensor
from vecfit.scene.crossings import crossed_subpaths
from vecfit.scene.untangle import untangle
from vecfit.svg.document import SvgDocument
from vecfit.svg.read import read_svg, scene_of
from vecfit.svg.precision import shape_decimals
from vecfit.svg.write import svg_bytes

from .config import loop_settings, output_precision
from .palette import colour_entry, nearest_colour, parse_palette
from .protocol import Outputs, listener
from .report import job_report
from .scoring import judging_samples, refuse_non_finite, render_for_scoring, rendered_rgb, score_written

OPAQUE = 0.999  # a target whose every alpha is at least this is treated as opaque
ASPECT_TOLERANCE = 0.01
MIN_SIDE = 11


# ------------------------------------------------------------------------- target

def load_target(source, return_orientation: bool = False):
    """The target image (a path, or an image itself: vecfit.io.images.image_rgba), upright,
    big enough to be measured: SSIM's Gaussian window is 11 x 11 pixels. With
    ``return_orientation``, (the image, the report's "orientation" entry: read_image's)."""
    a, orientation = read_image(source)
    name = str(source) if isinstance(source, (str, Path)) else "the image given"
    if min(a.shape[:2]) < MIN_SIDE:
        raise VecfitError(f"{name}: the image is too small ({a.shape[1]}x{a.shape[0]} pixels; "
                          f"at least {MIN_SIDE}x{MIN_SIDE})")
    return (a, orientation) if return_orientation else a


def corner_color(image: np.ndarray) -> tuple:
    """The median colour of the four corner patches (5% of each side, at least 1 pixel)."""
    h, w = image.shape[:2]
    ph, pw = max(1, h // 20), max(1, w // 20)
    patches = [image[:ph, :pw], image[:ph, -pw:], image[-ph:, :pw], image[-ph:, -pw:]]
    rgb = np.median(np.concatenate([p.reshape(-1, 4) for p in patches])[:, :3], axis=0)
    return (float(rgb[0]), float(rgb[1]), float(rgb[2]), 1.0)


def background_for(image: np.ndarray, setting: str) -> tuple | None:
    """'auto': transparent for a target with transparency, else its corners' colour."""
    if setting.strip().lower() == "auto":
        return None if float(image[..., 3].min()) < OPAQUE else corner_color(image)
    return fitting_background(setting)


def load_scene_to_fit(svg) -> tuple[Scene, SvgDocument]:
    """The user's SVG (a path, or its text) as a Scene (its warnings shown every time) and
    its document (to write the result into), refused when it has no shapes: what refine,
    edit and retarget start from."""
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        if isinstance(svg, str):
            document = SvgDocument.parse(svg, "the SVG given")
            scene = scene_of(document)
        else:
            scene, document = read_svg(svg)
    if not scene.shapes:
        raise VecfitError(f"{document.name}: the SVG has no shapes to optimise")
    return scene, document


def check_has_size(scene: Scene, svg_path) -> None:
    """Refuses an SVG whose canvas has no positive width and height (refine, edit and
    retarget need one to fit to)."""
    if not (scene.width > 0 and scene.height > 0):
        raise VecfitError(f"{svg_path}: the SVG has no size")


def check_sizes(scene: Scene, target: np.ndarray, svg_path, target_path) -> None:
    h, w = target.shape[:2]
    check_has_size(scene, svg_path)
    a, b = scene.width / scene.height, w / h
    if abs(a - b) > ASPECT_TOLERANCE * max(a, b):
        raise VecfitError(f"{svg_path} is {scene.width:g}x{scene.height:g} but {target_path} is "
                          f"{w}x{h}: their aspect ratios differ")


def generated_scene(document: SvgDocument) -> Scene:
    """The Scene of an SVG that vecfit made (a trace, random strokes): nothing in it
    deserves a warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return scene_of(document)


# --------------------------------------------------------------------------- run

def _not_optimised(scene: Scene, settings: Settings) -> Result:
    """The counts the loop would report for 0 iterations (vecfit.fitting.rates.parameter_kinds:
    the kinds with a positive rate and tensors), and its refusal of a scene without any."""
    if settings.iterations != 0:
        raise VecfitError("a Scene of NumPy arrays cannot be optimised (read it with tensors)")
    counts = {name: sum(int(np.size(t)) for t in tensors) for name, tensors in scene.parameters().items()
              if float(settings.lr.get(name, 0.0)) > 0 and tensors}
    if not counts:
        raise VecfitError("nothing to optimise: the scene has no parameters with a learning rate above 0")
    return Result(parameters=counts)


def cut_crossed_outlines(scene: Scene, keep: set, config: dict, pixels=None) -> int:
    """Outlines that cross themselves, but for those in ``keep`` (drawn so), cut into
    simple loops (vecfit/scene/untangle.py), judged at the decimals the SVG will be written
    with on a ``pixels`` canvas; returns how many were cut."""
    return untangle(scene, keep=keep, decimals=shape_decimals(scene, pixels, output_precision(config)))


def _as_fitted(final_rgb: np.ndarray, target_rgb: np.ndarray, settings: Settings) -> dict:
    """Where the render was blurred before the loss (optimize.target_blur: a scan fitted as
    the sharp drawing that blurs to it), the figures of the result blurred alike against the
    target: what the fit reached. The report's "optimized" compares the sharp result with
    the blurred target, which reads lower however right the lines are."""
    blur = settings.blur_px
    if blur <= 0:
        return {}
    import torch
    from vecfit.fitting.blur import gaussian_blur
    blurred = gaussian_blur(torch.from_numpy(np.ascontiguousarray(final_rgb, np.float32)), blur).numpy()
    return {"as_fitted": {"target_blur": blur, **compare(blurred.astype(final_rgb.dtype), target_rgb)}}


def _traced_corners(scene: Scene, settings: Settings, size: tuple[int, int], background, target_rgb) -> dict | None:
    """A stroke trace's corners before the fit, which cannot add the nodes they need: small
    rings made the polygons they are, corners drawn sharp or as curves rounded where the
    picture is (fitting/fillets.traced_corners), judged on renders of 4 x 4 samples or
    more. None where the scene has no strokes."""
    from vecfit.fitting.fillets import stroked, traced_corners
    if not any(stroked(s) for s in scene.shapes):
        return None
    judged = dataclasses.replace(settings, eval_samples=max(4, settings.eval_samples))
    w, h = size
    return traced_corners(scene, lambda s, seed=0: rendered_rgb(s, w, h, judged, background, seed), target_rgb, size)


def fit_and_write(scene: Scene, document: SvgDocument, target: np.ndarray, config: dict, outputs: Outputs,
                  progress=None, inputs: dict | None = None, hooks=(), keep_alpha=(),
                  generated: bool = False, removed_background: tuple | None = None) -> dict:
    """Optimise ``scene`` (read from ``document``) against ``target`` with the
    ``[optimize]`` settings of ``config``; writes the SVG, the comparison picture and the
    report (last, so a report means a finished run). Returns the report. ``inputs`` are
    extra report entries (a callable value is called when the report is made); ``hooks``
    and ``keep_alpha`` go to the optimisation loop. ``generated``: the Scene is vecfit's own
    (a trace, random strokes), so under ``optimize.alpha = "auto"`` its colours start
    opaque unless the target has translucent areas (vecfit/fitting/opacity.py).
    ``removed_background``: an opaque RGBA fitted over in place of optimize.background and
    never written (trace --remove-background: the shapes fitted over it as over
    transparency)."""
    started = time.perf_counter()
    progress = listener(progress)
    # The report marks a finished run: an old one must not sit beside new outputs if this
    # run dies before it writes its own.
    outputs.forget_report()
    settings = loop_settings(config)  # its device resolved once: the loop, the renders, the report
    drop_background = removed_background is not None
    background = removed_background if drop_background else background_for(target, settings.background)
    palette = parse_palette(settings.palette)
    if palette is not None and palette.auto is None and not drop_background:  # a background written in is a paint too
        background = nearest_colour(background, palette.rgb)
    h, w = target.shape[:2]
    small = downscaled(target, settings.max_size)
    sh, sw = small.shape[:2]
    # Measured at the optimised size: a 12-megapixel photo's full-size renders, SSIM and
    # comparison took a minute and 3 GB around a loop of seconds (--max-size 0: full size).
    target_rgb = to_rgb(small, background)  # (metrics of a transparent target: over white)

    # Rendered bare and composited here (the same arithmetic as the core's background):
    # the alpha then also says whether the shapes cover the canvas.
    initial_image = render_for_scoring(scene, sw, sh, settings)
    initial_rgb = to_rgb(initial_image, background)
    initial = compare(initial_rgb, target_rgb)
    # crossings the user drew stay; those the fit makes (and those a trace's fit gives a
    # sliver's two sides) are cut into simple loops
    drawn_crossed = set() if generated else crossed_subpaths(scene)
    cutouts = config["output"].get("stacking", "stacked") == "cutouts"
    if cutouts:  # refused before the work, not after it
        from vecfit.initial.tracer.cutouts import cutout_problem
        problem = cutout_problem(scene)
        if problem is not None:
            raise VecfitError(f"--stacking cutouts: {document.name}: {problem}")
    simplified = corners = None
    if is_tensor(scene.view):
        import torch
        from vecfit.fitting.loop import Target, optimize
        from vecfit.fitting.opacity import make_opaque
        goal = Target(torch.from_numpy(small), background)
        if generated and settings.alpha == "auto" and not goal.wants_translucency:
            make_opaque(scene)
        if generated:
            corners = _traced_corners(scene, settings, (sw, sh), background, target_rgb)
        progress.start(settings.iterations)
        if palette is None:
            result = optimize(scene, goal, settings, progress=progress, hooks=hooks, keep_alpha=keep_alpha)
        else:  # every paint ends on the palette (vecfit/jobs/palette.py)
            from .palette import optimize_on_palette
            result, used = optimize_on_palette(scene, goal, settings, palette, progress=progress, hooks=hooks,
                                               keep_alpha=keep_alpha)
            if not drop_background:  # auto:N's: one of the N
                background = nearest_colour(background, used / 255.0)
        if settings.simplify > 0 and result.iterations > 0:  # fewer nodes (fitting/simplify.py)
            from vecfit.fitting.simplify import simplify_fitted
            # (judged at simplify_samples where set: strokes' thin lines need more than quick's 2x2;
            # else at 2x2 where their noise is small beside the error: a photo's)
            judge = judging_samples(scene, sw, sh, settings, background, target_rgb)
            judged = dataclasses.replace(settings, eval_samples=judge.samples)
            render_rgb = lambda s, seed=0: rendered_rgb(s, sw, sh, judged, background, seed)  # noqa: E731
            simplified = simplify_fitted(scene, goal, settings, render_rgb, target_rgb, float(settings.simplify),
                                         int(settings.simplify_iterations), hooks, keep_alpha,
                                         rendered=judge.rendered)
            simplified["judged_samples"] = judge.samples  # N of the N x N samples a pixel the joins were judged at
    else:
        progress.start(0)
        result = _not_optimised(scene, settings)
    untangled = cut_crossed_outlines(scene, drawn_crossed, config, (w, h))
    if simplified is not None:  # subpaths the picture does not need: the cuts' slivers, pieces under others
        from vecfit.fitting.simplify import drop_unseen
        simplified["unseen"] = drop_unseen(scene, lambda s, w_, h_: rendered_rgb(s, w_, h_, judged, background),
                                           target_rgb)
    if result.iterations == 0:  # nothing moved: the same picture and figures
        final_image, final_rgb, final = initial_image, initial_rgb, dict(initial)
    else:
        final_image = render_for_scoring(scene, sw, sh, settings)
        final_rgb = to_rgb(final_image, background)
        final = compare(final_rgb, target_rgb)
    refuse_non_finite(final)

    # The SVG must look like what was optimised: where the shapes leave the canvas
    # uncovered, the background is written in as a first rect.
    covered = float(final_image[..., 3].min()) >= OPAQUE
    svg_background = background if background is not None and not covered and not drop_background else None
    written = svg_bytes(scene, document, background=svg_background, precision=output_precision(config),
                        pixels=(w, h))
    cut = None
    if cutouts:  # the drawing as pieces that do not overlap, scored as written
        from vecfit.initial.tracer.cutouts import cut_out
        written, cut = cut_out(written, (w, h), gap_filler=bool(config["output"].get("gap_filler")),
                               precision=output_precision(config), name=str(document.name))
        cut = {**cut.as_dict(), **score_written(written, (sw, sh), target_rgb, background, settings)}
    layers = None
    if config["output"].get("group_by", "none") != "none":
        from vecfit.svg.layers import group_by_colour
        written, layers = group_by_colour(written)
        for line in layers["warnings"]:
            warnings.warn(line)
    outputs.keep_svg(written)
    if outputs.comparison is not None:
        save_comparison(outputs.comparison, target_rgb, initial_rgb, final_rgb)
    outcome = {
        **_as_fitted(final_rgb, target_rgb, settings),  # a blurred target (a scan): the figures the fit saw
        **({} if corners is None else {"traced_corners": corners}),  # a stroke trace's corners and rings before the fit
        "simplified": simplified,  # nodes dropped after the fit (fitting/simplify.py), or None
        "untangled_outlines": untangled,  # outlines the fit made cross themselves, cut into simple loops
        **({} if cut is None else {"cutouts": cut}),  # --stacking cutouts: pieces, chains, and the file's score
        **({} if palette is None and layers is None else {"colours": colour_entry(written, palette, layers)}),
    }
    return outputs.keep_report(job_report(
        config, settings, outputs, result, started=started, inputs=inputs or {},
        canvas={"size": [w, h], "optimized_size": [sw, sh]},  # the metrics and the comparison picture are at this size
        background=background, initial=initial, optimized=final, shapes=len(scene.shapes), written=written,
        outcome=outcome))
