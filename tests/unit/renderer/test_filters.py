"""The pixel filters: each one's weights (a straight edge's coverage against the filter's
integral) and the Monte Carlo gradients under it (against central differences).

Coverage of pixel x by the half-plane left of x0 is the filter's integral from -r to
x0 - (x + 0.5), over its integral from -r to r (filters are separable). 32 x 32 samples
place 1024 strata along x: tolerance 0.01. Gradients: as tests/oracles/test_gradients.py (same
weighting, 16 x 16 samples), 10% of the finite difference's norm.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import vecfit
from test_gradients import BOUNDARY, SAMPLES, SIZE, W, background
from vecfit.scene import Circle, Rect, Scene, Shape, Solid

PROFILES = {  # the filter along one axis, u = offset / radius in [-1, 1]
    "tent": lambda u: 1 - np.abs(u),
    "parabolic": lambda u: 1 - u * u,
    "hann": lambda u: 0.5 * (1 + np.cos(np.pi * u)),
    "gaussian": lambda u: np.exp(-2 * u * u),  # sigma = r / 2
}


def share(profile, a, b):
    u = np.linspace(-1, 1, 20001)
    w = profile(u)
    inside = (u >= a) & (u <= b)
    return float(np.trapezoid(w * inside, u) / np.trapezoid(w, u))


@pytest.mark.parametrize("name", list(PROFILES))
def test_edge_coverage_matches_the_filter(name):
    r, x0 = 1.7, 6.3
    scene = Scene(width=12, height=4, shapes=[
        Shape(geometry=Rect(torch.tensor([-20.0, -20.0]), torch.tensor([x0, 30.0])),
              fill=Solid(torch.tensor([0.0, 0.0, 0.0, 1.0])))])
    image = vecfit.render(scene, 12, 4, samples=32, filter=name, filter_radius=r, seed=3)
    for x in range(3, 10):
        expected = share(PROFILES[name], -1.0, (x0 - (x + 0.5)) / r)
        got = float(image[2, x, 3])
        assert abs(got - expected) < 0.01, (x, got, expected)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["box", "tent", "gaussian", "parabolic", "hann"])
def test_gradients_under_the_filter(name):
    def loss(center, radius):
        scene = Scene(width=SIZE, height=SIZE, shapes=[background(), Shape(  # opaque: straight colour is smooth
            geometry=Circle(center, radius), fill=Solid(torch.tensor([0.8, 0.3, 0.2, 0.9])))])
        img = vecfit.render(scene, SIZE, SIZE, samples=SAMPLES, filter=name, filter_radius=1.5, seed=0,
                            boundary_samples=BOUNDARY)
        return (img * W).sum()

    center = torch.tensor([19.0, 21.0], requires_grad=True)
    radius = torch.tensor(9.0, requires_grad=True)
    loss(center, radius).backward()
    ad = torch.cat([center.grad, radius.grad.reshape(1)])
    fd = []
    h = 0.5
    with torch.no_grad():
        for i in range(3):
            params = [center.detach().clone(), radius.detach().clone()]
            plus = [p.clone() for p in params]
            minus = [p.clone() for p in params]
            target = (0, i) if i < 2 else (1, None)
            for p, s in ((plus, h), (minus, -h)):
                if target[1] is None:
                    p[1] += s
                else:
                    p[0][target[1]] += s
            fd.append(float((loss(*plus) - loss(*minus)) / (2 * h)))
    fd = torch.tensor(fd)
    assert float((ad - fd).norm()) <= 0.1 * float(fd.norm()) + 0.5, (ad, fd)
