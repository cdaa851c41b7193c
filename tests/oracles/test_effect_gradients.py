"""Gradients through clip paths, masks and blurs against central differences, in both
modes (the issue "Real SVG files render as browsers draw them"): small scenes over an
opaque background (a straight-alpha image jumps where a pixel's alpha leaves 0) with the
checks and tolerances of test_gradients.py, and the Fig. 9 check on a real Noto emoji
whose shapes are clipped (every point moved right, clip paths' included)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
import torch

import vecfit
from vecfit.renderer.fig9 import fig9, mean_derivative, weighting
from vecfit.scene import Circle, ClipPath, Filter, FilterStep, Mask, Rect, Scene, Shape, Solid

from shared_data import SHARED
from test_gradients import SIZE, background, check

from helpers import slow_unless

MODES = ["mc", "analytic"]
# The analytical image curves within a pixel where a clip's edge and the content's meet
# (a product of two prefiltered edges): differences there take a small step.
STEP = {"mc": 0.3, "analytic": 0.05}


def solid(*rgba):
    return Solid(torch.tensor(rgba, dtype=torch.float32))


def square(p_min, size, color=(0.8, 0.3, 0.2, 1.0), **kw):
    paint = Solid(color) if isinstance(color, torch.Tensor) else solid(*color)
    return Shape(geometry=Rect(p_min=p_min, p_max=p_min + size), fill=paint, **kw)


def clipped(corner, center, radius):
    clip = ClipPath(Scene(width=1, height=1, shapes=[
        Shape(geometry=Circle(center=center, radius=radius), fill=solid(0, 0, 0, 1))]))
    return Scene(width=SIZE, height=SIZE, shapes=[background(), square(corner, 20.0, clip=clip)])


@pytest.mark.parametrize("mode", slow_unless(MODES, ["analytic"]))
def test_through_a_clip_to_the_content_and_the_clip(mode):
    # The square's corner sits inside the clip's circle, so both boundaries show.
    check(clipped, {"corner": torch.tensor([9.55, 10.45]), "center": torch.tensor([22.45, 21.55]),
                    "radius": torch.tensor(11.05)},
          {"corner": STEP[mode], "center": STEP[mode], "radius": STEP[mode]}, mode=mode)


def masked(corner, grey, mask_corner):
    mask = Mask(Scene(width=1, height=1, shapes=[square(mask_corner, 18.0, color=grey)]),
                units="userSpaceOnUse", region=(0.0, 0.0, 40.0, 40.0))
    return Scene(width=SIZE, height=SIZE, shapes=[background(), square(corner, 20.0, mask=mask)])


@pytest.mark.parametrize("mode", slow_unless(MODES, ["analytic"]))
def test_through_a_mask_to_the_content_and_the_mask(mode):
    check(masked, {"corner": torch.tensor([8.55, 9.45]), "grey": torch.tensor([0.7, 0.5, 0.3, 0.9]),
                   "mask_corner": torch.tensor([14.45, 12.55])},
          {"corner": STEP[mode], "grey": 0.01, "mask_corner": STEP[mode]}, mode=mode)


def blurred(center, radius, color):
    step = FilterStep("GaussianBlur", ["SourceGraphic"], params={"std": (1.5, 2.5)})
    blur = Filter([step], units="userSpaceOnUse", region=(0.0, 0.0, 40.0, 40.0))
    return Scene(width=SIZE, height=SIZE, shapes=[
        background(), Shape(geometry=Circle(center=center, radius=radius), fill=Solid(color), filter=blur)])


@pytest.mark.parametrize("mode", slow_unless(MODES, ["analytic"]))
def test_through_a_blur(mode):
    check(blurred, {"center": torch.tensor([19.3, 21.2]), "radius": torch.tensor(9.4),
                    "color": torch.tensor([0.2, 0.6, 0.4, 0.8])},
          {"center": STEP[mode], "radius": STEP[mode], "color": 0.01}, mode=mode)


EMOJI = SHARED / "realworld" / "cases" / "noto-emoji-018.svg"


@pytest.mark.slow
@pytest.mark.skipif(not EMOJI.exists(), reason="the shared real-world corpus is not present")
def test_fig9_on_a_clipped_emoji():
    """Noto's leg emoji draws two groups through clip paths (the clip's outline runs along
    the content's). Over white, as refine draws it.

    Analytical 1x1 at a step of 0.01 px: autograd within 3% of the differences.

    Monte Carlo 4x4 at +-0.5 px over 16 seeds: a layer's coverage times its clip's is a
    product of two ramps within a pixel, so L curves within +-0.5 px (at the derivative
    itself autograd gave 60.5 and -16.9 where the differences gave 64.0 and 2.5). The
    differences over +-0.5 px equal the mean of L' over that interval, which autograd gives
    at 8 midpoints (fig9.mean_derivative): within 5% (of the norm over both weightings: the
    second one's derivative nearly cancels, about 3 against 64)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(EMOJI)
    assert any(g.clip is not None for g in scene.groups)
    w = h = 128
    weights = [weighting(k, h, w) for k in range(2)]
    white = (1.0, 1.0, 1.0)  # (transparent pixels would jump in straight colour)
    ad, fd = np.array(fig9(scene, w, h, weights, step=0.01, mode="analytic", samples=1, background=white)).T
    rel = np.abs(ad - fd) / np.abs(fd)
    print(f"\nanalytical: autograd {ad.round(3)}, differences {fd.round(3)}, relative {rel.round(4)}")
    assert rel.max() <= 0.03
    fd, ad = [], []
    for seed in range(16):
        kw = dict(mode="mc", samples=4, seed=seed, background=white)
        fd.append([d for _, d in fig9(scene, w, h, weights, step=0.5, **kw)])
        ad.append(mean_derivative(scene, w, h, weights, step=0.5, points=8, **kw))
    fd, ad = np.mean(fd, axis=0), np.mean(ad, axis=0)
    error = np.linalg.norm(ad - fd) / np.linalg.norm(fd)
    print(f"Monte Carlo, 16 seeds: autograd (interval mean) {ad.round(3)}, differences {fd.round(3)}, "
          f"error {error:.4f}")
    assert error <= 0.05
