"""Straight runs, rectangles, circles and ellipses in a trace (vecfit/initial/tracer/primitives.py)."""
from __future__ import annotations

import re

import numpy as np
import pytest

import vecfit
from vecfit.initial.tracer import TraceSettings, trace_image
from vecfit.initial.tracer.bezier import fit_closed
from vecfit.initial.tracer.primitives import as_primitive, straightened

from test_trace import count_shapes, coverage, over_white, paint, psnr, render


def line_cubic(a, b, bend=0.0):
    """A cubic from a to b with its control points at the thirds, pushed ``bend`` px off."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    n = np.array([-d[1], d[0]]) / np.hypot(*d)
    return np.stack([a, a + d / 3 + bend * n, a + 2 * d / 3 + bend * n, b])


def loop_of(corners, bends=None, split=1):
    """Closed cubics through ``corners``, each side cut into ``split`` cubics."""
    segs = []
    for k, a in enumerate(corners):
        b = corners[(k + 1) % len(corners)]
        for j in range(split):
            p = np.asarray(a, float) + (np.asarray(b, float) - a) * j / split
            q = np.asarray(a, float) + (np.asarray(b, float) - a) * (j + 1) / split
            segs.append(line_cubic(p, q, 0.0 if bends is None else bends[k]))
    return np.array(segs)


def test_straight_cubics_become_lines_and_runs_merge():
    square = loop_of([(10, 10), (40, 10), (40, 30), (10, 30)], split=3)  # 12 cubics
    out = straightened(square, 0.25)
    assert out.degrees == [1, 1, 1, 1, 1]  # four sides and the closing Z
    assert len(out.points) == 5 and np.allclose(out.points[0], out.points[-1])
    assert {tuple(p) for p in out.points[:4]} == {(10, 10), (40, 10), (40, 30), (10, 30)}


def test_runs_merge_across_the_outline_start():
    # the outline starts in the middle of the bottom side
    corners = [(25, 30), (10, 30), (10, 10), (40, 10), (40, 30)]
    out = straightened(loop_of(corners), 0.25)
    assert out.degrees == [1, 1, 1, 1, 1]
    assert {tuple(p) for p in out.points[:4]} == {(10, 10), (40, 10), (40, 30), (10, 30)}


def test_curved_and_doubling_back_cubics_stay_cubics():
    bent = loop_of([(10, 10), (40, 10), (40, 30), (10, 30)], bends=[0.0, 2.0, 0.0, 0.2])
    out = straightened(bent, 0.25)
    assert out.degrees == [1, 3, 1, 1, 1]  # the 0.2-px bend is within the tolerance
    back = np.array([[[0, 0], [30, 0], [-10, 0], [20, 0]], [[20, 0], [20, 10], [0, 10], [0, 0]]], float)
    assert straightened(back, 0.25).degrees[0] == 3  # control points beyond the chord's ends


def test_rectangle_circle_and_ellipse_recognised():
    rect = loop_of([(10, 10), (40, 10), (40, 30), (10, 30)], split=2)
    shape = as_primitive(rect, straightened(rect, 0.25), 0.25, 0.25)
    assert shape.tag == "rect" and shape.attributes == pytest.approx(
        {"x": 10, "y": 10, "width": 30, "height": 20})
    tilted = loop_of([(10, 10), (40, 12), (38, 32), (8, 30)])
    assert as_primitive(tilted, straightened(tilted, 0.25), 0.25, 0.25) is None

    t = np.linspace(0, 2 * np.pi, 800, endpoint=False)
    circle = np.stack([50 + 20 * np.cos(t), 40 + 20 * np.sin(t)], 1)
    smooth = fit_closed(circle, 0.1, 135.0)
    shape = as_primitive(circle, straightened(smooth, 0.25), 0.25, 0.25)
    assert shape.tag == "circle"
    assert [shape.attributes[k] for k in ("cx", "cy", "r")] == pytest.approx([50, 40, 20], abs=0.02)
    ellipse = np.stack([50 + 30 * np.cos(t), 40 + 12 * np.sin(t)], 1)
    shape = as_primitive(ellipse, straightened(fit_closed(ellipse, 0.1, 135.0), 0.25), 0.25, 0.25)
    assert shape.tag == "ellipse"
    assert [shape.attributes[k] for k in ("cx", "cy", "rx", "ry")] == pytest.approx([50, 40, 30, 12], abs=0.02)
    noisy = circle + np.random.default_rng(1).normal(0, 0.1, circle.shape)
    assert as_primitive(noisy, straightened(smooth, 0.25), 0.25, 0.35).tag == "circle"


def test_a_stadium_is_not_an_ellipse():
    """A rounded rectangle's straight sides leave an ellipse by more than the tolerance."""
    t = np.linspace(0, 2 * np.pi, 800, endpoint=False)
    x, y = np.cos(t), np.sin(t)
    pts = np.stack([50 + 10 * x, 40 + 18 * np.clip(y * 1.6, -1, 1)], 1)
    segs = fit_closed(pts, 0.1, 135.0)
    assert as_primitive(pts, straightened(segs, 0.25), 0.25, 0.35) is None


def test_striped_flag_traces_to_rects(tmp_path):
    """Three stripes and a disc: one background rect, two stripe rects and a circle, with
    no curve in the file, drawn as closely as the paths were."""
    w, h = 90, 60
    stripe1 = coverage(lambda x, y: (y > 20) & (y < 40) & (x > -1), w, h)
    stripe2 = coverage(lambda x, y: (y > 40) & (x > -1), w, h)
    disc = coverage(lambda x, y: (x - 45.3) ** 2 + (y - 30.2) ** 2 < 8.4 ** 2, w, h)
    image = paint([(stripe1, (0.9, 0.9, 0.9)), (stripe2, (0.1, 0.5, 0.2)), (disc, (0.8, 0.1, 0.1))],
                  w, h, background=(0.1, 0.2, 0.6))
    shapes = trace_image(image, TraceSettings.defaults(paths=8))
    plain = trace_image(image, TraceSettings.defaults(paths=8, lines=0.0))
    assert len(re.findall(r"<rect\b", shapes.svg)) == 3 and "<circle" in shapes.svg
    assert " d=" not in shapes.svg and len(shapes.svg) < 0.8 * len(plain.svg)
    out, before = render(shapes, w, h, tmp_path), render(plain, w, h, tmp_path)
    assert psnr(image[..., :3], out[..., :3]) >= psnr(image[..., :3], before[..., :3]) - 0.3


def two_eyes(w: int = 96, h: int = 64) -> np.ndarray:
    """Two black discs on a yellow face-coloured page, and a red bar: the discs are one
    colour, one compound path."""
    left = coverage(lambda x, y: (x - 28.3) ** 2 + (y - 30.6) ** 2 < 9.2 ** 2, w, h)
    right = coverage(lambda x, y: (x - 66.7) ** 2 + (y - 31.2) ** 2 < 9.2 ** 2, w, h)
    bar = coverage(lambda x, y: (y > 50) & (y < 56) & (x > 20) & (x < 76), w, h)
    return paint([(left, (0, 0, 0)), (right, (0, 0, 0)), (bar, (0.9, 0.2, 0.1))], w, h,
                 background=(0.99, 0.92, 0.17))


def test_a_compound_path_of_two_discs_is_written_as_two_circles(tmp_path):
    """Each disc of a compound path is its own <circle>, of the same paint, drawn as the
    path drew it; with the budget full (paths=2: the discs' path and the bar), the path
    stays one path."""
    image = two_eyes()
    split = trace_image(image, TraceSettings.defaults(paths=4))
    assert len(re.findall(r"<circle\b", split.svg)) == 2 and split.svg.count('fill="#000000"') == 2
    assert split.paths == 3 and count_shapes(split.svg) == 3 and split.segments == 4 + 4 + 4
    whole = trace_image(image, TraceSettings.defaults(paths=4, primitives=False))
    assert "<circle" not in whole.svg and whole.paths == 2
    full = trace_image(image, TraceSettings.defaults(paths=2))
    assert "<circle" not in full.svg and full.paths == count_shapes(full.svg) == 2
    out, before = render(split, 96, 64, tmp_path), render(whole, 96, 64, tmp_path)
    assert psnr(image[..., :3], out[..., :3]) >= psnr(image[..., :3], before[..., :3]) - 0.3
    assert float(np.abs(out - before).max()) < 0.5  # the same picture: only the discs' rims differ


def test_a_disc_with_a_hole_beside_it_is_not_split(tmp_path):
    """A ring over transparency (its hole cut out of it: no page to paint the hole with):
    its outlines meet each other's boxes, so the ring stays a path; the disc beside it in
    the same colour becomes a circle."""
    w, h = 96, 64
    ring = coverage(lambda x, y: ((x - 28) ** 2 + (y - 32) ** 2 < 16 ** 2) & ((x - 28) ** 2 + (y - 32) ** 2 > 8 ** 2), w, h)
    disc = coverage(lambda x, y: (x - 72.4) ** 2 + (y - 32.3) ** 2 < 9.5 ** 2, w, h)
    image = paint([(ring, (0.1, 0.3, 0.8)), (disc, (0.1, 0.3, 0.8))], w, h)
    result = trace_image(image, TraceSettings.defaults(paths=4))
    assert len(re.findall(r"<circle\b", result.svg)) == 1 and len(re.findall(r"<path\b", result.svg)) == 1
    assert 'fill-rule="evenodd"' in result.svg and result.svg.count("z") == 2  # the ring: outline and hole
    out = render(result, w, h, tmp_path)
    assert psnr(over_white(image), out[..., :3]) > 30


def test_a_rings_rims_are_exact_circles(tmp_path, monkeypatch):
    """A ring is a path (its hole must stay cut out of it), but each of its rims is
    written as the circle it is: four cubics on the true circle, closer than the free fit."""
    import vecfit.initial.tracer.trace as tracer
    w, h = 64, 64
    ring = coverage(lambda x, y: ((x - 31.3) ** 2 + (y - 32.6) ** 2 < 21 ** 2) & ((x - 31.3) ** 2 + (y - 32.6) ** 2 > 11 ** 2), w, h)
    image = paint([(ring, (0.1, 0.3, 0.8))], w, h)
    result = trace_image(image, TraceSettings.defaults(paths=4))
    assert "<circle" not in result.svg and result.segments == 8
    (tmp_path / "ring.svg").write_text(result.svg)
    path = vecfit.load_svg(tmp_path / "ring.svg").shapes[0].geometry
    assert [int(d) for d in path.degrees] == [3] * 4 + [1] + [3] * 4 + [1]
    for rim, radius in zip(np.split(path.points.numpy(), [13]), (21.0, 11.0)):
        centre = rim[[0, 6]].mean(0)  # the rightmost and leftmost points
        assert np.allclose(centre, (31.3, 32.6), atol=0.1)
        on_curve = np.hypot(*(rim[::3] - centre).T)
        assert np.abs(on_curve - radius).max() < 0.15
    out = render(result, w, h, tmp_path)
    monkeypatch.setattr(tracer, "elliptical", lambda edge, outline: outline)
    free = trace_image(image, TraceSettings.defaults(paths=4))
    assert free.svg != result.svg
    before = render(free, w, h, tmp_path)
    assert psnr(over_white(image), out[..., :3]) > psnr(over_white(image), before[..., :3]) + 1.0
