"""The render defaults have one source in Python, RenderOptions (vecfit/renderer/options.py):
vecfit.render, render_numpy, render_batch and the render command take theirs from it, the
core's struct starts from the same, and a fit's [optimize] table renders with them but for
the differences options.FITTING names."""
from __future__ import annotations

import dataclasses
import inspect

import numpy as np
import pytest
import torch

import vecfit
from vecfit import _core
from vecfit.cli.commands import main
from vecfit.io.configs import defaults
from vecfit.renderer.forward import render_numpy
from vecfit.renderer.many import render_batch
from vecfit.renderer.options import FITTING, RenderOptions
from vecfit.scene import Path, Scene, Shape, Solid

DEFAULTS = {f.name: f.default for f in dataclasses.fields(RenderOptions) if f.default is not dataclasses.MISSING}


@pytest.mark.parametrize("function", [vecfit.render, render_numpy, render_batch])
def test_the_python_renders_take_the_defaults_of_render_options(function):
    taken = 0
    for name, parameter in inspect.signature(function).parameters.items():
        if name in DEFAULTS:
            assert parameter.default == DEFAULTS[name], (function.__name__, name)
            taken += 1
    assert taken >= 7


def test_the_render_command_takes_them_too():
    options = {p.name: p.default for p in main.commands["render"].params}
    for cli, field in (("samples", "samples"), ("mode", "mode"), ("filter_", "filter"),
                       ("filter_radius", "filter_radius"), ("seed", "seed"), ("threads", "threads")):
        assert options[cli] == DEFAULTS[field], cli


def test_the_cores_struct_starts_from_the_same():
    core = _core.RenderOptions(width=1, height=1)
    shared = [name for name in DEFAULTS if hasattr(core, name)]
    assert set(DEFAULTS) - set(shared) == {"boundary_samples"}  # (the core takes it beside the struct)
    for name in shared:
        assert getattr(core, name) == DEFAULTS[name], name


def test_a_fit_renders_with_them_but_for_the_named_differences():
    optimize = defaults("refine", "optimize")
    render_keys = sorted(set(optimize) & set(DEFAULTS) - {"background"})  # (a fit's: "auto", the target's corners)
    assert render_keys == ["boundary_budget", "boundary_samples", "interior_samples", "mode", "samples", "seed",
                           "threads"]
    for name in render_keys:
        assert optimize[name] == FITTING.get(name, DEFAULTS[name]), name
    assert all(FITTING[name] != DEFAULTS[name] for name in FITTING)  # (each a real difference)


def test_boundary_samples_reach_the_backward_pass():
    """RenderOptions.boundary_samples is what the Monte Carlo backward samples the boundaries
    with: the same value, the same gradient; another, another estimate."""
    def point_gradient(**kw):
        points = torch.tensor([[10.0, 10.0], [50.0, 12.0], [30.0, 40.0]], requires_grad=True)
        tri = Path(points=points, degrees=np.array([1, 1, 1]), subpaths=[(0, 3, True)])
        scene = Scene(width=64, height=48, shapes=[Shape(geometry=tri, fill=Solid(torch.tensor([1.0, 0, 0, 1])))])
        vecfit.render(scene, seed=3, **kw)[..., 3].sum().backward()
        return points.grad

    default = point_gradient()
    assert float(default.abs().sum()) > 0
    assert torch.equal(point_gradient(boundary_samples=RenderOptions.boundary_samples), default)
    assert not torch.equal(point_gradient(boundary_samples=16.0), default)
    with pytest.raises(Exception):
        RenderOptions(4, 4).boundary_samples = 1.0  # (frozen: one value a render)
