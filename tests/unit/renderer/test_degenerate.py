"""Degenerate geometry renders without crashing and without NaN, in both modes."""
from __future__ import annotations

import numpy as np
import pytest
import torch

import vecfit
from vecfit.errors import VecfitError
from vecfit.scene import Circle, Ellipse, Path, Rect, Scene, Shape, Solid

RED = lambda: Solid(torch.tensor([1.0, 0.0, 0.0, 1.0]))  # noqa: E731


def path(points, degrees, closed=False):
    return Path(points=torch.tensor(points, dtype=torch.float32), degrees=np.array(degrees),
                subpaths=[(0, len(degrees), closed)])


def shapes_cases():
    yield "zero-length line", path([[10, 10], [10, 10]], [1])
    yield "coincident cubic", path([[10, 10], [10, 10], [10, 10], [10, 10]], [3])
    yield "cubic with coincident inner points", path([[5, 5], [5, 5], [20, 20], [20, 20]], [3])
    yield "cubic with a cusp", path([[5, 20], [25, 5], [5, 5], [25, 20]], [3])
    yield "collinear quadratic", path([[5, 5], [10, 10], [20, 20]], [2])
    yield "closed zero-area", path([[5, 5], [20, 5]], [1, 1], closed=True)
    yield "zero radius circle", Circle(torch.tensor([10.0, 10.0]), torch.tensor(0.0))
    yield "zero radius ellipse", Ellipse(torch.tensor([10.0, 10.0]), torch.tensor([5.0, 0.0]))
    yield "zero-size rect", Rect(torch.tensor([5.0, 5.0]), torch.tensor([5.0, 20.0]))
    yield "huge coordinates", path([[-1e7, -1e7], [1e7, 3], [3, 1e7]], [1, 1], closed=True)
    yield "reversal (180 degree turn)", path([[5, 10], [20, 10], [5, 10]], [1, 1])
    yield "empty path", Path(points=torch.zeros((0, 2)), degrees=np.array([], dtype=int), subpaths=[])


CASES = list(shapes_cases())


@pytest.mark.parametrize("mode", ["mc", "analytic"])
@pytest.mark.parametrize("linecap", ["butt", "round", "square"])
@pytest.mark.parametrize("name,geometry", CASES, ids=[c[0] for c in CASES])
def test_degenerate_geometry_renders_finite(name, geometry, linecap, mode):
    shape = Shape(geometry=geometry, fill=RED(), stroke=Solid(torch.tensor([0.0, 0, 1, 1])),
                  stroke_width=torch.tensor(3.0), linecap=linecap, linejoin="miter")
    image = vecfit.render(Scene(width=32, height=32, shapes=[shape]), samples=2, mode=mode)
    assert image.shape == (32, 32, 4)
    assert torch.isfinite(image).all()
    assert float(image.min()) >= 0 and float(image.max()) <= 1


def test_zero_length_subpath_caps():
    """A zero-length subpath draws a dot with round caps, a square with square caps and
    nothing with butt caps (SVG)."""
    areas = {}
    for cap in ["butt", "round", "square"]:
        shape = Shape(geometry=path([[16, 16], [16, 16]], [1]), stroke=RED(),
                      stroke_width=torch.tensor(8.0), linecap=cap)
        img = vecfit.render(Scene(width=32, height=32, shapes=[shape]), samples=8)
        areas[cap] = float(img[..., 3].sum())
    assert areas["butt"] == 0
    assert areas["round"] == pytest.approx(np.pi * 16, rel=0.03)
    assert areas["square"] == pytest.approx(64, rel=0.03)


def test_non_finite_values_are_refused():
    shape = Shape(geometry=path([[1, 1], [float("nan"), 5], [9, 9]], [1, 1], closed=True), fill=RED())
    with pytest.raises(VecfitError, match="non-finite"):
        vecfit.render(Scene(width=16, height=16, shapes=[shape]))


def test_bad_options_are_refused():
    scene = Scene(width=8, height=8)
    with pytest.raises(VecfitError, match="too large"):
        vecfit.render(scene, 100_000, 100_000)
    with pytest.raises(VecfitError):
        vecfit.render(scene, mode="fast")
    with pytest.raises(VecfitError):
        vecfit.render(scene, filter="lanczos")
    with pytest.raises(VecfitError):
        vecfit.render(scene, samples=0)
