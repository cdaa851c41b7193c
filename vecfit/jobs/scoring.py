"""How every job measures a result: the scene rendered at optimize.eval_samples (not the
loop's samples), composited over the fitting background and compared with what it was
fitted to. The figures in the reports and the comparison pictures come from here."""
from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np

from vecfit.errors import VecfitError
from vecfit.fitting.metrics import compare, to_rgb
from vecfit.fitting.settings import Settings
from vecfit.scene import Scene
from vecfit.scene.arrays import is_tensor


def render_for_scoring(scene: Scene, width: int, height: int, settings: Settings, seed_offset: int = 0) -> np.ndarray:
    """``scene`` at ``width`` x ``height`` pixels, without background: straight RGBA as a
    NumPy array, at ``settings``' eval_samples, seed (plus ``seed_offset``), threads and
    device. A Scene of NumPy arrays (nothing to optimise) is drawn without torch."""
    options = dict(samples=settings.eval_samples, seed=settings.seed + seed_offset, threads=settings.threads,
                   device=settings.device)
    if not is_tensor(scene.view):
        from vecfit.renderer.forward import render_numpy
        return render_numpy(scene, width, height, **options)
    import torch
    from vecfit.renderer.raster import render
    with torch.no_grad():
        return render(scene, width, height, **options).numpy()


def rendered_rgb(scene: Scene, width: int, height: int, settings: Settings, background,
                 seed_offset: int = 0) -> np.ndarray:
    """render_for_scoring over ``background`` (None: white): the RGB the figures compare."""
    return to_rgb(render_for_scoring(scene, width, height, settings, seed_offset), background)


# The joins after a fit (fitting/simplify.py) are judged at the fewest samples whose noise
# is at most this share of the squared error they measure: a photo's trace at 35 dB, 2 x 2
# samples' noise 14% of it, so 4 x 4 (16 samples a pixel, four times the cost) changed
# nothing but the time; flat art at 45 dB, where 2 x 2's noise is two thirds of the error.
JUDGE_NOISE_SHARE = 0.2
CHEAP_JUDGE = 2


@dataclasses.dataclass
class Judge:
    """How the joins after a fit are judged: ``samples`` (N of N x N a pixel) and, where
    judging_samples already rendered the scene at them, (that render, its sampling noise):
    fitting/simplify.simplify_fitted's ``rendered``."""
    samples: int
    rendered: tuple | None = None


def judging_samples(scene: Scene, width: int, height: int, settings: Settings, background,
                    goal_rgb: np.ndarray) -> Judge:
    """The samples the joins after a fit are judged at: optimize.simplify_samples where
    set, else 2 x 2 where their sampling noise (half the mean squared difference of two
    seeds' renders) is at most JUDGE_NOISE_SHARE of the render's squared error against
    ``goal_rgb``, else eval_samples."""
    if settings.simplify_samples or settings.eval_samples <= CHEAP_JUDGE:
        return Judge(settings.simplify_samples or settings.eval_samples)
    cheap = dataclasses.replace(settings, eval_samples=CHEAP_JUDGE)
    first = rendered_rgb(scene, width, height, cheap, background)
    noise = 0.5 * float(((rendered_rgb(scene, width, height, cheap, background, 1) - first) ** 2).mean())
    error = float(((first - goal_rgb) ** 2).mean())
    if noise <= JUDGE_NOISE_SHARE * error:
        return Judge(CHEAP_JUDGE, (first, noise))
    return Judge(settings.eval_samples)


def refuse_non_finite(figures: dict, what: str = "optimised") -> None:
    """Nothing is written for a result whose figures are not finite (an exact match's PSNR
    is infinite, and fine)."""
    if not all(math.isfinite(figures[k]) or (k == "psnr" and figures["mse"] == 0) for k in figures):
        raise VecfitError(f"the {what} image has non-finite values ({figures}); nothing written")


def score_written(svg: bytes, size: tuple[int, int], goal_rgb: np.ndarray, background, settings: Settings) -> dict:
    """The SVG as written (cut-outs: not what was optimised) read back, rendered at ``size``
    and compared with ``goal_rgb``: {"psnr", "mse", "ssim"}."""
    from vecfit.export import scene_of_svg

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene, _ = scene_of_svg(svg)
    figures = compare(rendered_rgb(scene, size[0], size[1], settings, background), goal_rgb)
    return {k: v for k, v in figures.items() if k in ("psnr", "mse", "ssim")}
