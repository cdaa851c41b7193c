"""The report every job returns and writes (NAME.report.json): its entries named here,
once, in one order, so trace, refine, paint, edit and retarget report the same facts
under the same keys; each job's own entries go in the places kept for them."""
from __future__ import annotations

import time

from vecfit import __version__
from vecfit.fitting.result import Result
from vecfit.fitting.settings import Settings
from vecfit.svg.numbers import hex_color
from vecfit.svg.stats import design_stats

from .config import DEFAULT_EFFORT
from .protocol import Outputs


def job_report(config: dict, settings: Settings, outputs: Outputs, result: Result, *, started: float,
               inputs: dict, canvas: dict, background, initial: dict | None, optimized: dict, shapes: int,
               written: bytes, measured: dict | None = None, outcome: dict | None = None) -> dict:
    """The report of a job that started at ``started`` (time.perf_counter) and ran the loop
    with ``settings`` (``result``: its run; retarget's rounds summed into one). In order:

    - ``inputs``: what the job was given (command, target, init, ...); a callable value is
      called now (paint's frames, finished when the report is made);
    - the outputs' names, then ``canvas``: the sizes (size, optimized_size; retarget's
      size before, working sizes, seams and rounds), and the fitting ``background``;
    - ``initial`` and ``optimized``: the figures of the start and of the result against
      what was fitted (retarget's start: its input's render scaled plainly; None where it
      cannot be compared), and the gain between them;
    - ``measured``: the job's own figures (edit: its changed region and elements);
    - the loop's counts and seconds, the shapes, ``outcome`` (what the job did to the file
      written: nodes simplified, outlines untangled, cut-outs, colours) and the file's
      design statistics (``written``: the SVG's bytes);
    - the parameters, loss, seed, device, effort and the whole ``config``."""
    seconds = time.perf_counter() - started
    gained = initial is not None
    return {
        "vecfit": __version__,
        **{k: v() if callable(v) else v for k, v in inputs.items()},
        **outputs.names(),
        **canvas,
        "background": None if background is None else hex_color(background),
        "initial": initial,
        "optimized": optimized,
        "psnr_gain_db": optimized["psnr"] - initial["psnr"] if gained else None,
        "mse_ratio": initial["mse"] / optimized["mse"] if gained and optimized["mse"] > 0 else None,
        **(measured or {}),
        "iterations": result.iterations,
        "coarse_iterations": result.coarse_iterations,  # their losses are at half the size
        "interrupted": result.interrupted,
        "skipped_steps": result.skipped_steps,
        # the point rate after the density rule (configs/refine.toml: dense_outline), and
        # the density it followed
        "point_rate": result.point_rate,
        "outline_density": result.outline_density,
        "seconds": {"total": seconds, "optimize": result.seconds,
                    "per_iteration": result.seconds / max(result.iterations, 1),
                    "iterations": [round(t, 4) for t in result.iteration_seconds]},
        "shapes": shapes,
        **(outcome or {}),
        "file": design_stats(written),  # what a designer finds in the SVG written
        "parameters": {**result.parameters, "total": sum(result.parameters.values())},
        "loss": settings.loss,
        "loss_curve": result.losses,
        "seed": settings.seed,
        "device": settings.device,  # what "auto" came to
        "effort": config.get("effort", DEFAULT_EFFORT),  # quick | normal | best (configs/: [efforts])
        "config": config,
    }
