"""Crossed outlines cut into simple loops (vecfit/scene/untangle.py): the picture stays."""
from __future__ import annotations

import numpy as np
import pytest
import torch

import vecfit
from vecfit.renderer.raster import render
from vecfit.scene import Path, Scene, Shape, Solid
from vecfit.scene.segments import layout_of, segments_of, split_at
from vecfit.scene.crossings import crossed_subpaths, subpath_crossings
from vecfit.scene.untangle import cut_at, loop_area, untangle


def shape(points, degrees, fill_rule="nonzero", stroke=False):
    path = Path(points=torch.tensor(points, dtype=torch.float32), degrees=np.array(degrees),
                subpaths=[(0, len(degrees), True)])
    return Shape(path, fill=Solid(torch.tensor([0.8, 0.2, 0.1, 1.0])), fill_rule=fill_rule,
                 stroke=Solid(torch.tensor([0.0, 0.0, 0.0, 1.0])) if stroke else None)


FIGURE_EIGHT = ([[10, 10], [50, 50], [50, 10], [10, 50]], [1, 1, 1, 1])
# a cubic thrown into a loop (its own crossing at (30, 8.57)), closed by two lines
LOOPED = ([[10, 30], [70, -20], [-10, -20], [50, 30], [30, 40]], [3, 1, 1])
PENTAGRAM = ([[30 + 20 * np.sin(a), 30 - 20 * np.cos(a)] for a in np.arange(5) * 4 * np.pi / 5], [1] * 5)


def picture(scene):
    return render(scene, 64, 64, samples=4, seed=3).numpy()


def no_crossings(scene):
    for s in scene.shapes:
        g = s.geometry
        pts = g.points.detach().numpy().astype(np.float64)
        for (first, count, closed), (p0, n) in zip(g.subpaths, g.subpath_point_ranges()):
            assert not subpath_crossings(pts[p0:p0 + n], g.degrees[first:first + count], closed)


@pytest.mark.parametrize("case", [FIGURE_EIGHT, LOOPED, PENTAGRAM])
@pytest.mark.parametrize("fill_rule", ["nonzero", "evenodd"])
def test_cut_outlines_draw_the_same(case, fill_rule):
    scene = Scene(64, 64, [shape(*case, fill_rule=fill_rule)])
    before = picture(scene)
    assert crossed_subpaths(scene) == {(0, 0)}
    assert untangle(scene, min_area=0.0) == 1
    no_crossings(scene)
    assert len(scene.shapes[0].geometry.subpaths) > 1
    assert np.abs(picture(scene) - before).max() < 1e-6  # the same edges: the same winding numbers


def test_slivers_dropped_and_kept_crossings_stay():
    # a square whose corner is folded over into a triangle of 0.5 px²
    fold = [[10, 10], [40, 10], [40, 40], [11, 40], [10, 39.0], [10.5, 40.5]]
    scene = Scene(64, 64, [shape(fold, [1] * 6), shape(*PENTAGRAM)])
    assert crossed_subpaths(scene) == {(0, 0), (1, 0)}
    before = picture(scene)
    assert untangle(scene, keep={(1, 0)}) == 1
    assert len(scene.shapes[0].geometry.subpaths) == 1  # the fold is gone
    assert crossed_subpaths(scene) == {(1, 0)}  # the star the user drew is left as drawn
    assert np.abs(picture(scene) - before).sum() < 1.0  # under a square pixel of coverage


def test_cut_at_a_crossing_point():
    segs = segments_of(np.array(FIGURE_EIGHT[0], float), FIGURE_EIGHT[1], True)
    a, b = cut_at(segs, 0, 0.5, 2, 0.5, (30, 30))
    assert [len(x) for x in (a, b)] == [3, 3]
    assert abs(loop_area(a)) == pytest.approx(400) and abs(loop_area(b)) == pytest.approx(400)
    assert loop_area(a) * loop_area(b) < 0  # the figure-eight's two lobes turn opposite ways
    points, degrees = layout_of(a, True)
    assert np.allclose(points[0], [30, 30]) and degrees == [1, 1, 1]
    left, right = split_at(np.array([[0, 0], [10, 20], [20, 0]], float), 0.25)
    assert np.allclose(left[-1], right[0]) and np.allclose(left[-1], [5, 7.5])


def test_refine_keeps_the_users_crossing(tmp_path):
    """A pentagram drawn by the user (even-odd) stays one crossing outline after refine."""
    points = " ".join(f"{x:.3f},{y:.3f}" for x, y in PENTAGRAM[0])
    svg = (f'<svg xmlns="http://www.w3.org/2000/svg" width="64" height="64">'
           f'<polygon id="star" points="{points}" fill="#c03020" fill-rule="evenodd"/></svg>')
    target = np.ones((64, 64, 3), np.float32)
    target[20:44, 20:44] = (0.7, 0.2, 0.1)
    out, report = vecfit.refine(target, svg, settings={"optimize": {"iterations": 5}})
    assert report["untangled_outlines"] == 0
    path = tmp_path / "star.svg"
    path.write_text(out)
    scene = vecfit.load_svg(path)  # (a background rect first: the star leaves the canvas uncovered)
    star = next(i for i, s in enumerate(scene.shapes) if s.source == "star")
    assert crossed_subpaths(scene) == {(star, 0)}


def test_a_loop_within_a_few_rounding_steps_is_left_whole_not_cut_for_ever():
    """Cut at its crossing, a figure-eight a few hundredths of a pixel wide rounds (at 2
    decimals) to segments that cross again at every cut: it is left whole (the callers
    drop it by its area); the same figure at full size is still cut in two."""
    def eight(size):
        return [np.array([[0, 0], [size, size], [size, -size], [0, 0]], float),
                np.array([[0, 0], [-size, size], [-size, -size], [0, 0]], float)]
    from vecfit.scene.untangle import simple_loops
    assert len(simple_loops(eight(0.03), 1e-4, 2)) == 1
    assert len(simple_loops(eight(30.0), 1e-4, 2)) == 2


def test_a_loop_crossed_at_its_own_start_is_cut_at_its_other_crossings():
    # a refined kitty trace's outline (Illustrator's, refined at the defaults): a cubic
    # that loops through its neighbours, and a crossing reported where the loop closes,
    # whose cut cuts off nothing; untangling left it whole, crossed
    from vecfit.scene.untangle import simple_loops
    points = np.array([[265.74, 335.54], [268.73, 337.92], [266.83, 332.94], [275.36, 343.39],
                       [267.05, 334.44], [269.48, 338.13], [268.81, 335.32], [266.74, 338.66],
                       [266.46, 338.07], [266.84, 337.35], [267.64, 336.58], [266.89, 336.31],
                       [266.24, 335.97], [265.74, 335.54]])
    degrees = [3, 3, 1, 3, 3, 1]
    assert subpath_crossings(points, degrees, True, 0.01)
    loops = simple_loops(segments_of(points, degrees, True), 0.01, 2)
    assert len(loops) > 1
    for loop in loops:
        assert subpath_crossings(*layout_of(loop, True), True, 0.01) == []


@pytest.mark.slow
def test_an_outline_with_many_crossings_is_checked_in_a_few_batches(monkeypatch):
    # a coiled ribbon (a prolate trochoid, 40 loops, closed below): 40 crossings. Checking
    # the rest of the outline again after every cut made a gradient emoji's outline take
    # 1,300 s; the crossings found are handed on to the loops each cut makes, and the loops
    # handed none are checked together
    import vecfit.scene.untangle as untangle_module
    turns = 40
    t = np.linspace(0, 2 * np.pi * turns, 24 * turns + 1)
    coil = np.stack([20 + 5 * t, 40 + 12 * np.sin(t)], axis=1)
    coil[:, 0] -= 12 * np.cos(t) - 12
    points = np.concatenate([coil, [[coil[-1, 0], 70.0], [coil[0, 0], 70.0]]])
    segs = [np.array([points[k], points[(k + 1) % len(points)]]) for k in range(len(points))]
    assert len(subpath_crossings(*layout_of(segs, True), True, 0.01)) == turns
    calls = []
    real = untangle_module.many_subpath_crossings
    monkeypatch.setattr(untangle_module, "many_subpath_crossings", lambda jobs: calls.append(len(jobs)) or real(jobs))
    loops = untangle_module.simple_loops(segs, 0.01, 2)
    assert len(loops) == turns + 1
    assert len(calls) <= 3, calls  # the outline, then its loops together (and any a rounding crossed)
    for loop in loops:
        assert subpath_crossings(*layout_of(loop, True), True, 0.01) == []
    # the same signed area, to the rounding of 963 points to 2 decimals
    assert abs(sum(loop_area(loop) for loop in loops) - loop_area(segs)) < 1e-4 * abs(loop_area(segs))
