"""`vecfit retarget` (Li et al. 2020, section 6.2): content-aware resizing of a vector
graphic. The SVG's render (at ``work_size``) is seam-carved to the new size; the seams are
divided into rounds, and each round moves the SVG's points as its seams move the pixels
under them (a point's x goes left by the seams removed to its left in its row), narrows
the canvas and fits the points, colours and widths to that round's carved image with the
shared loop. The SVG keeps every element, id and group; its width, height and viewBox
take the new size.

The seams are found on the render of the input, carved one after another (each on what
the previous left), not on each round's fitted render: the targets stay crisp, and a
round's fit cannot steer later seams into content it blurred."""
from __future__ import annotations

import dataclasses
import re
import time

import cv2
import numpy as np
import torch

from vecfit.editing.points import carve_points
from vecfit.editing.seams import carve, foreground, remove_seam
from vecfit.editing.settings import RetargetSettings
from vecfit.errors import VecfitError
from vecfit.fitting.loop import Target, optimize
from vecfit.fitting.metrics import compare, seen, to_rgb
from vecfit.fitting.result import joined
from vecfit.io.report import save_panels, side_by_side
from vecfit.scene.crossings import crossed_subpaths
from vecfit.svg.write import svg_bytes

from .config import loop_settings, output_precision, settings_of
from .fit import MIN_SIDE, background_for, check_has_size, cut_crossed_outlines, load_scene_to_fit
from .protocol import Inputs, Outputs, listener
from .report import job_report
from .scoring import refuse_non_finite, render_for_scoring

_SIZE = re.compile(r"\s*(\d+(?:\.\d*)?|\.\d+)\s*(%|px)?\s*$")


def parse_size(text, native: float, name: str) -> float:
    """'120' or '120px' (pixels) or '65%' (of ``native``) -> pixels."""
    m = _SIZE.match(str(text))
    if not m:
        raise VecfitError(f"{name} must be pixels (120, 120px) or a percentage (65%), not {text!r}")
    value = float(m.group(1))
    return value * native / 100 if m.group(2) == "%" else value


def _rounds(total: int, steps: int) -> list[int]:
    """``total`` seams divided into at most ``steps`` rounds, as evenly as can be."""
    steps = max(1, min(steps, total))
    return [total // steps + (1 if i < total % steps else 0) for i in range(steps)] if total else []


def divided_iterations(total: int, rounds: int, per_round: int, final: int) -> tuple[int, int]:
    """``total`` Adam iterations divided between ``rounds`` rounds and the final fit in the
    proportions of ``per_round`` and ``final`` (40 a round and 60 at the end, 6 rounds:
    150 gives 20 a round and 30 at the end)."""
    planned = rounds * per_round + final
    each = total * per_round // planned if planned else 0
    return each, total - rounds * each


def run(inputs: Inputs, config: dict, outputs: Outputs, progress=None) -> dict:
    """`vecfit retarget`: the SVG (inputs.svg) resized to retarget.width / height; writes
    the resized SVG, the comparison picture (input | plain scaling | retargeted) and the
    report (last)."""
    started = time.perf_counter()
    inputs.need("retarget", "svg")
    svg_path, progress = inputs.name("svg"), listener(progress)
    outputs.check_against(inputs)
    outputs.forget_report()
    retarget = settings_of(RetargetSettings, config["retarget"])
    width = str(retarget.width).strip() or None
    height = str(retarget.height).strip() or None
    if width is None and height is None:
        raise VecfitError("no new size: give --width (or --height), or retarget.width in the config")
    scene, document = load_scene_to_fit(inputs.svg)
    check_has_size(scene, svg_path)
    w0, h0 = scene.width, scene.height
    new_w = parse_size(width, w0, "--width") if width is not None else w0
    new_h = parse_size(height, h0, "--height") if height is not None else h0
    if new_w > w0 + 0.5 or new_h > h0 + 0.5:
        raise VecfitError(f"{svg_path} is {w0:g}x{h0:g}: retarget removes seams, it cannot enlarge "
                          f"to {new_w:g}x{new_h:g}")
    if min(new_w, new_h) < MIN_SIDE:
        raise VecfitError(f"{new_w:g}x{new_h:g} is too small (at least {MIN_SIDE}x{MIN_SIDE} pixels)")
    if round(new_w) == round(w0) and round(new_h) == round(h0):
        raise VecfitError(f"{svg_path} is already {w0:g}x{h0:g}: nothing to retarget")
    settings = loop_settings(config)  # its device resolved once: the loop, the renders, the report
    if not any(v and settings.lr.get(k, 0) > 0 for k, v in scene.parameters().items()):
        raise VecfitError(f"{svg_path}: nothing to optimise (no parameter kind has a learning rate above 0)")

    # Work at one scale s (pixels of the working image per pixel of the canvas).
    s = retarget.work_size / max(w0, h0) if retarget.work_size > 0 else 1.0
    s = max(s, MIN_SIDE / min(new_w, new_h))  # (a wide SVG: its new short side stays >= 11 px)
    ww, wh = max(1, round(w0 * s)), max(1, round(h0 * s))
    s_x, s_y = ww / w0, wh / h0

    original = render_for_scoring(scene, ww, wh, settings)
    background = background_for(original, settings.background)
    goal_w, goal_h = min(ww, max(1, round(new_w * s_x))), min(wh, max(1, round(new_h * s_y)))
    # Vertical seams first (width), then horizontal ones (height, on the transposed image).
    empty = seen(np.zeros((1, 1, 4), np.float32), background)[0, 0]  # the bare canvas
    look = seen(original, background)
    carved_w, seams_w = carve(original, ww - goal_w, seen=look,
                              salience=retarget.foreground * foreground(look, empty))
    look = seen(carved_w, background).transpose(1, 0, 2)
    _, seams_h = carve(carved_w.transpose(1, 0, 2), wh - goal_h, seen=look,
                       salience=retarget.foreground * foreground(look, empty))
    plan = [(0, chunk) for chunk in _rounds(len(seams_w), retarget.steps)]
    plan += [(1, chunk) for chunk in _rounds(len(seams_h), retarget.steps)]
    if retarget.iterations > 0:  # the whole run's iterations, divided as the config divides them
        retarget.iterations_per_step, retarget.final_iterations = divided_iterations(
            retarget.iterations, len(plan), retarget.iterations_per_step, retarget.final_iterations)
        config = {**config, "retarget": {**config["retarget"], "iterations_per_step": retarget.iterations_per_step,
                                         "final_iterations": retarget.final_iterations}}
    progress.start(len(plan) * retarget.iterations_per_step + retarget.final_iterations)

    loop = dataclasses.replace(settings, iterations=retarget.iterations_per_step)
    drawn_crossed = crossed_subpaths(scene)  # the user's crossings stay; the fit's are cut
    cur_w, cur_h = ww, wh
    image = original
    used = {0: 0, 1: 0}
    runs = []  # the loop's runs: a round's each, then the final fit
    for axis, count in plan:
        seams = (seams_w if axis == 0 else seams_h)[used[axis]:used[axis] + count]
        used[axis] += count
        carve_points(scene, seams, cur_w, cur_h, axis)
        image = _apply(image, seams, axis)
        if axis == 0:
            cur_w -= count
        else:
            cur_h -= count
        scene.width, scene.height = cur_w / s_x, cur_h / s_y
        runs.append(optimize(scene, Target(torch.from_numpy(np.ascontiguousarray(image)), background), loop,
                             progress=progress))
        if runs[-1].interrupted:
            break
    if not (runs and runs[-1].interrupted) and retarget.final_iterations > 0:
        final_loop = dataclasses.replace(settings, iterations=retarget.final_iterations)
        runs.append(optimize(scene, Target(torch.from_numpy(np.ascontiguousarray(image)), background),
                             final_loop, progress=progress))
    result = joined(runs)

    # The canvas: the new size exactly, unless Ctrl-C stopped at a round's size.
    out_w, out_h = (cur_w / s_x, cur_h / s_y) if result.interrupted else (new_w, new_h)
    scene.width, scene.height = out_w, out_h
    cut_crossed_outlines(scene, drawn_crossed, config)
    final = render_for_scoring(scene, cur_w, cur_h, settings)
    final_rgb, goal_rgb = to_rgb(final, background), to_rgb(image, background)
    fit = compare(final_rgb, goal_rgb)
    refuse_non_finite(fit, "retargeted")
    written = svg_bytes(scene, document, canvas=(out_w, out_h), precision=output_precision(config))
    outputs.keep_svg(written)
    original_rgb = to_rgb(original, background)
    scaled_rgb = cv2.resize(original_rgb.astype(np.float32), (cur_w, cur_h), interpolation=cv2.INTER_AREA)
    if outputs.comparison is not None:
        save_panels(outputs.comparison, side_by_side([original_rgb, scaled_rgb, final_rgb]))
    plain = compare(scaled_rgb.astype(np.float64), goal_rgb) if scaled_rgb.shape == goal_rgb.shape else None
    return outputs.keep_report(job_report(
        config, settings, outputs, result, started=started, inputs={"command": "retarget", "init": str(svg_path)},
        canvas={"size_before": [w0, h0], "size": [out_w, out_h],
                "working_size": {"before": [ww, wh], "after": [cur_w, cur_h]},
                "seams": {"vertical": used[0], "horizontal": used[1]}, "rounds": len(plan)},
        background=background,
        # against the seam-carved render of the input (what was fitted): plain scaling of
        # the input's render, and the retargeted SVG's render
        initial=plain, optimized=fit, shapes=len(scene.shapes), written=written))


def _apply(image: np.ndarray, seams: list, axis: int) -> np.ndarray:
    """``image`` less ``seams`` (vertical for axis 0, horizontal for axis 1)."""
    if axis == 1:
        image = image.transpose(1, 0, 2)
    for seam in seams:
        image = remove_seam(image, seam)
    return image.transpose(1, 0, 2) if axis == 1 else image
