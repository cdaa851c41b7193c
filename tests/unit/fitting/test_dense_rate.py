"""Dense scenes (issue 29): the point rate that follows the outline density
(vecfit/fitting/rates.py), the report's figures, the boundary budget as a setting, and a
dense scene's boundary samples held to what its first full-size iteration asks (issue 41)."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from vecfit import VecfitError
from vecfit.fitting import loop
from vecfit.fitting.loop import Settings, Target, optimize
from vecfit.fitting.rates import boundary_length_density, dense_point_rate, held_boundary_budget, outline_density
from vecfit.scene import Circle, Ellipse, Path, Rect, Scene, Shape, Solid


def squares(count: int, side: float, size: int = 64) -> Scene:
    """``count`` closed squares of ``side`` px (four lines each) on a size x size canvas."""
    rng = np.random.default_rng(count)
    shapes = []
    for x, y in rng.uniform(0, size - side, (count, 2)):
        pts = torch.tensor([[x, y], [x + side, y], [x + side, y + side], [x, y + side]], dtype=torch.float32)
        path = Path(pts, torch.ones(4, dtype=torch.int32), [(0, 4, True)])
        shapes.append(Shape(path, fill=Solid(torch.tensor([0.2, 0.4, 0.8, 1.0]))))
    return Scene(size, size, shapes)


def test_outline_density_is_the_control_polygons_per_pixel():
    # 10 squares of side 8: 10 x 32 px of outline (closing edges included) over 64 x 64 px
    assert outline_density(squares(10, 8.0), 64, 64) == pytest.approx(320 / 4096, rel=1e-6)
    # twice the resolution: twice the length over four times the pixels
    assert outline_density(squares(10, 8.0), 128, 128) == pytest.approx(320 / 4096 / 2, rel=1e-6)


@pytest.mark.parametrize("density, expected", [(0.0, 2.0), (0.2, 2.0), (0.3, 2.0), (0.45, 1.625), (0.6, 1.25),
                                               (0.9, 1.25)])
def test_the_point_rate_falls_between_the_densities(density, expected):
    assert dense_point_rate(2.0, density, 0.3, 1.25) == pytest.approx(expected)


def test_the_rule_never_raises_a_rate_and_can_be_off():
    assert dense_point_rate(1.0, 0.9, 0.3, 1.25) == 1.0  # paint's and edit's 1 px stay
    assert dense_point_rate(2.0, 5.0, 0.0, 1.25) == 2.0  # dense_outline 0: off


def _target(size: int = 64) -> Target:
    img = np.ones((size, size, 4), np.float32)
    img[20:40, 20:40, :3] = (0.2, 0.4, 0.8)
    return Target(torch.from_numpy(img), (1.0, 1.0, 1.0, 1.0))


@pytest.mark.parametrize("count, rate", [(4, 2.0), (60, 1.0)])
def test_the_loop_uses_and_reports_the_rate_of_the_scene(count, rate):
    """4 squares of 12 px: 0.047 px of outline per pixel (sparse: refine's 2 px); 60: 0.70
    (dense: 1 px, configs/refine.toml's dense_points). Adam's first step moves each coordinate by its rate."""
    scene = squares(count, 12.0)
    before = scene.shapes[0].geometry.points.clone()
    result = optimize(scene, _target(), Settings.defaults(iterations=1, lr_warmup=0, lr_decay=1.0, threads=1,
                                                          lr={"points": 2.0}))
    assert result.point_rate == pytest.approx(rate)
    assert result.outline_density == pytest.approx(count * 48 / 4096, rel=1e-5)
    moved = (scene.shapes[0].geometry.points - before).abs().max()
    assert float(moved) == pytest.approx(rate, abs=1e-3)


def budgets_seen(monkeypatch) -> list:
    """The boundary budget of each render the loop makes from now on, in order."""
    seen = []
    real = loop.render

    def spy(*args, **kwargs):
        seen.append(kwargs["boundary_budget"])
        return real(*args, **kwargs)

    monkeypatch.setattr(loop, "render", spy)
    return seen


def test_the_boundary_budget_setting_reaches_the_renderer(monkeypatch):
    seen = budgets_seen(monkeypatch)
    optimize(squares(4, 12.0), _target(), Settings.defaults(iterations=2, threads=1, boundary_budget=0.5))
    assert seen and set(seen) == {0.5}


@pytest.mark.parametrize("key", ["boundary_budget", "boundary_growth", "dense_outline", "dense_points"])
def test_the_new_settings_are_checked(key):
    with pytest.raises(VecfitError, match=key):
        Settings.defaults(**{key: -1.0})


def test_the_boundary_length_counts_a_stroke_twice_and_primitives_by_their_perimeter():
    blue = Solid(torch.tensor([0.2, 0.4, 0.8, 1.0]))
    square = squares(1, 8.0).shapes[0].geometry  # 32 px of outline
    scene = Scene(64, 64, [Shape(square, fill=blue), Shape(square, stroke=blue), Shape(square, fill=blue, stroke=blue)])
    assert boundary_length_density(scene, 64, 64) == pytest.approx((32 + 64 + 96) / 4096, rel=1e-6)
    t = torch.tensor
    primitives = Scene(64, 64, [Shape(Circle(t([32.0, 32.0]), t(10.0)), fill=blue),
                                Shape(Ellipse(t([32.0, 32.0]), t([10.0, 10.0])), fill=blue),
                                Shape(Rect(t([0.0, 0.0]), t([8.0, 4.0])), fill=blue)])
    assert boundary_length_density(primitives, 64, 64) == pytest.approx((2 * 20 * np.pi + 24) / 4096, rel=1e-5)
    # twice the resolution: twice the length over four times the pixels
    assert boundary_length_density(scene, 128, 128) == pytest.approx((32 + 64 + 96) / 4096 / 2, rel=1e-6)


@pytest.mark.parametrize("budget, growth, samples, density, expected", [
    (2.0, 1.0, 2.0, 0.64, 1.28),  # held below the budget
    (2.0, 1.0, 2.0, 1.50, 2.0),  # the budget the lower bound
    (0.0, 1.5, 2.0, 0.50, 1.5),  # no budget: the hold alone
    (2.0, 0.0, 2.0, 0.64, 2.0),  # growth 0: not held
    (2.0, 1.0, 2.0, 0.00, 2.0),  # nothing to count: not held (0 would mean no bound)
])
def test_the_held_budget_is_the_lower_of_the_two_bounds(budget, growth, samples, density, expected):
    assert held_boundary_budget(budget, growth, samples, density) == pytest.approx(expected)


@pytest.mark.parametrize("count, growth, expected", [
    (4, 1.0, 2.0),  # sparse (0.047 px a pixel): the budget as set
    (60, 1.0, 2 * 60 * 48 / 4096),  # dense (0.70): held to the samples its outlines ask at the start
    (60, 1.2, 1.2 * 2 * 60 * 48 / 4096),
    (60, 1.5, 2.0),  # past the budget: the budget
    (60, 0.0, 2.0),  # not held
])
def test_a_dense_scenes_boundary_samples_are_held_from_its_first_full_size_iteration(monkeypatch, count, growth,
                                                                                      expected):
    seen = budgets_seen(monkeypatch)
    optimize(squares(count, 12.0), _target(), Settings.defaults(iterations=3, threads=1, boundary_budget=2.0,
                                                                 boundary_samples=2.0, boundary_growth=growth))
    assert len(seen) == 4 and seen == pytest.approx([expected] * 4, rel=1e-5)
