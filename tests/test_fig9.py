"""The paper's Fig. 9 check: the derivative of sum(W * image) when the whole scene moves
right, autograd against central differences, on tiger and mcseem2 at their native size.

W is a smooth random weighting that vanishes within 16 px of the border (both scenes
have a background rect whose edges lie on the canvas border, where the image is not
differentiable under translation). Finite differences of a sampled image are noisy
(edges cross a finite number of samples), so both sides are averaged over seeds.
Measured (4x4 samples, 3 seeds, h = 0.5 px, two weightings): tiger 3.2% and 8.3%,
mcseem2 2.3% and 7.5%.
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest
import torch

import vecfit

from shared_data import SCENES
if not SCENES.exists():
    pytest.skip("the shared data folder is not present", allow_module_level=True)

SEEDS = (0, 1, 2)


def weighting(seed: int, height: int, width: int) -> torch.Tensor:
    g = torch.Generator().manual_seed(seed)
    coarse = torch.rand(1, 4, 8, 8, generator=g)
    w = torch.nn.functional.interpolate(coarse, size=(height, width), mode="bicubic", align_corners=True)[0]
    ry = torch.clamp(torch.minimum(torch.arange(height), torch.arange(height).flip(0)) / 16.0, 0, 1)
    rx = torch.clamp(torch.minimum(torch.arange(width), torch.arange(width).flip(0)) / 16.0, 0, 1)
    return (w * ry[None, :, None] * rx[None, None, :]).permute(1, 2, 0)


def translated(scene, view0, dx):
    scene.view = torch.stack([torch.stack([torch.tensor(1.0), torch.tensor(0.0), dx]),
                              torch.tensor([0.0, 1.0, 0.0]), torch.tensor([0.0, 0.0, 1.0])]) @ view0
    return scene


@pytest.mark.parametrize("name", ["tiger", "mcseem2"])
def test_translation_derivative(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(SCENES / f"{name}.svg")
    w, h = round(scene.width), round(scene.height)
    view0 = scene.view.clone()
    ads, fds = [], []
    for k in range(2):
        W = weighting(k, h, w)
        ad = fd = 0.0
        for seed in SEEDS:
            dx = torch.tensor(0.0, requires_grad=True)
            img = vecfit.render(translated(scene, view0, dx), w, h, samples=4, seed=seed, boundary_samples=8)
            (img * W).sum().backward()
            ad += dx.grad.item() / len(SEEDS)
            with torch.no_grad():
                step = 0.5
                plus = (vecfit.render(translated(scene, view0, torch.tensor(step)), w, h, samples=4, seed=seed) * W).sum()
                minus = (vecfit.render(translated(scene, view0, torch.tensor(-step)), w, h, samples=4, seed=seed) * W).sum()
                fd += float(plus - minus) / (2 * step) / len(SEEDS)
        ads.append(ad)
        fds.append(fd)
    ads, fds = np.array(ads), np.array(fds)
    rel = np.abs(ads - fds) / np.abs(fds)
    print(f"\n{name}: autograd {ads.round(2)}, finite differences {fds.round(2)}, relative error {rel.round(3)}")
    assert rel.max() <= 0.15, f"relative errors {rel} (autograd {ads}, differences {fds})"
