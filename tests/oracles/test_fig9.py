"""The paper's Fig. 9 check on tiger and mcseem2 at their native size: every geometry point
moves right by delta; d/d delta of sum(W * image), W a smooth random weighting vanishing
within 4 px of the border (both scenes have a background rect on the canvas border, a kink:
DESIGN.md); autograd against central differences of the same renderer, same seed both
sides (vecfit/renderer/fig9.py; benchmarks/fig9.py prints the full table).

Analytical 1x1 at a step of 0.01 px: its image curves within +-0.5 px (the kernel's support
is one pixel wide, sampled once per pixel: the slope of L swings from -30 to 160 across
tiger's +-0.5 px, smoothly), so a wide step measures the curve, not the derivative. At 0.01
px: tiger 0.4% / 0.5%, mcseem2 0.6% / 0.3% (before the on-edge fix mcseem2 was 4-7% off at
any small step). Tolerance 3%, the issue's: the remaining error is the kinks of the
prefiltered image (thin strokes' centre lines, medial axes of slivers), which make L' vary
by a few % within 0.01 px.

Monte Carlo 4x4 at +-0.5 px, mean of 3 seeds: tiger 1.1% / 8.3%, mcseem2 2.0% / 3.6%
(these seeds). The estimate is unbiased, its error falls like 1/sqrt(seeds) (tiger: 12% /
33% with 1 seed, 5.0% / 6.8% with 4, 0.1% / 3.2% with 16: benchmarks/fig9.py), so the
tolerance, 12%, is about 1.5x the error of 3 seeds on the worse weighting. (mcseem2 kept
1-4% at 16 seeds, too large at any step and off the pixel lines too: a shape drawn over
another along part of its outline had both copies of that edge counted over the
background; 16 seeds now, both directions: test_monte_carlo_mcseem2_over_16_seeds.)
Cost: about 30 s in all, and a minute for each 16-seed direction.
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import vecfit
from vecfit.renderer.fig9 import fig9, weighting

from shared_data import SCENES
if not SCENES.exists():
    pytest.skip("the shared data folder is not present", allow_module_level=True)


def scene_and_weights(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(SCENES / f"{name}.svg")
    w, h = round(scene.width), round(scene.height)
    return scene, w, h, [weighting(k, h, w) for k in range(2)]


def relative_errors(results):
    ad, fd = np.array(results).T
    return ad, fd, np.abs(ad - fd) / np.abs(fd)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["tiger", "mcseem2"])
def test_analytic_gradient_is_the_derivative_of_its_image(name):
    scene, w, h, weights = scene_and_weights(name)
    ad, fd, rel = relative_errors(fig9(scene, w, h, weights, step=0.01, mode="analytic", samples=1))
    print(f"\n{name} analytical: autograd {ad.round(3)}, differences {fd.round(3)}, relative {rel.round(4)}")
    assert rel.max() <= 0.03, f"relative errors {rel} (autograd {ad}, differences {fd})"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["tiger", "mcseem2"])
def test_monte_carlo_gradient_is_the_derivative_of_its_image(name):
    scene, w, h, weights = scene_and_weights(name)
    runs = [fig9(scene, w, h, weights, step=0.5, mode="mc", samples=4, seed=seed) for seed in range(3)]
    ad, fd, rel = relative_errors(np.mean(runs, axis=0))
    print(f"\n{name} Monte Carlo: autograd {ad.round(2)}, differences {fd.round(2)}, relative {rel.round(3)}")
    assert rel.max() <= 0.12, f"relative errors {rel} (autograd {ad}, differences {fd})"


@pytest.mark.slow
@pytest.mark.parametrize("axis", [0, 1])
def test_monte_carlo_mcseem2_over_16_seeds(axis):
    """mcseem2, MC 4x4, every point moved right (axis 0) or down (axis 1), the mean of 16
    seeds within 5% for both weightings. mcseem2 draws many shapes over others along part
    of their outlines, on the same side: the back copy's jump was counted over what lay
    behind both, so moved right it was 1.2% / 3.7% too large (and by 2-7% at 0.25 px, off
    the pixel lines); now 0.0% / 0.1%, and 0.6% / 0.6% moved down (0.2% / 0.2% before;
    a 16-seed mean has a standard error of about 1%)."""
    scene, w, h, weights = scene_and_weights("mcseem2")
    runs = [fig9(scene, w, h, weights, step=0.5, axis=axis, mode="mc", samples=4, seed=seed) for seed in range(16)]
    ad, fd, rel = relative_errors(np.mean(runs, axis=0))
    print(f"\nmcseem2 Monte Carlo, 16 seeds, axis {axis}: autograd {ad.round(2)}, differences {fd.round(2)}, "
          f"relative {rel.round(3)}")
    assert rel.max() <= 0.05, f"relative errors {rel} (autograd {ad}, differences {fd})"
