"""The pixel filter radius's gradient (pydiffvg's PixelFilter.radius) against central
differences of the image, for every filter in both modes.

Loss: sum(W * image) with fixed weights W, the difference between a wide filter's image
and a sharp one (the direction in which an L2 fit towards a blurrier target pulls), ramped
to 0 near the border. The image is linear in the loss, so a Monte Carlo estimate and a
central difference of the same renderer (same seed both sides, a step of 10% of r) agree
in expectation; the means over 8 seeds at 8 x 8 samples have standard errors of about 1%
(the differences) and 0.3% (the gradient). Tolerance 5%.

Monte Carlo: the core's estimate (filter_radius_kernel, csrc/common/sampling.h), from
samples of its own. Analytical (1 x 1, as pydiffvg's use_prefiltering): a central
difference of two more renders. The box filter always covers the pixel: its radius
changes nothing, and its gradient is 0.
"""
from __future__ import annotations

import numpy as np
import pytest
import torch

import vecfit
from vecfit.pydiffvg.render import analytic_radius_gradient, mc_radius_gradient
from vecfit.scene import Circle, Path, Rect, Scene, Shape, Solid

from helpers import slow_unless

SIZE = 40
SAMPLES = 8
SEEDS = 8
RADIUS = 1.3


def tensor(*values):
    return torch.tensor(values, dtype=torch.float32)


def scene() -> Scene:
    """An opaque background, a filled cubic blob, a translucent disc over it and an open
    stroke."""
    blob = Path(points=torch.tensor([[8.0, 9.0], [20.0, 3.0], [31.0, 14.0], [32.0, 30.0], [11.0, 33.0]]),
                degrees=np.array([3, 1, 1]), subpaths=[(0, 3, True)])
    curve = Path(points=torch.tensor([[6.0, 30.0], [14.0, 20.0], [26.0, 38.0], [35.0, 24.0]]),
                 degrees=np.array([3]), subpaths=[(0, 1, False)])
    return Scene(width=SIZE, height=SIZE, shapes=[
        Shape(geometry=Rect(tensor(0, 0), tensor(SIZE, SIZE)), fill=Solid(tensor(1, 1, 1, 1))),
        Shape(geometry=blob, fill=Solid(tensor(0.1, 0.5, 0.8, 1))),
        Shape(geometry=Circle(tensor(25, 16), torch.tensor(7.0)), fill=Solid(tensor(0.9, 0.3, 0.1, 0.6))),
        Shape(geometry=curve, stroke=Solid(tensor(0.1, 0.1, 0.1, 1)), stroke_width=torch.tensor(2.0))])


SCENE = scene()


def weights() -> torch.Tensor:
    with torch.no_grad():
        wide = vecfit.render(SCENE, SIZE, SIZE, samples=16, filter="tent", filter_radius=3.0, seed=99)
        sharp = vecfit.render(SCENE, SIZE, SIZE, samples=16, seed=98)
    ramp = torch.clamp(torch.minimum(torch.arange(SIZE), torch.arange(SIZE).flip(0)) / 4.0, 0, 1)
    return (wide - sharp) * ramp[:, None, None] * ramp[None, :, None]


W = weights()


def image(mode, filter, r, seed):
    options = dict(samples=1, mode="analytic") if mode == "analytic" else dict(samples=SAMPLES, seed=seed)
    with torch.no_grad():
        return vecfit.render(SCENE, SIZE, SIZE, filter=filter, filter_radius=r, **options)


def loss(mode, filter, r, seed):
    return float((image(mode, filter, r, seed) * W).double().sum())


def gradient(mode, filter, r, seed):
    """dL/dr as the pydiffvg adapter computes it (RenderFunction.apply's _FilterRadius)."""
    if mode == "analytic":
        estimate = analytic_radius_gradient(lambda value: image(mode, filter, value, seed), r)
    else:
        estimate = mc_radius_gradient(SCENE, SIZE, SIZE, dict(samples=SAMPLES, filter=filter, filter_radius=r,
                                                              seed=seed))
    return float(estimate(image(mode, filter, r, seed), W))


def means(mode, filter, r=RADIUS):
    """(gradient, central difference), each the mean over the seeds."""
    seeds = range(SEEDS) if mode == "mc" else [0]
    h = 0.1 * r if mode == "mc" else 0.01 * r  # (the analytical image is smooth in r)
    ad = [gradient(mode, filter, r, s) for s in seeds]
    fd = [(loss(mode, filter, r + h, s) - loss(mode, filter, r - h, s)) / (2 * h) for s in seeds]
    return float(np.mean(ad)), float(np.mean(fd))


@pytest.mark.parametrize("mode", slow_unless(["mc", "analytic"], ["analytic"]))
@pytest.mark.parametrize("filter", ["tent", "gaussian", "parabolic", "hann"])
def test_radius_gradient_matches_central_differences(mode, filter):
    ad, fd = means(mode, filter)
    assert abs(fd) > 1.0  # (the weighting makes the loss depend on r)
    assert abs(ad - fd) <= 0.05 * abs(fd), f"{filter} {mode}: gradient {ad:.4f}, central difference {fd:.4f}"


@pytest.mark.slow
@pytest.mark.parametrize("filter", ["tent", "hann"])
def test_wider_radius_matches_central_differences(filter):
    ad, fd = means("mc", filter, r=2.5)
    assert abs(ad - fd) <= 0.05 * abs(fd), f"{filter} at r = 2.5: gradient {ad:.4f}, central difference {fd:.4f}"


@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_box_radius_changes_nothing(mode):
    assert torch.equal(image(mode, "box", RADIUS + 0.2, 0), image(mode, "box", RADIUS - 0.2, 0))
    if mode == "mc":
        assert gradient(mode, "box", RADIUS, 0) == 0.0


def test_below_half_a_pixel_changes_nothing():
    """Filters are settled to at least 0.5 px: below that the image and the gradient
    stay put."""
    assert torch.equal(image("mc", "hann", 0.3, 0), image("mc", "hann", 0.45, 0))
    assert gradient("mc", "hann", 0.4, 0) == 0.0
