"""pydiffvg on vecfit: diffvg's API, checked by inverse rendering written against that API
only (as diffvg's own tests and the projects built on it use it).

Each feature: render a target, perturb the parameters, optimise them back with Adam on
the L2 image loss, and assert that they come back; the tolerance is stated per test (in
pixels for geometry, in colour units for colours). Images are 24-40 px, 2 x 2 samples,
at most 200 iterations: the whole file takes about 50 s on 2 cores.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import diffvg
import pydiffvg
import vecfit
from vecfit import scene as vs

from helpers import slow_unless

S = 40  # canvas and image size


def render(shapes, groups, size=S, samples=2, seed=0, background=None, **options):
    """An image of size x size pixels of the S x S canvas."""
    args = pydiffvg.RenderFunction.serialize_scene(S, S, shapes, groups, **options)
    return pydiffvg.RenderFunction.apply(size, size, samples, samples, seed, background, *args)


def fit(make, truth: dict, start: dict, iterations=150, lr=0.5, samples=2, size=S, same_samples=False, **kw):
    """Adam from ``start`` towards the parameters that rendered the target from ``truth``;
    returns the fitted parameters. ``make(params) -> (shapes, groups, options)``. Each
    iteration draws new samples, unless ``same_samples`` (the target's samples)."""
    with torch.no_grad():
        shapes, groups, options = make({k: v.clone() for k, v in truth.items()})
        target = render(shapes, groups, size=size, samples=samples, seed=1234, **options, **kw)
    params = {k: v.detach().clone().requires_grad_(True) for k, v in start.items()}
    rates = lr if isinstance(lr, dict) else {k: lr for k in params}
    opt = torch.optim.Adam([{"params": [params[k]], "lr": rates[k]} for k in params])
    # cosine decay to 10%: the last steps settle instead of jittering at the full rate
    decay = torch.optim.lr_scheduler.LambdaLR(opt, lambda i: 0.1 + 0.45 * (1 + math.cos(math.pi * i / iterations)))
    for it in range(iterations):
        opt.zero_grad()
        shapes, groups, options = make(params)
        img = render(shapes, groups, size=size, samples=samples, seed=1234 if same_samples else it, **options, **kw)
        loss = ((img - target) ** 2).mean()
        loss.backward()
        opt.step()
        decay.step()
    return {k: v.detach() for k, v in params.items()}


def on_curve(points, closed):
    """Points along the cubics (8 per segment): control points may trade off against each
    other with little change to the image, the curve they draw may not."""
    pts = torch.cat([points, points[:1]]) if closed else points
    t = torch.linspace(0, 1, 8)[:, None]
    out = []
    for k in range(0, len(pts) - 1, 3):
        p0, p1, p2, p3 = pts[k:k + 4]
        out.append((1 - t) ** 3 * p0 + 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t * t * p2 + t ** 3 * p3)
    return torch.cat(out)


def close(a, b, tol):
    err = float((torch.as_tensor(a) - torch.as_tensor(b)).abs().max())
    assert err <= tol, f"{a} vs {b}: off by {err:.3g} (tolerance {tol})"


BLUE = torch.tensor([0.2, 0.3, 0.9, 1.0])


def one(shape, fill=BLUE, **group):
    return [shape], [pydiffvg.ShapeGroup(torch.tensor([0]), fill_color=fill, **group)], {}


# ------------------------------------------------------------------------ shapes

@pytest.mark.slow
def test_circle():
    got = fit(lambda p: one(pydiffvg.Circle(p["r"], p["c"])),
              {"r": torch.tensor(10.0), "c": torch.tensor([20.0, 18.0])},
              {"r": torch.tensor(7.0), "c": torch.tensor([16.0, 22.0])})
    close(got["r"], 10.0, 0.15)
    close(got["c"], [20.0, 18.0], 0.15)


@pytest.mark.slow
def test_ellipse():
    got = fit(lambda p: one(pydiffvg.Ellipse(p["r"], p["c"])),
              {"r": torch.tensor([12.0, 7.0]), "c": torch.tensor([20.0, 19.0])},
              {"r": torch.tensor([9.0, 9.0]), "c": torch.tensor([17.0, 22.0])})
    close(got["r"], [12.0, 7.0], 0.15)
    close(got["c"], [20.0, 19.0], 0.15)


@pytest.mark.slow
def test_rect():
    # The start is off the pixel lines: an edge exactly on one gets the one-sided derivative
    # towards +x / +y (DESIGN.md, boundary term), which is 0 where the pixel on that side
    # is already right, so an edge starting there may not move (hi = (26, 31) stayed).
    got = fit(lambda p: one(pydiffvg.Rect(p["lo"], p["hi"])),
              {"lo": torch.tensor([8.0, 11.0]), "hi": torch.tensor([30.0, 27.0])},
              {"lo": torch.tensor([10.6, 8.7]), "hi": torch.tensor([26.4, 29.3])})
    close(got["lo"], [8.0, 11.0], 0.15)
    close(got["hi"], [30.0, 27.0], 0.15)


STAR = torch.tensor([[20.0, 4.0], [29.4, 33.0], [4.8, 15.1], [35.2, 15.1], [10.6, 33.0]])


@pytest.mark.slow
def test_self_intersecting_polygon_even_odd():
    # A pentagram: even-odd leaves the centre pentagon empty, which the fit must reproduce.
    make = lambda p: one(pydiffvg.Polygon(p["pts"], True), use_even_odd_rule=True)  # noqa: E731
    start = STAR + torch.tensor([[1.5, -1.0], [-1.0, 1.5], [1.0, 1.0], [-1.5, -1.0], [1.0, -1.5]])
    got = fit(make, {"pts": STAR}, {"pts": start}, lr=0.2)
    close(got["pts"], STAR, 0.3)
    with torch.no_grad():
        img = render(*make({"pts": STAR})[:2])
    assert float(img[20, 20, 3]) < 0.05 and float(img[8, 20, 3]) > 0.95  # hole inside, star tip filled


# three bulging sides between sharp corners (points 0, 3, 6): a smooth joint would let its
# point slide along the outline without changing the image
BLOB = torch.tensor([[6.0, 8.0], [14.0, 2.0], [26.0, 4.0], [34.0, 12.0], [36.0, 22.0], [28.0, 32.0],
                     [18.0, 36.0], [8.0, 32.0], [2.0, 18.0]])


@pytest.mark.slow
def test_closed_cubic_path():
    # three cubics, the last wrapping round to points[0]
    make = lambda p: one(pydiffvg.Path(torch.tensor([2, 2, 2]), p["pts"], True))  # noqa: E731
    g = torch.Generator().manual_seed(0)
    start = BLOB + (torch.rand(BLOB.shape, generator=g) - 0.5) * 3
    got = fit(make, {"pts": BLOB}, {"pts": start}, iterations=200, lr=0.2)
    close(on_curve(got["pts"], True), on_curve(BLOB, True), 0.5)
    close(got["pts"], BLOB, 1.5)  # control points: less well determined by the image


def stroke_only(path):
    return [path], [pydiffvg.ShapeGroup(torch.tensor([0]), fill_color=None,
                                        stroke_color=torch.tensor([0.9, 0.2, 0.1, 1.0]))], {}


CURVE = torch.tensor([[6.0, 30.0], [12.0, 6.0], [28.0, 6.0], [34.0, 30.0]])


@pytest.mark.slow
def test_open_stroke():
    make = lambda p: stroke_only(pydiffvg.Path(torch.tensor([2]), p["pts"], False, stroke_width=p["w"]))  # noqa: E731
    got = fit(make, {"pts": CURVE, "w": torch.tensor(2.0)},
              {"pts": CURVE + torch.tensor([[1.5, 1.0], [-1.0, 1.5], [1.0, -1.0], [-1.5, -1.0]]),
               "w": torch.tensor(1.4)}, iterations=200, lr={"pts": 0.2, "w": 0.05})
    close(got["w"], 2.0, 0.1)
    close(got["pts"][[0, 3]], CURVE[[0, 3]], 0.3)  # the end points (round caps)
    close(on_curve(got["pts"], False), on_curve(CURVE, False), 0.5)
    close(got["pts"], CURVE, 1.5)  # control points: less well determined by the image


@pytest.mark.slow
def test_per_point_thickness():
    line = torch.tensor([[6.0, 20.0], [34.0, 20.0]])
    make = lambda p: stroke_only(pydiffvg.Path(torch.tensor([0]), line, False, stroke_width=p["w"]))  # noqa: E731
    got = fit(make, {"w": torch.tensor([1.5, 4.0])}, {"w": torch.tensor([3.0, 2.5])}, lr=0.05)
    close(got["w"], [1.5, 4.0], 0.1)


# ----------------------------------------------------------------------- paints

SQUARE = pydiffvg.Rect(torch.tensor([4.0, 4.0]), torch.tensor([36.0, 36.0]))


@pytest.mark.slow
def test_linear_gradient():
    def make(p):
        grad = pydiffvg.LinearGradient(p["begin"], p["end"], torch.tensor([0.0, 1.0]), p["colors"])
        return one(SQUARE, grad)
    colors = torch.tensor([[0.9, 0.1, 0.1, 1.0], [0.1, 0.2, 0.9, 1.0]])
    got = fit(make, {"begin": torch.tensor([8.0, 10.0]), "end": torch.tensor([32.0, 28.0]), "colors": colors},
              {"begin": torch.tensor([12.0, 6.0]), "end": torch.tensor([28.0, 32.0]),
               "colors": torch.tensor([[0.6, 0.3, 0.3, 1.0], [0.3, 0.3, 0.6, 1.0]])},
              iterations=200, lr={"begin": 0.3, "end": 0.3, "colors": 0.01})
    close(got["begin"], [8.0, 10.0], 0.5)
    close(got["end"], [32.0, 28.0], 0.5)
    close(got["colors"][:, :3], colors[:, :3], 0.03)


@pytest.mark.slow
def test_radial_gradient():
    colors = torch.tensor([[1.0, 0.9, 0.2, 1.0], [0.1, 0.1, 0.5, 1.0]])

    def make(p):
        return one(SQUARE, pydiffvg.RadialGradient(p["c"], p["r"], torch.tensor([0.0, 1.0]), colors))
    got = fit(make, {"c": torch.tensor([18.0, 22.0]), "r": torch.tensor([14.0, 9.0])},
              {"c": torch.tensor([22.0, 18.0]), "r": torch.tensor([10.0, 12.0])}, iterations=200, lr=0.3)
    close(got["c"], [18.0, 22.0], 0.3)
    close(got["r"], [14.0, 9.0], 0.3)


@pytest.mark.slow
def test_shape_to_canvas_2x3():
    square = pydiffvg.Rect(torch.tensor([-8.0, -8.0]), torch.tensor([8.0, 8.0]))
    truth = torch.tensor([[1.0, 0.4, 20.0], [-0.3, 0.8, 19.0]])
    start = torch.tensor([[0.8, 0.2, 18.0], [-0.1, 1.0, 21.0]])
    got = fit(lambda p: one(square, shape_to_canvas=p["m"]), {"m": truth}, {"m": start}, iterations=200,
              lr=0.02)
    close(got["m"][:, :2], truth[:, :2], 0.03)
    close(got["m"][:, 2], truth[:, 2], 0.3)


# ---------------------------------------------------------------- filter, background

@pytest.mark.slow
@pytest.mark.parametrize("ftype", [diffvg.FilterType.tent, diffvg.FilterType.parabolic, diffvg.FilterType.hann])
@pytest.mark.parametrize("prefiltering", [False, True])
def test_pixel_filter_radius(ftype, prefiltering):
    # A disk over an opaque square: the image's colour is defined everywhere.
    shapes = [pydiffvg.Rect(torch.tensor([0.0, 0.0]), torch.tensor([40.0, 40.0])),
              pydiffvg.Circle(torch.tensor(9.0), torch.tensor([20.0, 20.0]))]
    groups = [pydiffvg.ShapeGroup(torch.tensor([0]), torch.tensor([1.0, 1.0, 1.0, 1.0])),
              pydiffvg.ShapeGroup(torch.tensor([1]), BLUE)]

    def make(p):
        return shapes, groups, dict(filter=pydiffvg.PixelFilter(ftype, p["r"]), use_prefiltering=prefiltering)
    # Monte Carlo: with new samples each step the expected loss's minimum moves (the
    # image's variance depends on r), so the fit uses the target's samples.
    got = fit(make, {"r": torch.tensor(1.5)}, {"r": torch.tensor(0.9)}, iterations=80, lr=0.05,
              samples=4, same_samples=True)
    close(got["r"], 1.5, 0.08)


@pytest.mark.parametrize("ftype", slow_unless([diffvg.FilterType.tent, diffvg.FilterType.parabolic, diffvg.FilterType.hann],
                                      [diffvg.FilterType.hann]))
@pytest.mark.parametrize("prefiltering", [False, True])
def test_filter_radius_gradient_against_finite_differences(ftype, prefiltering):
    """dL/dr against a central difference of the loss (step 0.1 px, the same samples),
    L = sum(weights * image) over an opaque square. Monte Carlo (16 x 16 samples): the
    core's estimate of the radius derivative, within 10%; analytical: within 2%."""
    weights = torch.rand(S, S, 4, generator=torch.Generator().manual_seed(2))
    shapes = [pydiffvg.Rect(torch.tensor([0.0, 0.0]), torch.tensor([40.0, 40.0])),
              pydiffvg.Path(torch.tensor([2, 2, 2]), BLOB, True)]
    groups = [pydiffvg.ShapeGroup(torch.tensor([0]), torch.tensor([1.0, 1.0, 1.0, 1.0])),
              pydiffvg.ShapeGroup(torch.tensor([1]), torch.tensor([0.1, 0.5, 0.8, 1.0]))]
    samples = 1 if prefiltering else 16

    def loss(r):
        return (render(shapes, groups, samples=samples, filter=pydiffvg.PixelFilter(ftype, r),
                       use_prefiltering=prefiltering) * weights).sum()
    r = torch.tensor(1.3, requires_grad=True)
    loss(r).backward()
    h = 0.1
    with torch.no_grad():
        fd = float((loss(torch.tensor(1.3 + h)) - loss(torch.tensor(1.3 - h))) / (2 * h))
    tol = 0.02 if prefiltering else 0.1
    assert abs(float(r.grad) - fd) <= tol * abs(fd), (float(r.grad), fd)


@pytest.mark.slow
def test_background_image():
    # A disk over a background image whose colour is fitted (visible around the disk).
    disk = pydiffvg.Circle(torch.tensor(10.0), torch.tensor([20.0, 20.0]))
    half = torch.tensor([0.7, 0.2, 0.1, 0.6])

    def make(p):
        return one(disk, fill=torch.tensor([0.1, 0.2, 0.9, 0.5]))

    truth = torch.tensor([0.3, 0.8, 0.5, 1.0])
    target = render(*make({})[:2], background=truth.expand(S, S, 4).contiguous())
    bg = half.clone().requires_grad_(True)
    opt = torch.optim.Adam([bg], lr=0.02)
    for it in range(150):
        opt.zero_grad()
        img = render(*make({})[:2], background=bg.expand(S, S, 4), seed=it)
        ((img - target) ** 2).mean().backward()
        opt.step()
        with torch.no_grad():
            bg.clamp_(0, 1)
    close(bg.detach(), truth, 0.02)


# --------------------------------------------------------------------------- sdf

@pytest.mark.slow
def test_sdf_output():
    """OutputType.sdf: signed distances (negative inside) equal the exact ones, and fitting
    an ellipse and a rect to a target sdf brings their parameters back (0.05 px)."""
    def make(p):
        shapes = [pydiffvg.Ellipse(p["r"], p["c"]), pydiffvg.Rect(p["lo"], torch.tensor([36.0, 36.0]))]
        groups = [pydiffvg.ShapeGroup(torch.tensor([0]), BLUE), pydiffvg.ShapeGroup(torch.tensor([1]), BLUE)]
        return shapes, groups, dict(output_type=pydiffvg.OutputType.sdf)

    with torch.no_grad():
        disk = make({"r": torch.tensor([8.0, 8.0]), "c": torch.tensor([14.0, 12.0]), "lo": torch.tensor([50.0, 50.0])})
        sdf = render(disk[0][:1], disk[1][:1], **disk[2])
    ys, xs = torch.meshgrid(torch.arange(S) + 0.5, torch.arange(S) + 0.5, indexing="ij")
    exact = torch.sqrt((xs - 14) ** 2 + (ys - 12) ** 2) - 8
    assert sdf.shape == (S, S, 1)
    close(sdf[..., 0], exact, 1e-3)
    # rendered at 24 x 24 (the canvas stays 40 x 40): every pixel measures every shape
    truth = {"r": torch.tensor([9.0, 6.0]), "c": torch.tensor([14.0, 13.0]), "lo": torch.tensor([26.0, 28.0])}
    got = fit(make, truth, {"r": torch.tensor([7.0, 7.0]), "c": torch.tensor([16.0, 11.0]),
                            "lo": torch.tensor([24.0, 30.0])}, iterations=100, lr=0.3, size=24)
    for k in truth:
        close(got[k], truth[k], 0.05)


@pytest.mark.slow
def test_sdf_at_eval_positions():
    """eval_positions: N x 1 distances at the given points; a circle fitted to the
    distances at 8 points comes back (0.05 px), and the points' own gradient is the
    distance's direction."""
    g = torch.Generator().manual_seed(1)
    points = torch.rand(8, 2, generator=g) * S

    def sdf(r, c, positions=points):
        args = pydiffvg.RenderFunction.serialize_scene(
            S, S, [pydiffvg.Circle(r, c)], [pydiffvg.ShapeGroup(torch.tensor([0]), BLUE)],
            output_type=pydiffvg.OutputType.sdf, eval_positions=positions)
        return pydiffvg.RenderFunction.apply(S, S, 1, 1, 0, None, *args)

    target = sdf(torch.tensor(10.0), torch.tensor([21.0, 17.0]))
    exact = (points - torch.tensor([21.0, 17.0])).norm(dim=1, keepdim=True) - 10
    assert target.shape == (8, 1)
    close(target, exact, 1e-3)
    r, c = torch.tensor(7.0, requires_grad=True), torch.tensor([18.0, 20.0], requires_grad=True)
    opt = torch.optim.Adam([r, c], lr=0.5)
    decay = torch.optim.lr_scheduler.LambdaLR(opt, lambda i: 0.05 + 0.475 * (1 + math.cos(math.pi * i / 100)))
    for _ in range(100):
        opt.zero_grad()
        ((sdf(r, c) - target) ** 2).mean().backward()
        opt.step()
        decay.step()
    close(r.detach(), 10.0, 0.05)
    close(c.detach(), [21.0, 17.0], 0.05)
    p = torch.tensor([[30.0, 17.0]], requires_grad=True)
    sdf(torch.tensor(10.0), torch.tensor([21.0, 17.0]), p).sum().backward()
    close(p.grad, [[1.0, 0.0]], 1e-3)


@pytest.mark.slow
def test_colour_at_eval_positions():
    """Colour output at eval_positions: N x 4 straight RGBA at the points, and a linear
    gradient's end point fitted to the colours at 6 points comes back (0.05 px)."""
    pos = torch.tensor([[4.0, 10.0], [12.0, 5.0], [20.0, 15.0], [28.0, 8.0], [36.0, 12.0], [20.0, 30.0]])
    stops = torch.tensor([[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]])

    def colours(begin, end):
        shapes = [pydiffvg.Rect(torch.tensor([0.0, 0.0]), torch.tensor([40.0, 20.0])),
                  pydiffvg.Circle(torch.tensor(5.0), torch.tensor([20.0, 30.0]))]
        groups = [pydiffvg.ShapeGroup(torch.tensor([0]), pydiffvg.LinearGradient(begin, end, torch.tensor([0.0, 1.0]),
                                                                                  stops)),
                  pydiffvg.ShapeGroup(torch.tensor([1]), torch.tensor([0.0, 1.0, 0.0, 0.5]))]
        args = pydiffvg.RenderFunction.serialize_scene(S, S, shapes, groups, eval_positions=pos)
        return pydiffvg.RenderFunction.apply(S, S, 2, 2, 0, None, *args)

    target = colours(torch.tensor([2.0, 0.0]), torch.tensor([38.0, 6.0]))
    assert target.shape == (6, 4)
    close(target[5], [0.0, 1.0, 0.0, 0.5], 1e-6)  # the circle's centre
    t = ((pos[0] - torch.tensor([2.0, 0.0])) @ torch.tensor([36.0, 6.0])) / (36.0 ** 2 + 6.0 ** 2)
    close(target[0], (1 - t) * stops[0] + t * stops[1], 1e-5)
    # (begin can slide across the gradient's direction without changing any colour: fit end)
    end = torch.tensor([34.0, 3.0], requires_grad=True)
    opt = torch.optim.Adam([end], lr=0.5)
    for _ in range(150):
        opt.zero_grad()
        ((colours(torch.tensor([2.0, 0.0]), end) - target) ** 2).sum().backward()
        opt.step()
    close(end.detach(), [38.0, 6.0], 0.05)


# ------------------------------------------------------------------ render_grad

@pytest.mark.parametrize("prefiltering", [True, False])
def test_render_grad_sums_to_the_translation_gradient(prefiltering):
    """render_grad's image sums to dL/d(translation of the scene), here from autograd
    through a translation in every shape_to_canvas; analytical mode within 2%, Monte
    Carlo (4 x 4 samples, a per-pixel estimate) within 10%."""
    weights = torch.rand(S, S, 4, generator=torch.Generator().manual_seed(5))
    shapes = [pydiffvg.Path(torch.tensor([2, 2, 2]), BLOB.clone(), True),
              pydiffvg.Circle(torch.tensor(6.0), torch.tensor([28.0, 26.0]))]
    t = torch.zeros(2, requires_grad=True)
    move = torch.cat([torch.cat([torch.eye(2), t[:, None]], dim=1), torch.tensor([[0.0, 0.0, 1.0]])])
    grad = pydiffvg.LinearGradient(torch.tensor([5.0, 5.0]), torch.tensor([35.0, 30.0]), torch.tensor([0.0, 1.0]),
                                   torch.tensor([[0.9, 0.2, 0.1, 1.0], [0.1, 0.2, 0.9, 1.0]]))
    groups = [pydiffvg.ShapeGroup(torch.tensor([0]), grad, shape_to_canvas=move),
              pydiffvg.ShapeGroup(torch.tensor([1]), torch.tensor([0.2, 0.8, 0.2, 1.0]), shape_to_canvas=move,
                                  stroke_color=torch.tensor([0.0, 0.0, 0.0, 1.0]))]
    # the gradient paint is in canvas coordinates: it moves with the scene too
    grad.begin = torch.tensor([5.0, 5.0]) + t
    grad.end = torch.tensor([35.0, 30.0]) + t
    samples = 1 if prefiltering else 4
    args = pydiffvg.RenderFunction.serialize_scene(S, S, shapes, groups, use_prefiltering=prefiltering)
    img = pydiffvg.RenderFunction.apply(S, S, samples, samples, 0, None, *args)
    (img * weights).sum().backward()
    expected = t.grad.clone()
    per_pixel = pydiffvg.RenderFunction.render_grad(weights, S, S, samples, samples, 0, None, *args)
    assert per_pixel.shape == (S, S, 2)
    total = per_pixel.sum(dim=(0, 1))
    tol = 0.02 if prefiltering else 0.1
    assert float((total - expected).norm()) <= tol * float(expected.norm()), (total, expected)


# ------------------------------------------------------------- the adapter itself

def test_gradients_equal_vecfit_render():
    """The same scene built with pydiffvg and with vecfit's own Scene: equal images and
    equal gradients (same seed, same samples)."""
    pts = BLOB.clone().requires_grad_(True)
    color = torch.tensor([0.2, 0.5, 0.7, 0.8], requires_grad=True)
    half = torch.tensor(1.5, requires_grad=True)
    stroke = torch.tensor([0.1, 0.1, 0.1, 1.0], requires_grad=True)
    shapes = [pydiffvg.Path(torch.tensor([2, 2, 2]), pts, True, stroke_width=half)]
    groups = [pydiffvg.ShapeGroup(torch.tensor([0]), color, use_even_odd_rule=False, stroke_color=stroke)]
    weights = torch.rand(S, S, 4, generator=torch.Generator().manual_seed(3))
    (render(shapes, groups, seed=7) * weights).sum().backward()
    ours = [t.grad.clone() for t in (pts, color, half, stroke)]

    pts2, color2, half2, stroke2 = (t.detach().clone().requires_grad_(True) for t in (pts, color, half, stroke))
    geometry = vs.Path(points=pts2, degrees=np.array([3, 3, 3]), subpaths=[(0, 3, True)])
    scene = vs.Scene(width=S, height=S, shapes=[
        vs.Shape(geometry=geometry, stroke=vs.Solid(stroke2), stroke_width=2 * half2, linecap="round",
                 linejoin="round"),
        vs.Shape(geometry=geometry, fill=vs.Solid(color2))])
    (vecfit.render(scene, S, S, samples=2, seed=7) * weights).sum().backward()
    for a, b in zip(ours, (pts2.grad, color2.grad, half2.grad, stroke2.grad)):
        assert torch.allclose(a, b, rtol=1e-5, atol=1e-5)


def test_same_objects_rendered_again_see_their_changes():
    """The adapter reuses what it built for the same tensors (see convert._reuse): values
    changed in place, a reassigned attribute and changed shape ids must all show, and
    the images equal those of freshly made objects."""
    pts = BLOB.clone().requires_grad_(True)
    path = pydiffvg.Path(torch.tensor([2, 2, 2]), pts, True)
    disk = pydiffvg.Circle(torch.tensor(5.0), torch.tensor([30.0, 30.0]))
    group = pydiffvg.ShapeGroup(torch.tensor([0]), BLUE.clone())

    def image(shapes, color=None, index=0):
        fresh = pydiffvg.ShapeGroup(torch.tensor([index]), BLUE.clone() if color is None else color)
        return render(shapes, [fresh]).detach()

    first = render([path, disk], [group])
    first[..., 3].sum().backward()
    assert pts.grad.abs().sum() > 0
    with torch.no_grad():
        pts += 3.0  # in place, as an optimiser steps
    moved = render([path, disk], [group]).detach()
    assert (moved - first.detach()).abs().max() > 0.5
    assert torch.equal(moved, image([pydiffvg.Path(torch.tensor([2, 2, 2]), BLOB + 3.0, True), disk]))
    path.points = BLOB.clone()  # a new tensor
    assert torch.equal(render([path, disk], [group]).detach(), image([path, disk]))
    group.fill_color = torch.tensor([1.0, 0.0, 0.0, 1.0])
    assert torch.equal(render([path, disk], [group]).detach(), image([path, disk], group.fill_color))
    group.shape_ids[0] = 1  # in place: now the disk
    assert torch.equal(render([path, disk], [group]).detach(), image([path, disk], group.fill_color, 1))


def test_output_size_differs_from_canvas():
    shapes, groups, _ = one(pydiffvg.Circle(torch.tensor(10.0), torch.tensor([20.0, 20.0])))
    args = pydiffvg.RenderFunction.serialize_scene(S, S, shapes, groups)
    small = pydiffvg.RenderFunction.apply(20, 20, 4, 4, 0, None, *args)
    assert small.shape == (20, 20, 4)
    # the disk of radius 10 in a 40 px canvas covers radius 5 in the 20 px image
    cover = float(small[..., 3].sum())
    assert abs(cover - math.pi * 25) < 1.5


def test_modules_are_one():
    import vecfit.pydiffvg as inner
    assert pydiffvg is inner
    assert diffvg.FilterType.hann == pydiffvg.FilterType.hann


def test_from_svg_path():
    paths = pydiffvg.from_svg_path("M 10 10 C 20 0 30 0 40 10 L 40 30 Z M 0 0 L 5 5",
                                   shape_to_canvas=torch.tensor([[2.0, 0, 1], [0, 2.0, 0], [0, 0, 1]]))
    assert len(paths) == 2
    first, second = paths
    assert first.is_closed and first.num_control_points.tolist() == [2, 0, 0]
    assert torch.allclose(first.points[0], torch.tensor([21.0, 20.0]))
    assert first.points.shape == (5, 2)  # closed: the last line wraps to points[0]
    assert not second.is_closed and second.points.shape == (2, 2)


def test_imwrite_gamma_and_channels(tmp_path):
    from PIL import Image
    img = torch.full((2, 3, 4), 0.5)
    pydiffvg.imwrite(img, tmp_path / "sub" / "a.png")  # folders are made
    with Image.open(tmp_path / "sub" / "a.png") as im:
        px = im.convert("RGBA").getpixel((0, 0))
    assert px[:3] == (186, 186, 186) and px[3] == 128  # 0.5 ** (1 / 2.2) = 0.7297; alpha as is
    pydiffvg.imwrite(torch.tensor([[0.0, 1.0]]), tmp_path / "g.png", gamma=1.0)  # H x W: grey
    with Image.open(tmp_path / "g.png") as im:
        assert im.mode == "RGB" and im.getpixel((1, 0)) == (255, 255, 255)
