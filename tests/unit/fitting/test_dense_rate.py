"""Dense scenes (issue 29): the point rate that follows the outline density
(vecfit/fitting/rates.py), the report's figures, and the boundary budget as a setting."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from vecfit import VecfitError
from vecfit.fitting import loop
from vecfit.fitting.loop import Settings, Target, optimize
from vecfit.fitting.rates import dense_point_rate, outline_density
from vecfit.scene import Path, Scene, Shape, Solid


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


def test_the_boundary_budget_setting_reaches_the_renderer(monkeypatch):
    seen = []
    real = loop.render

    def spy(*args, **kwargs):
        seen.append(kwargs["boundary_budget"])
        return real(*args, **kwargs)

    monkeypatch.setattr(loop, "render", spy)
    optimize(squares(4, 12.0), _target(), Settings.defaults(iterations=2, threads=1, boundary_budget=0.5))
    assert seen and set(seen) == {0.5}


@pytest.mark.parametrize("key", ["boundary_budget", "dense_outline", "dense_points"])
def test_the_new_settings_are_checked(key):
    with pytest.raises(VecfitError, match=key):
        Settings.defaults(**{key: -1.0})
