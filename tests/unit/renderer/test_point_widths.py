"""Per-point stroke widths (Path.widths): forward geometry and gradients, both modes.

Gradients use the finite-difference harness of test_gradients (same loss, same seed on
both sides, 16 x 16 samples and 32 boundary samples per pixel in Monte Carlo mode).
Tolerances, as there: Monte Carlo 10% of |fd| on each parameter's gradient vector (plus
0.5), analytical prefilter 2% (plus 0.01). Measured when written: Monte Carlo 0.4-3%,
analytical 0.1-0.8% (the hw'(t*) dt*/dtheta term of the analytical sweep distance is
needed: without it the point gradients of these tests are 23-27% off).
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest
import torch

import vecfit
from helpers import brute_force, slow_unless
from test_gradients import OFF_GRID, W, background, check, solid
from vecfit.errors import VecfitError
from vecfit.scene import Path, Scene, Shape

CURVE = torch.tensor([[7.0, 30.0], [12.0, 5.0], [26.0, 36.0], [33.0, 10.0]])
CURVE_WIDTHS = torch.tensor([2.0, 6.0, 3.0, 5.0])
POLYGON = torch.tensor([[8.0, 10.0], [30.0, 6.0], [33.0, 28.0], [18.0, 34.0], [6.0, 24.0]])
POLYGON_WIDTHS = torch.tensor([2.0, 6.0, 3.0, 5.0, 1.0])


def report(errors):
    """Prints the measured errors (pytest -s shows them)."""
    print(" ".join(f"{k}: {err / max(scale, 1e-30):.2%} of |fd| = {scale:.3g}" for k, (err, scale) in errors.items()))


def line_scene(widths, cap="butt"):
    path = Path(points=torch.tensor([[10.0, 32.0], [54.0, 32.0]]), degrees=np.array([1]),
                subpaths=[(0, 1, False)], widths=widths)
    return Scene(width=64, height=64, shapes=[Shape(geometry=path, stroke=solid(0, 0, 0, 1), linecap=cap)])


# -------------------------------------------------------------------------- forward

@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_tapered_line_covers_the_trapezoid(mode):
    """Widths 2 -> 10 along a 44 px line with butt caps: (2 + 10) / 2 * 44 = 264 px^2."""
    img = vecfit.render(line_scene(torch.tensor([2.0, 10.0])), samples=8 if mode == "mc" else 1, mode=mode)
    area = float(img[..., 3].sum())
    assert abs(area - 264) <= 0.01 * 264, area


def mixed_paths(widths, cap, join, transform=None):
    """An open cubic-and-lines path, a closed polygon, a zero-length subpath and a
    quadratic followed by a nearly straight cubic, with
    per-point widths (widths: a callable giving a path's widths from its point count) or
    the uniform stroke width 3.5."""
    paths = [Path(points=torch.tensor([[6.0, 30.0], [11.0, 5.0], [20.0, 31.0], [34.0, 12.0], [27.0, 8.0],
                                       [20.0, 20.0]]), degrees=np.array([3, 1, 1]), subpaths=[(0, 3, False)]),
             Path(points=torch.tensor([[5.0, 5.0], [15.0, 3.0], [12.0, 14.0], [4.0, 12.0]]),
                  degrees=np.array([1, 1, 1, 1]), subpaths=[(0, 4, True)]),
             Path(points=torch.tensor([[30.0, 34.0], [30.0, 34.0]]), degrees=np.array([1]), subpaths=[(0, 1, False)]),
             # a quadratic, then a cubic within 1e-3 px of its chord (stroked as a line)
             Path(points=torch.tensor([[22.0, 36.0], [28.0, 24.0], [36.0, 30.0], [36.0004, 33.0], [35.9997, 35.0],
                                       [36.0, 38.0]]), degrees=np.array([2, 3]), subpaths=[(0, 2, False)])]
    shapes = []
    for p in paths:
        if widths is not None:
            p.widths = widths(len(p.points))
        shapes.append(Shape(geometry=p, stroke=solid(0.1, 0.2, 0.8, 0.9), stroke_width=torch.tensor(3.5),
                            linecap=cap, linejoin=join,
                            transform=transform if transform is not None else torch.eye(3)))
    return Scene(width=40, height=40, shapes=shapes)


ANISOTROPIC = torch.tensor([[1.0, 0.3, 2.0], [0.1, 0.8, 1.0], [0.0, 0.0, 1.0]])


@pytest.mark.parametrize("mode", ["mc", "analytic"])
@pytest.mark.parametrize("cap,join", [("butt", "miter"), ("round", "round"), ("square", "bevel")])
@pytest.mark.parametrize("skew", [False, True])
def test_equal_widths_render_as_the_uniform_width(mode, cap, join, skew):
    transform = ANISOTROPIC if skew else None
    n = 4 if mode == "mc" else 1
    uniform = vecfit.render(mixed_paths(None, cap, join, transform), samples=n, mode=mode)
    per_point = vecfit.render(mixed_paths(lambda k: torch.full((k,), 3.5), cap, join, transform), samples=n, mode=mode)
    assert float((uniform - per_point).abs().max()) <= 1e-4


def tapered_cubic(cap, join, scale=1.0):
    pts = torch.tensor([[7.0, 30.0], [12.0, 5.0], [26.0, 36.0], [33.0, 10.0], [36.0, 30.0], [20.0, 36.0]]) * scale
    widths = torch.tensor([1.0, 8.0, 2.0, 6.0, 0.5, 4.0]) * scale
    path = Path(points=pts, degrees=np.array([3, 1, 1]), subpaths=[(0, 3, False)], widths=widths)
    return Scene(width=40 * scale, height=40 * scale, shapes=[Shape(
        geometry=path, stroke=solid(0, 0, 0, 1), linecap=cap, linejoin=join)])


@pytest.mark.parametrize("cap,join", [("round", "round"), ("butt", "miter"), ("square", "bevel")])
def test_tapered_strokes_have_no_cracks(cap, join):
    """A tapered cubic with joins and caps, 2x scale: Monte Carlo (8 x 8) and the
    analytical prefilter cover the same area (within 0.5%), and wherever the analytical
    image is opaque over a whole 3 x 3 neighbourhood (deep inside the stroke) every Monte
    Carlo sample is inside too: no crack between sweeps, joins and caps."""
    scene = tapered_cubic(cap, join, scale=2.0)
    mc = vecfit.render(scene, samples=8)[..., 3]
    an = vecfit.render(scene, samples=1, mode="analytic")[..., 3]
    assert abs(float(mc.sum()) - float(an.sum())) <= 0.005 * float(an.sum())
    deep = -torch.nn.functional.max_pool2d(-(an == 1).float()[None, None], 3, stride=1, padding=1)[0, 0] > 0
    assert int(deep.sum()) > 100
    assert float(mc[deep].min()) == 1.0


@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_tiles_match_brute_force(mode):
    scene = tapered_cubic("round", "miter", scale=2.0)
    n = 2 if mode == "mc" else 1
    tiled = vecfit.render(scene, samples=n, mode=mode)
    with brute_force():
        brute = vecfit.render(scene, samples=n, mode=mode)
    assert torch.equal(tiled, brute)


# ------------------------------------------------------------------------ gradients

def check_points_and_widths(build, points, widths, mode):
    """Finite differences of points and widths in either mode: MC with 0.3 px steps; the
    analytical prefilter with 0.01 steps, off the pixel grid, to 2% (+0.01)."""
    if mode == "mc":
        errors = check(build, {"points": points, "widths": widths}, {"points": 0.3, "widths": 0.3})
    else:
        errors = check(build, {"points": points + OFF_GRID, "widths": widths}, {"points": 0.01, "widths": 0.01},
                       rtol=0.02, atol=0.01, mode="analytic")
    report(errors)


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["mc", "analytic"])
@pytest.mark.parametrize("cap", ["butt", "round"])
def test_tapered_open_cubic_gradients(mode, cap):
    def build(points, widths):
        path = Path(points=points, degrees=np.array([3]), subpaths=[(0, 1, False)], widths=widths)
        return Scene(width=40, height=40, shapes=[background(), Shape(
            geometry=path, stroke=solid(0.1, 0.3, 0.9, 1), linecap=cap)])
    check_points_and_widths(build, CURVE, CURVE_WIDTHS, mode)


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["mc", "analytic"])
@pytest.mark.parametrize("join", ["round", "miter"])
def test_closed_tapered_polygon_gradients(mode, join):
    def build(points, widths):
        path = Path(points=points, degrees=np.array([1, 1, 1, 1, 1]), subpaths=[(0, 5, True)], widths=widths)
        return Scene(width=40, height=40, shapes=[background(), Shape(
            geometry=path, stroke=solid(0.9, 0.3, 0.1, 1), linejoin=join, miter_limit=10)])
    check_points_and_widths(build, POLYGON, POLYGON_WIDTHS, mode)


@pytest.mark.parametrize("mode", slow_unless(["mc", "analytic"], ["analytic"]))
def test_steep_taper_gradients(mode):
    """Widths 1 -> 14 -> 2 over lines of 14 and 13 px (|hw'| / |B'| up to 0.46): the offset
    curves' normals and length elements are tilted well away from the curve's."""
    def build(points, widths):
        path = Path(points=points, degrees=np.array([1, 1]), subpaths=[(0, 2, False)], widths=widths)
        return Scene(width=40, height=40, shapes=[background(), Shape(
            geometry=path, stroke=solid(0.1, 0.3, 0.9, 1), linecap="round", linejoin="round")])
    pts, widths = torch.tensor([[10.0, 21.0], [24.0, 18.0], [30.0, 30.0]]), torch.tensor([1.0, 14.0, 2.0])
    check_points_and_widths(build, pts, widths, mode)


@pytest.mark.parametrize("mode", slow_unless(["mc", "analytic"], ["analytic"]))
def test_tapered_stroke_under_anisotropic_transform(mode):
    """Per-point widths live in stroke space (the shape's own space, uniformly scaled):
    gradients of the transform through the stroke metric and the widths' scale. (The
    analytical image is rough in the matrix at steps of 0.002 even with uniform widths,
    1-2% off; 0.0005 is in the linear range.)"""
    curve = torch.tensor([[5.13, 10.29], [12.0, 2.0], [22.0, 18.0], [30.17, 8.31]])

    def build(matrix, widths):
        path = Path(points=curve, degrees=np.array([3]), subpaths=[(0, 1, False)], widths=widths)
        return Scene(width=40, height=40, shapes=[background(), Shape(
            geometry=path, stroke=solid(0.1, 0.3, 0.9, 1), linecap="round", transform=matrix)])
    matrix = torch.tensor([[1.0, 0.3, 2.0], [0.1, 2.0, 1.0], [0.0, 0.0, 1.0]])
    widths = torch.tensor([1.0, 5.0, 2.0, 3.0])
    if mode == "mc":
        errors = check(build, {"matrix": matrix, "widths": widths}, {"matrix": 0.02, "widths": 0.3})
    else:
        errors = check(build, {"matrix": matrix, "widths": widths}, {"matrix": 0.0005, "widths": 0.01},
                       rtol=0.02, atol=0.05, mode="analytic")
    report(errors)


@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_equal_widths_gradients_sum_to_the_uniform_width_gradient(mode):
    """At equal widths, moving every point's width together is moving the uniform width."""
    def grads(per_point):
        w = torch.tensor(3.5, requires_grad=True)
        widths = torch.full((6,), 3.5, requires_grad=True)
        path = Path(points=torch.tensor([[6.0, 30.0], [11.0, 5.0], [20.0, 31.0], [34.0, 12.0], [27.0, 8.0],
                                         [20.0, 20.0]]) + OFF_GRID, degrees=np.array([3, 1, 1]),
                    subpaths=[(0, 3, False)], widths=widths if per_point else None)
        scene = Scene(width=40, height=40, shapes=[background(), Shape(
            geometry=path, stroke=solid(0.1, 0.2, 0.8, 1), stroke_width=w, linecap="round", linejoin="miter")])
        img = vecfit.render(scene, samples=4 if mode == "mc" else 1, mode=mode)
        (img * W).sum().backward()
        return float(widths.grad.sum()) if per_point else float(w.grad)
    a, b = grads(True), grads(False)
    assert abs(a - b) <= 1e-3 * abs(b), (a, b)


@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_no_nan_with_zero_widths_and_zero_length_segments(mode):
    """Widths of 0 at some points (ends, a miter join, a cubic's control point), a
    zero-length segment between points of different widths, a zero-length subpath, and a
    path whose widths are all 0 (draws nothing): gradients finite."""
    pts = torch.tensor([[6.0, 30.0], [12.0, 8.0], [20.0, 8.0], [20.0, 20.0], [20.0, 20.0], [32.0, 30.0],
                        [34.0, 10.0], [24.0, 6.0], [24.0, 6.0]], requires_grad=True)
    widths = torch.tensor([0.0, 0.0, 4.0, 0.0, 6.0, 3.0, 0.0, 2.0, 5.0], requires_grad=True)
    path = Path(points=pts, degrees=np.array([3, 1, 1, 1, 1]), subpaths=[(0, 4, False), (4, 1, False)],
                widths=widths)
    closed_pts = torch.tensor([[5.0, 5.0], [15.0, 4.0], [15.0, 4.0], [10.0, 14.0]], requires_grad=True)
    closed_widths = torch.tensor([0.0, 3.0, 0.0, 2.0], requires_grad=True)
    closed = Path(points=closed_pts, degrees=np.array([1, 1, 1, 1]), subpaths=[(0, 4, True)], widths=closed_widths)
    nothing_widths = torch.zeros(2, requires_grad=True)
    nothing = Path(points=torch.tensor([[4.0, 36.0], [36.0, 36.0]]), degrees=np.array([1]),
                   subpaths=[(0, 1, False)], widths=nothing_widths)
    shapes = [background(),
              Shape(geometry=path, stroke=solid(0, 0, 1, 1), linecap="round", linejoin="miter"),
              Shape(geometry=closed, fill=solid(1, 0, 0, 0.5), stroke=solid(0, 0, 0, 1), linejoin="miter"),
              Shape(geometry=nothing, stroke=solid(0, 0, 0, 1))]
    img = vecfit.render(Scene(width=40, height=40, shapes=shapes), samples=4 if mode == "mc" else 1, mode=mode)
    assert torch.isfinite(img).all()
    (img * W).sum().backward()
    for t in (pts, widths, closed_pts, closed_widths):
        assert t.grad is not None and torch.isfinite(t.grad).all()
        assert float(t.grad.abs().sum()) > 0
    assert nothing_widths.grad is None or torch.isfinite(nothing_widths.grad).all()


# ------------------------------------------------------------------- scene and SVG

def test_widths_are_stroke_width_parameters():
    widths = torch.tensor([2.0, 10.0])
    scene = line_scene(widths)
    kinds = scene.parameters()
    assert any(t is widths for t in kinds["stroke_widths"])
    assert not any(t is scene.shapes[0].stroke_width for t in kinds["stroke_widths"])  # replaced


def test_widths_must_match_the_points():
    with pytest.raises(VecfitError, match="one value per point"):
        vecfit.render(line_scene(torch.tensor([2.0, 10.0, 3.0])))


def test_svg_writer_averages_per_point_widths(tmp_path):
    src = tmp_path / "in.svg"
    src.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="64" height="64">'
                   '<path id="a" d="M10 32 L54 32" stroke="black" stroke-width="1" fill="none"/>'
                   '<path id="b" d="M10 12 L54 12" stroke="black" stroke-width="1" fill="none"/></svg>')
    from vecfit.svg import VecfitWarning, load_svg
    from vecfit.svg.write import write_svg
    scene = load_svg(src)
    for shape in scene.shapes:
        shape.geometry.widths = torch.tensor([2.0, 10.0])
    out = tmp_path / "out.svg"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        write_svg(scene, src, out)
    ours = [w for w in caught if issubclass(w.category, VecfitWarning)]
    assert len(ours) == 1 and "mean" in str(ours[0].message)
    written = load_svg(out)
    assert [float(s.stroke_width) for s in written.shapes] == [6.0, 6.0]
