"""Fewer nodes after the fit (vecfit/fitting/simplify.py): segments joined where the picture
cannot tell, within the budget in dB, and never past it."""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import vecfit
from vecfit.fitting.simplify import (_apart, _end_hooks, drop_unseen, fit_pairs, join_straight_runs,
                                     reduce_nodes, tidy_stroke_ends,
                                     straight_run_candidates, straighten)
from vecfit.renderer.raster import render
from vecfit.scene import Path, Scene, Shape, Solid
from vecfit.scene.segments import layout_of, split_at, subpath_segments
from vecfit.svg.stats import design_stats


def test_a_split_cubic_joins_back_into_itself():
    c = np.array([[0.0, 0.0], [10.0, 30.0], [40.0, 30.0], [50.0, 0.0]])
    a, b = split_at(c, 0.4)
    joined, worst, mean, length, _ = fit_pairs(a[None], b[None])
    assert worst[0] < 0.05 and mean[0] < 0.05  # (the split point searched on a grid)
    assert np.abs(joined[0] - c).max() < 0.5
    assert length[0] == pytest.approx(71.9, abs=0.5)  # the arc length, from the samples


def test_a_corner_does_not_join_cheaply():
    a = np.array([[0.0, 0.0], [10.0, 0.0], [20.0, 0.0], [30.0, 0.0]])
    b = np.array([[30.0, 0.0], [30.0, 10.0], [30.0, 20.0], [30.0, 30.0]])
    _, worst, _, _, _ = fit_pairs(a[None], b[None])
    assert worst[0] > 3.0


def disc_scene(pieces: int, extra_lines: bool = True) -> Scene:
    """A disc of ``pieces`` cubics (over-segmented: 4 would do) and a square whose sides
    are each two collinear lines."""
    segs = []
    k = 4 / 3 * math.tan(math.pi / (2 * pieces))
    centre, r = np.array([22.0, 32.0]), 14.0
    for i in range(pieces):
        t0, t1 = 2 * math.pi * i / pieces, 2 * math.pi * (i + 1) / pieces
        p0 = centre + r * np.array([math.cos(t0), math.sin(t0)])
        p3 = centre + r * np.array([math.cos(t1), math.sin(t1)])
        d0 = np.array([-math.sin(t0), math.cos(t0)])
        d1 = np.array([-math.sin(t1), math.cos(t1)])
        segs.append(np.stack([p0, p0 + k * r * d0, p3 - k * r * d1, p3]))
    points, degrees = layout_of(segs, True)
    disc = Shape(Path(points=torch.tensor(points, dtype=torch.float32), degrees=np.array(degrees),
                      subpaths=[(0, len(degrees), True)]), fill=Solid(torch.tensor([0.8, 0.2, 0.1, 1.0])))
    square = np.array([[40, 20], [50, 20], [60, 20], [60, 30], [60, 44], [50, 44], [40, 44], [40, 30]], float)
    sq = Shape(Path(points=torch.tensor(square, dtype=torch.float32), degrees=np.array([1] * 8),
                    subpaths=[(0, 8, True)]), fill=Solid(torch.tensor([0.1, 0.3, 0.8, 1.0])))
    return Scene(64, 64, [disc, sq])


def rgb(scene, samples=4):
    return render(scene, 64, 64, samples=samples, seed=3, background=[1, 1, 1, 1]).numpy()[..., :3]


def psnr(a, b):
    return -10 * np.log10(float(((a - b) ** 2).mean()))


def noisy(image):
    """A target the scenes do not match exactly (a photograph's grain): the budget is a
    share of an error that the renderer's own sampling noise does not dominate."""
    return image + np.random.default_rng(5).normal(0, 0.03, image.shape)


def test_reduce_nodes_keeps_the_picture_within_the_budget():
    target = noisy(rgb(disc_scene(4), 8))
    scene = disc_scene(16)
    before = psnr(rgb(scene), target)

    def measure(s):
        return float(((rgb(s) - target) ** 2).mean())

    stats = reduce_nodes(scene, measure, rgb(scene), (64, 64), budget_db=0.1, rounds=3)
    disc, square = (s.geometry for s in scene.shapes)
    assert stats["segments_before"] == 24
    assert len(disc.degrees) <= 8 and stats["joined"] >= 8
    # the square's collinear halves join into single lines; its corners stay
    assert list(square.degrees) == [1, 1, 1, 1]
    assert psnr(rgb(scene), target) >= before - 0.1
    assert stats["mse_after"] <= stats["mse_before"] * 10 ** 0.01 + 1e-12


def test_a_zero_budget_joins_only_what_costs_nothing():
    target = noisy(rgb(disc_scene(16), 8))
    scene = disc_scene(16)

    def measure(s):
        return float(((rgb(s) - target) ** 2).mean())

    stats = reduce_nodes(scene, measure, rgb(scene), (64, 64), budget_db=0.0)
    assert stats["mse_after"] <= stats["mse_before"] + 1e-12
    assert list(scene.shapes[1].geometry.degrees) == [1, 1, 1, 1]  # collinear lines join at no cost


@pytest.mark.slow
def test_trace_drops_nodes_within_a_tenth_of_a_db():
    """The job: a trace of a flat picture with the pass (the default) and without; the
    pass's report, fewer segments in the file, and the loss within the budget (the
    final figures are at the eval samples, a little noisier than the pass's own)."""
    image = np.ones((64, 64, 3), np.float32)
    yy, xx = np.mgrid[0:64, 0:64] + 0.5
    image[(xx - 24) ** 2 + (yy - 30) ** 2 < 15 ** 2] = (0.8, 0.2, 0.1)
    image[12:50, 44:58] = (0.1, 0.3, 0.8)
    settings = {"trace": {"paths": 4}, "optimize": {"iterations": 40}}
    off, report_off = vecfit.trace(image, settings={**settings, "optimize": {"iterations": 40, "simplify": 0}})
    on, report_on = vecfit.trace(image, settings=settings)
    assert report_off["simplified"] is None
    s = report_on["simplified"]
    assert s["segments_after"] <= s["segments_before"]
    assert s["mse_refined"] <= s["mse_before"] * 10 ** 0.01 + 1e-12
    assert design_stats(on)["segments"] <= design_stats(off)["segments"]
    assert report_on["optimized"]["psnr"] >= report_off["optimized"]["psnr"] - 0.15
    assert design_stats(on)["crossed_outlines"] == 0
    assert s["unseen"]["dropped"] <= s["unseen"]["candidates"]  # (the pass after the untangling)


def speck_scene(sliver: bool = True, dot: bool = True, island: bool = True) -> Scene:
    """A black path: a square, a sliver of 1 px² along its top edge (what a cut crossing
    leaves), a real dot of 3 px² apart from it and an island of 100 px² that a blue square
    drawn over the path covers with a margin."""
    square = [[10, 10], [34, 10], [34, 34], [10, 34]]
    loops = [square]
    if sliver:
        loops.append([[16, 10], [26, 9.8], [26, 10]])  # 10 px long, 0.2 px high: 1 px²
    if dot:
        loops.append([[42, 20], [44, 20], [44, 21.5], [42, 21.5]])
    if island:
        loops.append([[44, 44], [54, 44], [54, 54], [44, 54]])
    points, degrees, table = [], [], []
    for loop in loops:
        table.append((len(degrees), len(loop), True))
        points += loop
        degrees += [1] * len(loop)
    path = Path(points=torch.tensor(points, dtype=torch.float32), degrees=np.array(degrees), subpaths=table)
    cover = Path(points=torch.tensor([[40.0, 40], [58, 40], [58, 58], [40, 58]]), degrees=np.array([1, 1, 1, 1]),
                 subpaths=[(0, 4, True)])
    return Scene(64, 64, [Shape(path, fill=Solid(torch.tensor([0.0, 0.0, 0.0, 1.0]))),
                          Shape(cover, fill=Solid(torch.tensor([0.1, 0.3, 0.8, 1.0])))])


def rgb_at(scene, width, height):
    return render(scene, width, height, samples=4, seed=3, background=[1, 1, 1, 1]).numpy()[..., :3]


def test_a_sliver_and_a_hidden_piece_are_dropped_and_a_small_shape_kept():
    """The sliver's render is next to nothing against a target without it; the island is
    under the blue square; the dot (as small as the sliver, nearly) is part of the picture.
    The picture is the same, less the sliver."""
    target = rgb(speck_scene(sliver=False), 8)
    scene = speck_scene()
    before = float(((rgb(scene) - target) ** 2).mean())
    stats = drop_unseen(scene, rgb_at, target)
    assert stats["candidates"] == 3 and stats["dropped"] == 2
    path = scene.shapes[0].geometry
    assert [count for _, count, _ in path.subpaths] == [4, 4]  # the square and the dot
    assert float(((rgb(scene) - target) ** 2).mean()) < before
    assert np.abs(rgb(scene) - rgb(speck_scene(sliver=False, island=False))).max() == 0
    # a sliver the target shows (its pixels are a part of the picture) stays
    kept = speck_scene()
    stats = drop_unseen(kept, rgb_at, rgb(kept, 8))
    assert stats["dropped"] == 1 and len(kept.shapes[0].geometry.subpaths) == 3  # (the island went)


def test_subpaths_whose_boxes_do_not_meet_are_judged_in_one_render():
    """drop_unseen judges subpaths apart from one another together: their boxes are
    grouped so that none in a group meets another (boxes that only touch do not meet)."""
    boxes = [(0, 0, 10, 10), (5, 5, 15, 15), (10, 0, 20, 10), (12, 12, 30, 30), (40, 40, 50, 50)]
    groups = _apart([(0.0, 0, k, box) for k, box in enumerate(boxes)])
    assert [[c[2] for c in g] for g in groups] == [[0, 2, 3, 4], [1]]
    for g in groups:
        for a in g:
            for b in g:
                if a is not b:
                    (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = a[3], b[3]
                    assert ax1 <= bx0 or bx1 <= ax0 or ay1 <= by0 or by1 <= ay0
    # the speck scene's three candidates lie apart: one render with everything, one
    # without the three, then the whole picture's checks of the bisection
    seen = []
    target = rgb(speck_scene(sliver=False), 8)
    stats = drop_unseen(speck_scene(), lambda s, w, h: seen.append((w, h)) or rgb_at(s, w, h), target)
    assert stats["candidates"] == 3 and stats["renders"] == len(seen) <= 2 + 2
    assert seen[:2] == [(64, 64), (64, 64)]


def outline_scene(right: list, top_flat: bool = True) -> Scene:
    """A black outline from (10, 10): its top edge a cubic 0.1 px from straight (or a
    line), then the cubics ``right`` down to (30, 40), the bottom and left edges lines;
    over it, a blue square covering x 26-38 (the right side's neighbourhood)."""
    top = np.array([[10, 10], [16, 10.1], [24, 9.9], [30, 10]], float) if top_flat else np.array([[10, 10], [30, 10]], float)
    segs = [top] + [np.array(c, float) for c in right] + [np.array([[30, 40], [10, 40]], float),
                                                          np.array([[10, 40], [10, 10]], float)]
    points, degrees = layout_of(segs, True)
    outline = Path(points=torch.tensor(points, dtype=torch.float32), degrees=np.array(degrees),
                   subpaths=[(0, len(degrees), True)])
    cover = Path(points=torch.tensor([[26.0, 4], [38, 4], [38, 46], [26, 46]]), degrees=np.array([1, 1, 1, 1]),
                 subpaths=[(0, 4, True)])
    return Scene(64, 64, [Shape(outline, fill=Solid(torch.tensor([0.0, 0.0, 0.0, 1.0]))),
                          Shape(cover, fill=Solid(torch.tensor([0.1, 0.3, 0.8, 1.0])))])


BUMPS = [[[30, 10], [33, 15], [33, 20], [30, 25]], [[30, 25], [33, 30], [33, 35], [30, 40]]]


def test_a_flat_cubic_becomes_a_line_and_a_curve_stays():
    scene = outline_scene([[[30, 10], [38, 20], [38, 30], [30, 40]]])
    target = noisy(rgb(scene, 8))

    def measure(s):
        return float(((rgb(s) - target) ** 2).mean())

    base = measure(scene)
    stats = straighten(scene, measure, (64, 64), base * 10 ** 0.002)
    assert stats["candidates"] == 1 and stats["straightened"] == 1
    assert list(scene.shapes[0].geometry.degrees) == [1, 3, 1, 1]  # the bulge is 6 px from its chord
    assert measure(scene) <= base * 10 ** 0.002


def test_a_pair_under_a_later_shape_joins_beyond_the_error_allowed():
    """Two bumps under the blue square: one cubic cannot follow them within 0.5 px, and
    need not: nothing of them shows."""
    def joined(hidden_error):
        scene = outline_scene(BUMPS, top_flat=False)
        target = noisy(rgb(scene, 8))
        measure = lambda s: float(((rgb(s) - target) ** 2).mean())  # noqa: E731
        before = rgb(scene)
        stats = reduce_nodes(scene, measure, before, (64, 64), budget_db=0.1, hidden_error=hidden_error)
        assert np.abs(rgb(scene) - before).max() < 1e-6  # the picture is the same
        return len(scene.shapes[0].geometry.degrees), stats["segments_after"]

    assert joined(0.0) == (5, 9) and joined(3.0) == (4, 8)  # (the blue square: 4 lines)


def stroked_scene(filled: bool = False) -> Scene:
    """A black stroke (3 px wide) along y = 20, its 4 segments a hair off one line (as a
    refined trace's are where lines crossed), then a corner down to (56, 50); or the same
    outline filled."""
    segs = [np.array([[8, 20], [20, 20.2]]), np.array([[20, 20.2], [26, 20.3], [32, 19.9], [38, 19.9]]),
            np.array([[38, 19.9], [48, 20]]), np.array([[48, 20], [56, 20]]), np.array([[56, 20], [56, 50]])]
    points, degrees = layout_of([np.asarray(c, float) for c in segs], False)
    path = Path(points=torch.tensor(points, dtype=torch.float32), degrees=np.array(degrees), subpaths=[(0, 5, False)])
    black = Solid(torch.tensor([0.0, 0.0, 0.0, 1.0]))
    shape = Shape(path, fill=black) if filled else Shape(path, stroke=black, stroke_width=torch.tensor(3.0))
    return Scene(64, 64, [shape])


def test_a_strokes_straight_run_is_one_line_and_its_corner_stays():
    scene = stroked_scene()
    found = straight_run_candidates(scene, {0: subpath_segments(scene.shapes[0].geometry)}, (64, 64))
    assert [(a, b) for _, _, _, a, b in found] == [(0, 3)]  # the run of 4; not round the corner
    stats = join_straight_runs(scene, (64, 64))
    assert stats == {"candidates": 1, "joined": 1, "segments_removed": 3}
    g = scene.shapes[0].geometry
    assert list(g.degrees) == [1, 1]
    assert np.allclose(g.points.numpy(), [[8, 20], [56, 20], [56, 50]])  # the run's ends kept


def test_a_filled_outline_has_no_straight_runs_to_join():
    scene = stroked_scene(filled=True)  # (fills: the pairwise joins within the budget only)
    assert join_straight_runs(scene, (64, 64))["candidates"] == 0
    assert len(scene.shapes[0].geometry.degrees) == 5


def test_a_stroke_a_hair_off_its_line_is_not_joined_beyond_the_tolerance():
    scene = stroked_scene()
    g = scene.shapes[0].geometry
    points = g.points.clone()
    points[1, 1] = 21.0  # the first line's end 1 px off: beyond STRAIGHT_RUN (0.5)
    scene.shapes[0].geometry = Path(points=points, degrees=g.degrees, subpaths=g.subpaths)
    found = straight_run_candidates(scene, {0: subpath_segments(scene.shapes[0].geometry)}, (64, 64))
    runs = [(a, b) for _, _, _, a, b in found]
    assert runs and all(a >= 1 for a, _ in runs)  # the line off the others joins none of them


def _stroke(segs, width=8.0, size=64) -> Scene:
    points, degrees = layout_of([np.asarray(c, float) for c in segs], False)
    path = Path(points=torch.tensor(points, dtype=torch.float32), degrees=np.array(degrees),
                subpaths=[(0, len(segs), False)])
    black = Solid(torch.tensor([0.0, 0.0, 0.0, 1.0]))
    return Scene(size, size, [Shape(path, stroke=black, stroke_width=torch.tensor(width), linecap="round",
                                    linejoin="round")])


def _measure_against(target):
    def measure(scene):
        return float(((render(scene, 64, 64, samples=4, background=[1, 1, 1, 1]).numpy()[..., :3] - target) ** 2).mean())
    return measure


def test_a_hook_under_a_round_cap_is_dropped_and_a_tiny_line_made_a_dot():
    line = [np.array([[10.0, 20.0], [50.0, 20.0]])]
    target = render(_stroke(line), 64, 64, samples=4, background=[1, 1, 1, 1]).numpy()[..., :3]
    # the fit's hook: the line's last 2 px folded back under its cap (half width 4)
    hooked = _stroke(line + [np.array([[50.0, 20.0], [51.0, 20.5], [49.5, 21.0], [48.5, 20.5]])])
    measure = _measure_against(target)
    stats = tidy_stroke_ends(hooked, measure, measure(hooked) * 1.01 + 1e-6)
    assert stats == {"hooks": 1, "dots": 0}
    assert list(hooked.shapes[0].geometry.degrees) == [1]
    dot = _stroke([np.array([[30.0, 30.0], [30.01, 30.11]])])
    stats = tidy_stroke_ends(dot, _measure_against(target), 1.0)
    assert stats == {"hooks": 0, "dots": 1}
    p = dot.shapes[0].geometry.points.numpy()
    assert np.allclose(p[0], p[1]) and np.allclose(p[0], [30.005, 30.055], atol=1e-4)


def test_a_short_end_going_on_is_no_hook_and_a_change_past_the_budget_is_undone():
    line = [np.array([[10.0, 20.0], [50.0, 20.0]]), np.array([[50.0, 20.0], [52.0, 21.0]])]
    assert _end_hooks([np.asarray(c) for c in line], 4.0) == []
    hooked = _stroke([np.array([[10.0, 20.0], [50.0, 20.0]]), np.array([[50.0, 20.0], [46.0, 20.0]])])
    target = render(_stroke([np.array([[10.0, 20.0], [50.0, 20.0]])]), 64, 64, samples=4,
                    background=[1, 1, 1, 1]).numpy()[..., :3]
    before = hooked.shapes[0].geometry.points.clone()
    stats = tidy_stroke_ends(hooked, _measure_against(target), -1.0)  # (no change can be within a negative limit)
    assert stats == {"hooks": 0, "dots": 0} and torch.equal(hooked.shapes[0].geometry.points, before)


def test_a_strokes_single_cubic_within_a_quarter_pixel_is_a_line_and_a_round_corner_stays():
    """A refined stroke's straight line often comes back as one cubic a hair off its chord
    (tabler-056's cross: 0.09 px); alone it is a line too, where a quarter arc is not."""
    k = 4 / 3 * math.tan(math.pi / 8) * 6
    scene = _stroke([np.array([[10.0, 10.0], [14.86, 14.73], [47.52, 47.62], [52.0, 52.0]]),
                     np.array([[52.0, 52.0], [52.0, 52 - k], [58 - k, 46.0], [58.0, 46.0]])])
    stats = join_straight_runs(scene, (64, 64))
    assert stats["joined"] == 1
    assert list(scene.shapes[0].geometry.degrees) == [1, 3]
    assert np.allclose(scene.shapes[0].geometry.points.numpy()[:2], [[10, 10], [52, 52]])
