"""`vecfit edit` (Li et al. 2020, section 6.2): an edit made on the raster render of an SVG
brought back into the SVG. The SVG's own parameters are fitted to the edited image with
the shared loop, the changed region weighted in the loss and a penalty on moving the
parameters that act only outside it; the SVG keeps its elements, ids and groups."""
from __future__ import annotations

import math
import time

import numpy as np
import torch

from vecfit.editing.mask import changed_region, grown, load_mask
from vecfit.editing.settings import EditSettings
from vecfit.errors import VecfitError
from vecfit.fitting.anchor import acting_on, anchors
from vecfit.fitting.loop import Target, optimize
from vecfit.fitting.metrics import compare, seen, to_rgb
from vecfit.fitting.rates import learning_rate_scales
from vecfit.io.images import downscaled, downscaled_weight
from vecfit.io.report import error_map, panels_image, save_panels
from vecfit.scene import Scene
from vecfit.scene.crossings import crossed_subpaths
from vecfit.svg.write import svg_bytes

from .config import loop_settings, output_precision, settings_of
from .fit import background_for, check_has_size, cut_crossed_outlines, load_scene_to_fit, load_target
from .protocol import Inputs, Outputs, listener
from .report import job_report
from .scoring import refuse_non_finite, render_for_scoring

MOVED_PX = 0.1        # an element counts as changed when a length moved this many pixels
RECOLOURED = 1.5 / 255  # ... or a colour channel more than a step of #rrggbb


def fit_canvas(scene: Scene, image: np.ndarray, svg_path, image_path) -> None:
    """The image must be the SVG's canvas at some scale (to a pixel either way). The scene's
    canvas is then set to the image's size at one scale, taken from the longer side: a
    renderer asked for a width rounds the height (resvg up, `vecfit render` to the
    nearest), and fitting the image stretched to the canvas would move every shape by up
    to half a pixel. The written SVG keeps its own size."""
    h, w = image.shape[:2]
    check_has_size(scene, svg_path)
    expected_h = scene.height * w / scene.width
    expected_w = scene.width * h / scene.height
    if abs(h - expected_h) > 1 and abs(w - expected_w) > 1:
        raise VecfitError(f"{image_path} is {w}x{h} pixels, which is not the canvas of {svg_path} "
                          f"({scene.width:g}x{scene.height:g}) at any scale (at width {w} it would "
                          f"be {w}x{round(expected_h)})")
    scale = w / scene.width if scene.width >= scene.height else h / scene.height
    scene.width, scene.height = w / scale, h / scale




def region_psnr(result: np.ndarray, target: np.ndarray, region: np.ndarray) -> float | None:
    """PSNR (dB) over the pixels of ``region`` (None where it has none; inf for a match)."""
    if not region.any():
        return None
    mse = float(np.mean((result[region] - target[region]) ** 2))
    return math.inf if mse == 0 else 10 * math.log10(1 / mse)


def changed_elements(scene: Scene, before: dict, width: int, height: int) -> list[dict]:
    """The shapes whose values moved: their element, the largest move of a length in
    pixels of the full-size image and the largest change of a colour channel (0-255)."""
    units = learning_rate_scales(scene, width, height)  # units per pixel
    out = []
    for shape in scene.shapes:
        moved = recoloured = 0.0
        for kind, tensors in Scene(scene.width, scene.height, [shape]).parameters().items():
            for t in tensors:
                if id(t) not in before:
                    continue
                delta = float((t.detach() - before[id(t)]).abs().max()) if t.numel() else 0.0
                if kind == "colors":
                    recoloured = max(recoloured, delta)
                elif id(t) in units:
                    moved = max(moved, delta / units[id(t)])
        if moved > MOVED_PX or recoloured > RECOLOURED:
            out.append({"element": shape.source, "moved_px": round(moved, 3),
                        "color_change": round(recoloured * 255, 2)})
    return out


def run(inputs: Inputs, config: dict, outputs: Outputs, progress=None) -> dict:
    """`vecfit edit`: fit the SVG (inputs.svg) to the edited render (inputs.image), changing
    as little as it can outside the changed region (computed, or inputs.mask, a PNG where
    white marks it). Writes the SVG, the comparison picture (original | edited | result |
    difference) and the report (last)."""
    started = time.perf_counter()
    inputs.need("edit", "image", "svg")
    edited_path, svg_path, mask = inputs.name("image"), inputs.name("svg"), inputs.mask
    progress = listener(progress)
    outputs.check_against(inputs)
    outputs.forget_report()
    target, orientation = load_target(inputs.image, return_orientation=True)
    scene, document = load_scene_to_fit(inputs.svg)
    fit_canvas(scene, target, svg_path, edited_path)
    edit = settings_of(EditSettings, config["edit"])
    settings = loop_settings(config)  # its device resolved once: the loop, the renders, the report
    kinds = [k for k, v in scene.parameters().items() if v and settings.lr.get(k, 0) > 0]
    if not kinds:
        raise VecfitError(f"{svg_path}: nothing to optimise (no parameter kind has a learning rate above 0)")
    background = background_for(target, settings.background)
    h, w = target.shape[:2]

    original_image = render_for_scoring(scene, w, h, settings)
    if mask is not None:
        region = load_mask(mask, (w, h))
    else:
        region = changed_region(seen(original_image, background), seen(target, background),
                                edit.threshold, edit.min_area, edit.grow)
    if not region.any():
        raise VecfitError(f"{edited_path} does not differ from the render of {svg_path}"
                          + (f" inside {mask}" if mask is not None else
                             f" (no pixel changed by more than {edit.threshold:g}): nothing to edit"))

    # Outside the changed region the fit aims at vecfit's own render of the SVG, not at the
    # edited image: the two renderers' anti-aliasing differs there (tiger: 36 dB between
    # vecfit's render and resvg's of the same SVG), and fitting that difference moved every
    # stroke's width and outline (274 of tiger's 303 paths changed), which resvg then drew
    # unlike the original on 92% of the error's pixels. Where nothing was edited, nothing
    # should move.
    aimed = np.where(region[..., None], target, original_image).astype(np.float32)
    small = downscaled(aimed, settings.max_size)
    sh, sw = small.shape[:2]
    weight = downscaled_weight(np.where(region, edit.changed_weight, 1.0).astype(np.float32), (sh, sw))
    region_small = downscaled_weight(region.astype(np.float32), (sh, sw)) > 0
    reach = max(0, round(edit.reach * sh / h))
    free = acting_on(scene, grown(region_small, reach), kinds, samples=settings.samples,
                     seed=settings.seed, threads=settings.threads, background=background,
                     device=settings.device)
    penalty = anchors(scene, free, kinds, edit.anchor, edit.anchor_free, edit.anchor_free_colors, sw, sh,
                      3 if background is not None else 4)
    before = {id(t): t.detach().clone() for k in kinds for t in scene.parameters()[k]}

    goal = Target(torch.from_numpy(small), background, torch.from_numpy(weight))
    drawn_crossed = crossed_subpaths(scene)  # the user's crossings stay; the fit's are cut
    progress.start(settings.iterations)
    result = optimize(scene, goal, settings, progress=progress, penalty=penalty)
    final_image = original_image if result.iterations == 0 else render_for_scoring(scene, w, h, settings)

    target_rgb = to_rgb(target, background)
    original_rgb, final_rgb = to_rgb(original_image, background), to_rgb(final_image, background)
    initial, final = compare(original_rgb, target_rgb), compare(final_rgb, target_rgb)
    refuse_non_finite(final)
    changed = changed_elements(scene, before, w, h)
    # after the picture and the changes are measured: cutting a crossed outline into
    # simple loops draws the same (less slivers under a square pixel)
    cut_crossed_outlines(scene, drawn_crossed, config, (w, h))

    # The SVG keeps its elements: no background rect is added (an uncovered canvas stays
    # transparent, which over the background looks as optimised).
    written = svg_bytes(scene, document, precision=output_precision(config), pixels=(w, h))
    outputs.keep_svg(written)
    if outputs.comparison is not None:
        save_panels(outputs.comparison, panels_image(
            [original_rgb, target_rgb, final_rgb, error_map(final_rgb, target_rgb)]))
    return outputs.keep_report(job_report(
        config, settings, outputs, result, started=started,
        inputs={"command": "edit", "target": str(edited_path),
                "orientation": orientation,  # the edited image's EXIF orientation, applied
                "init": str(svg_path), "mask": None if mask is None else str(mask)},
        canvas={"size": [w, h], "optimized_size": [sw, sh]}, background=background,
        initial=initial, optimized=final, shapes=len(scene.shapes), written=written,
        measured={
            "changed_region": {"pixels": int(region.sum()), "fraction": float(region.mean()),
                               "from": "mask" if mask is not None else "renders"},
            "psnr_inside": {"before": region_psnr(original_rgb, target_rgb, region),
                            "after": region_psnr(final_rgb, target_rgb, region)},
            "psnr_outside": {"before": region_psnr(original_rgb, target_rgb, ~region),
                             "after": region_psnr(final_rgb, target_rgb, ~region)},
            "elements": {"total": len(scene.shapes), "changed": changed,
                         "unchanged": len(scene.shapes) - len(changed)},
            "parameters_free": penalty.free,        # act on the changed region
            "parameters_anchored": penalty.anchored,  # held by the penalty
        }))
