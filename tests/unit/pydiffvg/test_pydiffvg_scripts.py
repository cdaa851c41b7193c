"""Two of diffvg's app scripts on the pydiffvg drop-in, shrunk to test size (issue 28):
code that runs on diffvg must run to its end here too."""
from __future__ import annotations

import pytest
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


@pytest.mark.slow
def test_optimize_pixel_filter_converges():
    """apps/optimize_pixel_filter.py at 64 px (the circle a quarter of the size, the same
    filter radii): Adam at lr 1.0 on a Hann filter's radius from 1.0 towards the target's
    8.0, 2 x 2 samples with a new seed each step, 40 steps (the script's 100 at 256 px
    ended at -5.0, its loss 1,038 -> 8,252: the radius's gradient, estimated from the
    image's own samples, correlated with the loss's adjoint and pointed the wrong way).
    The loss is measured at the target's samples: with new samples each step it cannot
    fall below the noise of two 2 x 2 renders of a radius-8 filter, about 0.6x its start."""
    size = 64
    circle = pydiffvg.Circle(radius=torch.tensor(10.0), center=torch.tensor([32.0, 32.0]))
    group = pydiffvg.ShapeGroup(shape_ids=torch.tensor([0]), fill_color=torch.tensor([0.3, 0.6, 0.3, 1.0]))

    def render(radius, seed):
        args = pydiffvg.RenderFunction.serialize_scene(
            size, size, [circle], [group], filter=pydiffvg.PixelFilter(type=diffvg.FilterType.hann, radius=radius))
        return pydiffvg.RenderFunction.apply(size, size, 2, 2, seed, None, *args)

    with torch.no_grad():
        target = render(torch.tensor(8.0), 0)

    def loss_at_target_samples(radius):
        with torch.no_grad():
            return float((render(torch.tensor(radius), 0) - target).pow(2).sum())

    radius = torch.tensor(1.0, requires_grad=True)
    optimizer = torch.optim.Adam([radius], lr=1.0)
    seen = []
    for t in range(40):
        optimizer.zero_grad()
        (render(radius, t + 1) - target).pow(2).sum().backward()
        optimizer.step()
        seen.append(float(radius.detach()))
    assert min(seen) > 1.0 and 6.5 < seen[-1] < 9.5, seen
    assert loss_at_target_samples(seen[-1]) <= 0.25 * loss_at_target_samples(1.0)


def test_eval_positions_gradients_match_differences():
    """SDF and colour at points: one call of the core for all the points. Their gradients
    (a control point, a stroke width, the points themselves, through a gradient fill too)
    against central differences."""
    t = torch.tensor
    points = t([[10.0, 10.0], [40.0, 8.0], [44.0, 40.0], [12.0, 38.0]], dtype=torch.float32)
    width = t(2.5)
    grad = pydiffvg.LinearGradient(t([5.0, 5.0]), t([40.0, 30.0]), t([0.0, 1.0]),
                                   t([[1.0, 0.2, 0.1, 1.0], [0.1, 0.3, 0.9, 0.6]]))
    positions = t([[20.0, 20.0], [30.0, 12.0], [6.0, 30.0], [41.0, 24.0], [25.0, 42.0]])

    def evaluate(pts, w, pos, output):
        shapes = [pydiffvg.Path(t([1, 0, 0]), pts, True, stroke_width=w)]
        groups = [pydiffvg.ShapeGroup(t([0]), grad, stroke_color=t([0.0, 0.0, 0.0, 0.5]))]
        args = pydiffvg.RenderFunction.serialize_scene(S, S, shapes, groups, output_type=output, eval_positions=pos)
        return pydiffvg.RenderFunction.apply(S, S, 0, 0, 0, None, *args)

    weights = torch.randn(5, 4, generator=torch.Generator().manual_seed(0))
    for output, cols in ((pydiffvg.OutputType.sdf, 1), (pydiffvg.OutputType.color, 4)):
        def loss(pts, w, pos):
            return (evaluate(pts, w, pos, output) * weights[:, :cols]).sum()
        leaves = [points.clone().requires_grad_(), width.clone().requires_grad_(), positions.clone().requires_grad_()]
        grads = torch.autograd.grad(loss(*leaves), leaves)
        h = 1e-2
        for i, (leaf, g) in enumerate(zip(leaves, grads)):
            flat = leaf.detach().reshape(-1)
            for k in range(flat.numel()):
                plus, minus = [x.detach().clone() for x in leaves], [x.detach().clone() for x in leaves]
                plus[i].view(-1)[k] += h
                minus[i].view(-1)[k] -= h
                with torch.no_grad():
                    fd = (loss(*plus) - loss(*minus)) / (2 * h)
                assert abs(float(g.reshape(-1)[k]) - float(fd)) <= 2e-3 + 2e-2 * abs(float(fd)), \
                    (output, i, k, float(g.reshape(-1)[k]), float(fd))


@pytest.mark.slow
def test_eval_positions_script_fits_the_circle():
    """apps/test_eval_positions.py, shrunk (64-px canvas, 120 Adam steps of 300 positions):
    the circle's SDF at random points, against the target SDF image sampled there, brings
    radius and centre back (a step cost ~1 ms a position before)."""
    render = pydiffvg.RenderFunction.apply
    shapes, groups = circle_scene(10.0, (32.0, 32.0))
    args = pydiffvg.RenderFunction.serialize_scene(64, 64, shapes, groups, output_type=pydiffvg.OutputType.sdf)
    target = render(64, 64, 2, 2, 0, None, *args) / 64
    radius_n = torch.tensor(5.0 / 64, requires_grad=True)
    center_n = torch.tensor([27.0 / 64, 34.5 / 64], requires_grad=True)
    optimizer = torch.optim.Adam([radius_n, center_n], lr=1e-2)
    g = torch.Generator().manual_seed(0)
    for step in range(120):
        optimizer.zero_grad()
        shapes[0].radius, shapes[0].center = radius_n * 64, center_n * 64
        positions = torch.rand(300, 2, generator=g) * 64
        args = pydiffvg.RenderFunction.serialize_scene(64, 64, shapes, groups, output_type=pydiffvg.OutputType.sdf,
                                                       eval_positions=positions)
        samples = render(64, 64, 0, 0, step + 1, None, *args) / 64
        grid = (positions / 64) * 2 - 1
        sampled = torch.nn.functional.grid_sample(target.view(1, 1, 64, 64), grid.view(1, -1, 1, 2), mode="nearest",
                                                  align_corners=False)
        (samples - sampled.view(-1, 1)).pow(2).mean().backward()
        optimizer.step()
    assert abs(float(radius_n.detach()) * 64 - 10) < 0.5
    assert (center_n.detach() * 64 - torch.tensor([32.0, 32.0])).abs().max() < 0.5
