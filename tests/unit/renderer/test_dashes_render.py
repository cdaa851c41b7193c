"""Dashed strokes drawn (Shape.dash_array, dash_offset; vecfit/renderer/pack.py): the same
image as the dashes drawn as separate paths, dots for zero-length dashes with round and
square caps (nothing with butt caps), the fill untouched, circles, ellipses and rects
dashed from SVG's start point, the persistent pack declined, and a pattern making too
many dashes drawn solid with a warning. Gradients: tests/oracles/test_gradients.py."""
from __future__ import annotations

import time
import warnings

import numpy as np
import pytest
import torch

import vecfit
from vecfit import limits
from vecfit.renderer.persistent import PersistentPack
from vecfit.fitting.rates import parameter_kinds
from vecfit.scene import Circle, Ellipse, Path, Rect, Scene, Shape, Solid
from vecfit.errors import VecfitWarning

BLACK = Solid(torch.tensor([0.0, 0.0, 0.0, 1.0]))
RED = Solid(torch.tensor([1.0, 0.0, 0.0, 1.0]))


def line(x0=10.0, x1=90.0, y=20.0) -> Path:
    return Path(points=torch.tensor([[x0, y], [x1, y]]), degrees=np.array([1]), subpaths=[(0, 1, False)])


def draw(*shapes, width=100, height=40, **kw):
    kw.setdefault("samples", 4)
    return vecfit.render(Scene(width=width, height=height, shapes=list(shapes)), **kw)[..., 3]


def test_dashes_draw_as_the_separate_pieces():
    dashed = draw(Shape(geometry=line(), stroke=BLACK, stroke_width=torch.tensor(6.0), dash_array=(10.0, 10.0)))
    pieces = Path(points=torch.tensor([[10.0, 20.0], [20.0, 20.0], [30.0, 20.0], [40.0, 20.0],
                                       [50.0, 20.0], [60.0, 20.0], [70.0, 20.0], [80.0, 20.0]]),
                  degrees=np.array([1, 1, 1, 1]), subpaths=[(i, 1, False) for i in range(4)])
    separate = draw(Shape(geometry=pieces, stroke=BLACK, stroke_width=torch.tensor(6.0)))
    assert torch.allclose(dashed, separate, atol=1e-6)
    assert float(dashed[20, 15]) == 1.0 and float(dashed[20, 25]) == 0.0


@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_zero_length_dashes_with_round_caps_are_dots(mode):
    """0 20 on 10..90: dots at 10, 30, 50, 70 (an interval starting at the path's end is
    not drawn, as resvg), of the stroke's width; square caps draw axis-aligned squares."""
    def alpha(cap):
        return draw(Shape(geometry=line(), stroke=BLACK, stroke_width=torch.tensor(8.0), linecap=cap,
                          dash_array=(0.0, 20.0)), mode=mode, **({"samples": 1} if mode == "analytic" else {}))
    round_ = alpha("round")
    for x in (10, 30, 50, 70):
        assert float(round_[20, x]) > 0.99 and float(round_[20, x - 1]) > 0.99
        assert float(round_[22, x + 1]) > 0.99  # inside the disc of radius 4
    for x in (20, 40, 60, 90, 94):
        assert float(round_[20, x]) < 0.01
    total = float(round_.sum())
    assert abs(total - 4 * np.pi * 16) < 4  # four discs of radius 4
    square = alpha("square")
    assert abs(float(square.sum()) - 4 * 64) < 2 and float(square[23, 33]) > 0.99  # a corner of 30's square
    assert float(round_[23, 33]) < 0.5
    assert float(alpha("butt").sum()) == 0.0


def test_fill_is_not_dashed():
    rect = Rect(torch.tensor([20.0, 10.0]), torch.tensor([80.0, 30.0]))
    dashed = Shape(geometry=rect, fill=RED, stroke=BLACK, stroke_width=torch.tensor(2.0), dash_array=(4.0, 4.0))
    solid = Shape(geometry=rect, fill=RED)
    scene = vecfit.render(Scene(width=100, height=40, shapes=[dashed]), samples=4)
    fill_only = vecfit.render(Scene(width=100, height=40, shapes=[solid]), samples=4)
    assert torch.allclose(scene[15:26, 25:76], fill_only[15:26, 25:76])
    # the rect starts at (x, y): its first dash covers 20..24 along the top edge
    assert float(scene[10, 22, 0]) < 0.01 and float(scene[10, 26, 0]) > 0.99


@pytest.mark.parametrize("geometry", [
    Circle(torch.tensor([50.0, 20.0]), torch.tensor(12.0)),
    Ellipse(torch.tensor([50.0, 20.0]), torch.tensor([30.0, 12.0])),
    Rect(torch.tensor([20.0, 8.0]), torch.tensor([80.0, 32.0]), torch.tensor([6.0, 4.0])),
], ids=["circle", "ellipse", "rounded-rect"])
def test_shapes_are_dashed_from_svgs_start(geometry):
    from vecfit.scene.dashes import dash_path, outline_path
    stroke = dict(stroke=BLACK, stroke_width=torch.tensor(2.0))
    dashed = draw(Shape(geometry=geometry, dash_array=(5.0, 3.0), dash_offset=1.0, **stroke))
    pieces = draw(Shape(geometry=dash_path(outline_path(geometry), (5.0, 3.0), 1.0), **stroke))
    assert torch.allclose(dashed, pieces, atol=1e-6)
    solid = draw(Shape(geometry=geometry, **stroke))
    assert 0.4 < float(dashed.sum()) / float(solid.sum()) < 0.8  # about 5/8 of the outline


def test_persistent_pack_declines_dashed_scenes(tmp_path):
    svg = tmp_path / "d.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="64" height="48">'
                   '<path d="M 5 5 L 60 40" stroke="black" stroke-width="3" stroke-dasharray="4 2"/></svg>')
    scene = vecfit.load_svg(svg)
    assert PersistentPack.build(scene, 64, 48, parameter_kinds(scene, {"colors": 0.01}, 64, 48)) is None
    scene.shapes[0].dash_array = None
    assert PersistentPack.build(scene, 64, 48, parameter_kinds(scene, {"colors": 0.01}, 64, 48)) is not None


def test_too_many_dashes_draw_solid_with_a_warning():
    long = Path(points=torch.tensor([[0.0, 20.0], [1e6, 20.0], [0.0, 20.0]]), degrees=np.array([1, 1]),
                subpaths=[(0, 2, False)])
    dashed = Shape(geometry=long, stroke=BLACK, stroke_width=torch.tensor(4.0), dash_array=(1e-3, 1e-3),
                   source="wire")
    start = time.perf_counter()
    with pytest.warns(VecfitWarning, match=f"wire: stroke-dasharray makes more than {limits.MAX_DASHES} dashes in the scene"):
        image = draw(dashed)
    solid = draw(Shape(geometry=long, stroke=BLACK, stroke_width=torch.tensor(4.0)))
    assert torch.equal(image, solid) and time.perf_counter() - start < 10


def test_dashed_points_get_gradients():
    points = torch.tensor([[10.0, 20.0], [50.0, 5.0], [90.0, 20.0]], requires_grad=True)
    widths = torch.tensor([2.0, 4.0, 6.0], requires_grad=True)
    path = Path(points=points, degrees=np.array([2]), subpaths=[(0, 1, False)], widths=widths)
    image = vecfit.render(Scene(width=100, height=40, shapes=[
        Shape(geometry=path, stroke=BLACK, dash_array=(7.0, 4.0), dash_offset=-2.0, linecap="round")]), samples=2)
    image[..., 3].sum().backward()
    assert points.grad.abs().sum() > 0 and widths.grad.abs().sum() > 0
    assert torch.isfinite(points.grad).all() and torch.isfinite(widths.grad).all()


def test_the_reader_and_the_packer_count_dashes_alike(tmp_path, monkeypatch):
    """One count (scene.dashes.DashBudget) for the reader and the packer: of two strokes
    that each fit the limit but not together, the reader keeps the first and notes the
    second; the packer then draws the scene it read without a warning, and a Scene made
    with both patterns gets the first dashed and the second solid, with a warning."""
    monkeypatch.setattr(limits, "MAX_DASHES", 43)  # (one dash short of both: 20 drawn + 2 each)
    svg = tmp_path / "d.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="40">'
                   '<path id="a" d="M 10 10 H 90" stroke="black" stroke-width="2" stroke-dasharray="2 2"/>'
                   '<path id="b" d="M 10 30 H 90" stroke="black" stroke-width="2" stroke-dasharray="2 2"/></svg>')
    with pytest.warns(VecfitWarning, match="stroke-dasharray"):
        scene = vecfit.load_svg(svg)  # 22 dashes each (20 + the pattern's 2)
    assert scene.shapes[0].dash_array == (2.0, 2.0) and scene.shapes[1].dash_array is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        image = vecfit.render(scene, samples=4)[..., 3]
    scene.shapes[1].dash_array = (2.0, 2.0)
    scene.shapes[1].source = "b"
    with pytest.warns(VecfitWarning, match="b: stroke-dasharray makes more than 43 dashes"):
        again = vecfit.render(scene, samples=4)[..., 3]
    assert torch.equal(image, again)
    assert 0.3 < float(image[10].sum()) / float(image[30].sum()) < 0.7  # a dashed row, a solid one
