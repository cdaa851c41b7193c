"""Two of diffvg's app scripts on the pydiffvg drop-in, shrunk to test size (issue 28):
code that runs on diffvg must run to its end here too."""
from __future__ import annotations

import torch

import diffvg
import pydiffvg

S = 48


def circle_scene(radius=12.0, center=(24.0, 24.0)):
    circle = pydiffvg.Circle(radius=torch.tensor(radius), center=torch.tensor(center))
    group = pydiffvg.ShapeGroup(shape_ids=torch.tensor([0]), fill_color=torch.tensor([0.3, 0.6, 0.3, 1.0]))
    return [circle], [group]


def hann(shapes, groups, radius, seed, prefilter=False):
    args = pydiffvg.RenderFunction.serialize_scene(
        canvas_width=S, canvas_height=S, shapes=shapes, shape_groups=groups, use_prefiltering=prefilter,
        filter=pydiffvg.PixelFilter(type=diffvg.FilterType.hann, radius=radius))
    return pydiffvg.RenderFunction.apply(S, S, 2, 2, seed, None, *args)


def test_filter_radius_at_or_below_zero_renders_as_diffvg_does():
    """diffvg splats a sample only onto pixel centres within the filter radius (|dx| <= r):
    with r <= 0, none. A transparent black image and zero gradients, not an error."""
    shapes, groups = circle_scene()
    shapes[0].radius.requires_grad_(True)
    for prefilter in (False, True):
        for r in (0.0, -0.7, -3.0):
            radius = torch.tensor(r, requires_grad=True)
            image = hann(shapes, groups, radius, seed=0, prefilter=prefilter)
            assert image.shape == (S, S, 4) and not image.any()
            background = torch.ones(S, S, 4)
            args = pydiffvg.RenderFunction.serialize_scene(
                S, S, shapes, groups, filter=pydiffvg.PixelFilter(type=diffvg.FilterType.tent, radius=radius))
            assert not pydiffvg.RenderFunction.apply(S, S, 2, 2, 0, background, *args).any()
            ((image - 0.5) ** 2).sum().backward()
            assert radius.grad == 0 and shapes[0].radius.grad == 0
    # and a positive radius still renders
    assert hann(shapes, groups, torch.tensor(1.0), seed=0)[..., 3].sum() > 100


def test_optimize_pixel_filter_runs_to_its_end():
    """apps/optimize_pixel_filter.py: Adam at lr 1.0 on a Hann filter's radius from 1.0
    towards the target's 8.0 (here 40 steps of a 48-px canvas). Steps can take the radius
    to 0 or below (VecfitError before): the script goes on, as it does on diffvg."""
    shapes, groups = circle_scene()
    with torch.no_grad():
        target = hann(shapes, groups, torch.tensor(8.0), seed=0)
    radius = torch.tensor(1.0, requires_grad=True)
    optimizer = torch.optim.Adam([radius], lr=1.0)
    seen = []
    for t in range(40):
        optimizer.zero_grad()
        image = hann(shapes, groups, radius, seed=t + 1)
        loss = (image - target).pow(2).sum()
        loss.backward()
        seen.append(float(radius.detach()))
        optimizer.step()
    assert torch.isfinite(radius) and len(seen) == 40 and min(seen) <= 0  # (it went there)
    # a last step from a negative radius is a zero image (what the loss sees is the target's)
    with torch.no_grad():
        assert not hann(shapes, groups, torch.tensor(-1.0), seed=0).any()
