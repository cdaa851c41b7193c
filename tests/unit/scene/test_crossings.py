"""vecfit.scene.crossings: where closed outlines cross themselves, checked on figures whose
crossings are known (exactly, or analytically for curves), against a brute-force Fraction
reference on random polygons, and on a real trace."""
from __future__ import annotations

import math
import subprocess
import sys
import warnings
from fractions import Fraction

import numpy as np
import pytest

from helpers import need
from shared_data import SHARED
from vecfit.scene import Circle, Path, Rect, Scene, Shape, Solid
from vecfit.scene.arrays import numpy_arrays
from vecfit.scene.crossings import Crossing, crossed_outlines, path_crossings, subpath_crossings

CASES = SHARED / "realworld" / "cases"


def polygon(*points):
    """A closed polygon's stored points and degrees."""
    return np.array(points, dtype=np.float64), [1] * len(points)


def crossings_of(points, degrees, closed=True, tolerance=0.01):
    return subpath_crossings(np.asarray(points, dtype=np.float64), degrees, closed, tolerance)


def bezier(controls, t):
    controls = np.asarray(controls, dtype=np.float64)
    d = len(controls) - 1
    return sum(math.comb(d, k) * (1 - t) ** (d - k) * t ** k * controls[k] for k in range(d + 1))


# ------------------------------------------------------------------- known figures

def test_figure_eight_crosses_once_at_its_middle():
    assert crossings_of(*polygon((0, 0), (2, 2), (2, 0), (0, 2))) == [Crossing(0, 0.5, 2, 0.5, (1.0, 1.0))]


def test_segments_of_no_length_are_passed_over():
    # a figure eight with a repeated point (a zero-length line) before its crossing
    # segment: the crossing is the same
    assert crossings_of(*polygon((0, 0), (0, 0), (2, 2), (2, 0), (0, 2))) == [Crossing(1, 0.5, 3, 0.5, (1.0, 1.0))]
    # a square closed by a line from its start to itself (as cutting an outline at its
    # start leaves it): the segments either side of that line meet, they do not cross
    assert crossings_of(*polygon((0, 0), (1, 0), (1, 1), (0, 1), (0, 0))) == []


def test_pentagram_crosses_five_times():
    angles = math.pi / 2 + np.arange(5) * 4 * math.pi / 5
    found = crossings_of(*polygon(*np.c_[np.cos(angles), np.sin(angles)]))
    assert len(found) == 5
    # the inner pentagon's corners: at radius cos(72°) / cos(36°) of the star's
    radii = [math.hypot(*c.point) for c in found]
    assert np.allclose(radii, math.cos(math.radians(72)) / math.cos(math.radians(36)), atol=1e-12)


def test_square_does_not_cross():
    assert crossings_of(*polygon((0, 0), (1, 0), (1, 1), (0, 1))) == []


def test_square_drawn_twice_lies_on_itself_without_crossing():
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    assert crossings_of(*polygon(*square, *square)) == []


def test_a_cubics_own_loop_is_found_within_the_segment():
    # symmetric about x = 1: B(t) = B(1 - t) where 7t² - 7t + 1 = 0, at y = 9 t (1 - t) = 9/7
    controls = [(0, 0), (3, 3), (-1, 3), (2, 0)]
    for closed_path in (False, True):
        points, degrees = (controls, [3]) if not closed_path else (controls + [(2, -1)], [3, 1, 1])
        found = crossings_of(points, degrees, closed=closed_path)
        assert len(found) == 1
        c = found[0]
        assert c.seg_a == c.seg_b == 0
        assert c.t_a == pytest.approx(0.5 - math.sqrt(21) / 14, abs=1e-6)
        assert c.t_b == pytest.approx(0.5 + math.sqrt(21) / 14, abs=1e-6)
        assert c.point == pytest.approx((1.0, 9 / 7), abs=1e-6)


def test_segments_meeting_at_a_vertex_do_not_cross():
    # a thin wedge, and a needle whose two cubics meet tangentially at its tip
    assert crossings_of(*polygon((0, 0), (10, 0.01), (0, 0.02))) == []
    needle = [(0, 1), (6, 1), (9, 0), (10, 0), (9, 0), (6, -1), (0, -1)]
    assert crossings_of(needle, [3, 3, 1]) == []


@pytest.mark.parametrize("dip", [0.0, 1e-15, -1e-15, -1e-17, 1e-3])
def test_a_curve_touching_a_line_does_not_cross_it(dip):
    # the parabola y = x² + dip sits on the line y = 0 (to within rounding, or 1e-3 above)
    points = [(-2, 0), (2, 0), (2, 4 + dip), (0, -4 + dip), (-2, 4 + dip)]
    assert crossings_of(points, [1, 1, 2, 1]) == []


def test_a_curve_dipping_across_a_line_crosses_it_twice():
    points = [(-2, 0), (2, 0), (2, 4 - 0.05), (0, -4 - 0.05), (-2, 4 - 0.05)]
    found = crossings_of(points, [1, 1, 2, 1])
    assert [c.point[0] for c in found] == pytest.approx([-math.sqrt(0.05), math.sqrt(0.05)], abs=1e-6)


def test_touches_at_vertices_and_edges_are_not_crossings():
    # two corners kissing: a bow of two squares meeting at (1, 1)
    assert crossings_of(*polygon((0, 0), (1, 0), (1, 1), (2, 1), (2, 2), (1, 2), (1, 1), (0, 1))) == []
    # a vertex grazing an edge from inside: the notch's tip (2, 0) on the bottom edge
    assert crossings_of(*polygon((0, 0), (4, 0), (4, 4), (2, 0), (0, 4))) == []
    # a keyhole: in along a slit, round the hole, back out along the same slit
    keyhole = [(0, 0), (10, 0), (10, 5), (7, 5), (7, 3), (3, 3), (3, 7), (7, 7), (7, 5), (10, 5), (10, 10),
               (0, 10)]
    assert crossings_of(*polygon(*keyhole)) == []
    # two lobes sharing a stretch of the bottom edge, both above it
    assert crossings_of(*polygon((0, 0), (6, 0), (6, 4), (4, 4), (4, 0), (2, 0), (2, 4), (0, 4))) == []


def test_passing_through_a_vertex_or_along_an_edge_to_the_other_side_crosses():
    # figure eights whose crossing is a vertex of both passes, or of one
    assert crossings_of(*polygon((0, 0), (1, 1), (2, 2), (2, 0), (1, 1), (0, 2))) == [
        Crossing(1, 0.0, 4, 0.0, (1.0, 1.0))]
    assert crossings_of(*polygon((0, 0), (1, 1), (2, 2), (2, 0), (0, 2))) == [Crossing(1, 0.0, 3, 0.5, (1.0, 1.0))]
    # in from above at (4, 0), back along the bottom edge to (2, 0), out below it
    found = crossings_of(*polygon((0, 0), (6, 0), (6, 4), (4, 4), (4, 0), (2, 0), (2, -2), (0, -2)))
    assert len(found) == 1 and found[0].point == (2.0, 0.0)


def test_closing_segment_crossing_the_first_segment():
    # the first segment, a cubic, leaves the start and dips below the closing line y = 0:
    # y(t) = 3t (t² - 9t + 6)... = 0 at t = (9 - √57) / 2
    points = [(0, 0), (-1, 2), (-2, 1), (-2, -2), (-4, 0)]
    found = crossings_of(points, [3, 1, 1])
    assert len(found) == 1
    c = found[0]
    t = (9 - math.sqrt(57)) / 2
    x = bezier(points[:4], t)[0]
    assert (c.seg_a, c.seg_b) == (0, 2)
    assert c.t_a == pytest.approx(t, abs=1e-6)
    assert c.t_b == pytest.approx((x + 4) / 4, abs=1e-6)
    assert c.point == pytest.approx((x, 0.0), abs=1e-6)
    # and a polygon whose closing edge crosses its second
    assert crossings_of(*polygon((0, 0), (2, 0), (2, 2), (3, 1))) == [Crossing(1, 1 / 3, 3, 1 / 3, (2.0, 2 / 3))]


def test_a_parabola_crossed_by_a_line_at_a_known_point():
    # the quadratic is y = (4 - x²) / 2 at t = (x + 2) / 4; the line y = (2 - x) / 5 meets it
    # at x = -1.6
    found = crossings_of([(-2, 0), (0, 4), (2, 0), (-3, 1)], [2, 1, 1])
    assert len(found) == 1
    c = found[0]
    assert (c.seg_a, c.seg_b) == (0, 1)
    assert c.t_a == pytest.approx(0.1, abs=1e-6) and c.t_b == pytest.approx(0.72, abs=1e-6)
    assert c.point == pytest.approx((-1.6, 0.72), abs=1e-6)


def dense_crossing_count(points, degrees, samples=600) -> int:
    """Proper crossings of the closed subpath sampled densely (``samples`` chords per
    segment), counted over all pairs of non-adjacent chords: a reference that shares no
    code with the module (no pruning, no flattening bound, no touch rules)."""
    points = np.asarray(points, np.float64)
    ring, start = [], 0
    closed_points = np.concatenate([points, points[:1]])
    for d in degrees:
        t = np.arange(samples)[:, None] / samples
        ring.append(bezier(closed_points[start:start + d + 1], t))
        start += d
    a = np.concatenate(ring)
    b = np.roll(a, -1, axis=0)
    n, hits = len(a), 0

    def orient(p, q, r):
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))

    for lo in range(0, n, 256):
        i = np.arange(lo, min(n, lo + 256))[:, None]
        j = np.arange(n)[None, :]
        pairs = (j > i + 1) & ~((i == 0) & (j == n - 1))
        ai, bi, aj, bj = a[i], b[i], a[j], b[j]
        hit = (orient(ai, bi, aj) * orient(ai, bi, bj) < 0) & (orient(aj, bj, ai) * orient(aj, bj, bi) < 0)
        hits += int((hit & pairs).sum())
    return hits


def test_two_cubics_crossing_where_a_dense_reference_says():
    # an S-curve out along the x axis and a cubic back across it, closed by a line
    a = [(0, 0), (10, 20), (20, -20), (30, 0)]
    b = [(30, 0), (25, 10), (5, -10), (0, 5)]
    points, degrees = a + b[1:3] + [b[3]], [3, 3, 1]
    found = crossings_of(points, degrees)
    assert len(found) == dense_crossing_count(points, degrees) == 2
    for c in found:
        assert (c.seg_a, c.seg_b) == (0, 1)
        pa, pb = bezier(a, c.t_a), bezier(b, c.t_b)
        assert np.linalg.norm(pa - pb) < 1e-6 and np.allclose(c.point, pa, atol=1e-6)


def test_bad_input_is_refused():
    with pytest.raises(ValueError):
        subpath_crossings(np.zeros((3, 2)), [1, 1], True)  # 2 closed lines store 2 points
    with pytest.raises(ValueError):
        subpath_crossings(np.zeros((2, 2)), [4], False)
    with pytest.raises(ValueError):
        subpath_crossings(np.array([[0, 0], [np.nan, 1]]), [1], False)
    with pytest.raises(ValueError):
        subpath_crossings(np.zeros((2, 2)), [1], False, tolerance=0)


# ----------------------------------------------------- against a brute-force reference

def exact_orient(a, b, c) -> int:
    d = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    return (d > 0) - (d < 0)


def brute_force(points) -> list[tuple[int, Fraction, int, Fraction]]:
    """Every proper crossing of non-adjacent edges of a closed polygon, in Fractions:
    (edge, t, edge, u) with the first edge's index the lower."""
    p = [(Fraction(x), Fraction(y)) for x, y in points]
    n, out = len(p), []
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue
            a, b, c, d = p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]
            if exact_orient(a, b, c) * exact_orient(a, b, d) < 0 and exact_orient(c, d, a) * exact_orient(c, d, b) < 0:
                den = (b[0] - a[0]) * (d[1] - c[1]) - (b[1] - a[1]) * (d[0] - c[0])
                t = ((c[0] - a[0]) * (d[1] - c[1]) - (c[1] - a[1]) * (d[0] - c[0])) / den
                u = ((c[0] - a[0]) * (b[1] - a[1]) - (c[1] - a[1]) * (b[0] - a[0])) / den
                out.append((i, t, j, u))
    return out


@pytest.mark.slow
def test_random_polygons_match_the_brute_force_reference():
    rng = np.random.default_rng(37)
    total = 0
    for _ in range(100):
        points = rng.uniform(0, 100, (int(rng.integers(4, 25)), 2))
        found = crossings_of(points, [1] * len(points), tolerance=1e-9)
        expected = brute_force(points.tolist())
        total += len(expected)
        assert sorted((c.seg_a, c.seg_b) for c in found) == sorted((i, j) for i, _, j, _ in expected)
        by_edges = {(i, j): (t, u) for i, t, j, u in expected}
        for c in found:
            t, u = by_edges[(c.seg_a, c.seg_b)]
            assert c.t_a == pytest.approx(float(t), abs=1e-9) and c.t_b == pytest.approx(float(u), abs=1e-9)
    assert total > 500  # the polygons did cross, a lot


@pytest.mark.slow
def test_degenerate_grid_polygons_agree_with_any_small_perturbation():
    """On a 4 x 4 grid, polygons touch and overlap themselves everywhere. A small perturbation
    turns each place where two passes meet into proper crossings: an odd number where they
    cross, an even number (0 for some perturbation) where they touch. So the count here has
    the parity of every perturbed polygon's brute-force count, and is at most that count."""
    rng = np.random.default_rng(2026)
    tested = strict = 0
    while tested < 300:
        points = rng.integers(0, 4, (int(rng.integers(4, 11)), 2)).astype(np.float64)
        before, after = np.roll(points, 1, axis=0), np.roll(points, -1, axis=0)
        incoming, outgoing = points - before, after - points
        if (incoming == 0).all(axis=1).any():
            continue  # a zero-length edge
        turned_back = ((incoming[:, 0] * outgoing[:, 1] == incoming[:, 1] * outgoing[:, 0])
                       & ((incoming * outgoing).sum(axis=1) < 0))
        if turned_back.any():
            continue  # a spike: no side to pass to
        tested += 1
        ours = len(crossings_of(points, [1] * len(points), tolerance=1e-9))
        for _ in range(3):
            theirs = len(brute_force((points + rng.normal(0, 1e-6, points.shape)).tolist()))
            assert theirs % 2 == ours % 2 and theirs >= ours, points.tolist()
            strict += theirs > ours
    assert strict > 0  # touches were there to be told apart from crossings


# ------------------------------------------------------------------ paths and scenes

def figure_eight_path(closed: bool, offset=(0.0, 0.0)) -> tuple[np.ndarray, list]:
    points = np.array([(0, 0), (2, 2), (2, 0), (0, 2)], dtype=np.float64) + offset
    return (points, [1] * 4) if closed else (np.concatenate([points, points[:1]]), [1] * 4)


def test_path_crossings_reports_closed_subpaths_that_cross():
    eight, _ = figure_eight_path(True)
    open_eight, _ = figure_eight_path(False, offset=(5, 0))
    square = np.array([(10, 0), (11, 0), (11, 1), (10, 1)], dtype=np.float64)
    eight_again, _ = figure_eight_path(True, offset=(20, 0))
    path = Path(points=np.concatenate([eight, open_eight, square, eight_again]).astype(np.float32),
                degrees=np.ones(16, np.int64), subpaths=[(0, 4, True), (4, 4, False), (8, 4, True), (12, 4, True)])
    found = path_crossings(path)
    assert [index for index, _ in found] == [0, 3]
    assert found[1][1] == [Crossing(0, 0.5, 2, 0.5, (21.0, 1.0))]
    torch = pytest.importorskip("torch")
    as_tensor = Path(points=torch.from_numpy(np.asarray(path.points)), degrees=path.degrees, subpaths=path.subpaths)
    assert path_crossings(as_tensor) == found


def test_crossed_outlines_counts_filled_closed_subpaths():
    with numpy_arrays():
        red = Solid(color=np.array([1, 0, 0, 1], np.float32))
        eight, _ = figure_eight_path(True)
        twice = Path(points=np.concatenate([eight, eight + 5]).astype(np.float32), degrees=np.ones(8, np.int64),
                     subpaths=[(0, 4, True), (4, 4, True)])
        open_eight, _ = figure_eight_path(False)
        scene = Scene(width=30, height=30, shapes=[
            Shape(geometry=twice, fill=red),                                   # 2
            Shape(geometry=Path(points=eight.astype(np.float32), degrees=np.ones(4, np.int64),
                                subpaths=[(0, 4, True)]), fill=None, stroke=red),  # a stroke only
            Shape(geometry=Path(points=open_eight.astype(np.float32), degrees=np.ones(4, np.int64),
                                subpaths=[(0, 4, False)]), fill=red),          # open
            Shape(geometry=Circle(center=np.array([5, 5], np.float32), radius=np.array(3, np.float32)), fill=red),
            Shape(geometry=Rect(p_min=np.zeros(2, np.float32), p_max=np.ones(2, np.float32)), fill=red),
        ])
    assert crossed_outlines(scene) == 2


def test_importing_needs_no_torch():
    code = "import sys, vecfit.scene.crossings; sys.exit('torch' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


# ----------------------------------------------------------------------- a real trace

def traced_scene(name: str, paths: int = 64):
    from PIL import Image

    from vecfit.initial.tracer import TraceSettings, trace_image
    from vecfit.svg.read import scene_of

    image = np.asarray(Image.open(need(CASES / f"{name}.png")).convert("RGBA"), np.float32) / 255
    traced = trace_image(image, TraceSettings.defaults(paths=paths))
    with numpy_arrays(), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return scene_of(traced.document, for_writing=False)


@pytest.mark.parametrize("name", ["noto-emoji-000", "fxemoji-000"])
def test_traced_emoji_outlines_are_simple(name):
    scene = traced_scene(name)
    assert sum(len(s.geometry.subpaths) for s in scene.shapes if isinstance(s.geometry, Path)) > 5
    assert crossed_outlines(scene) == 0


def test_crossings_found_on_a_real_trace_are_on_both_curves():
    """noto-emoji-002's trace has a thin sliver whose two sides cross (when this was
    written): what is reported must be points on both curves, crossing at an angle."""
    scene = traced_scene("noto-emoji-002")
    for shape in scene.shapes:
        if not isinstance(shape.geometry, Path):
            continue
        path = shape.geometry
        points = np.asarray(path.points, np.float64)
        for index, found in path_crossings(path):
            first, count, _ = path.subpaths[index]
            start, n = path.subpath_point_ranges()[index]
            ring = np.concatenate([points[start:start + n], points[start:start + 1]])
            offsets = np.concatenate([[0], np.cumsum(path.degrees[first:first + count])])
            for c in found:
                ca = ring[offsets[c.seg_a]:offsets[c.seg_a + 1] + 1]
                cb = ring[offsets[c.seg_b]:offsets[c.seg_b + 1] + 1]
                pa, pb = bezier(ca, c.t_a), bezier(cb, c.t_b)
                assert np.linalg.norm(pa - pb) < 1e-6 and np.allclose(c.point, pa, atol=1e-6)
                ta = bezier(ca, min(c.t_a + 1e-5, 1)) - bezier(ca, max(c.t_a - 1e-5, 0))
                tb = bezier(cb, min(c.t_b + 1e-5, 1)) - bezier(cb, max(c.t_b - 1e-5, 0))
                sine = (ta[0] * tb[1] - ta[1] * tb[0]) / (np.linalg.norm(ta) * np.linalg.norm(tb))
                assert abs(sine) > 0.01


def test_parts_closer_than_the_tolerance_are_flattened_again_before_they_are_said_to_cross(monkeypatch):
    """A speck of vscode-icons' lerna logo (0.4 units across): at 0.01 its first and fourth
    cubics' pieces cross where the curves, 0.005 apart, do not."""
    from vecfit.scene import crossings

    points = [(15.836000442504883, 17.552000045776367), (15.800000190734863, 17.552000045776367),
              (15.829999923706055, 17.493000030517578), (15.895999908447266, 17.424999237060547),
              (15.971712112426758, 17.347122192382812), (16.051843643188477, 17.273666381835938),
              (16.13599967956543, 17.204999923706055), (16.20199966430664, 17.15399932861328),
              (16.172000885009766, 17.21299934387207), (16.076000213623047, 17.332000732421875),
              (16.01235008239746, 17.421796798706055), (15.928854942321777, 17.495712280273438),
              (15.831999778747559, 17.54800033569336)]
    degrees = [3, 3, 3, 3, 1]
    assert dense_crossing_count(points, degrees) == 0
    assert crossings_of(points, degrees) == []
    monkeypatch.setattr(crossings, "_FINER", 0)
    assert len(crossings_of(points, degrees)) == 1  # what the first flattening alone says
