"""Dashing (vecfit.scene.dashes) against an independent reference: paths sampled densely
(20,000 points a segment) give arc lengths by chords, and the dash intervals come from a
plain loop over the pattern written here (SVG 2 as resvg: the offset wraps modulo the
pattern, each subpath starts anew, a closed subpath's last dash runs on into its first).
Each dash's length and end points are compared with the reference; gradients of the
dashes' points with respect to the path's points with central differences."""
from __future__ import annotations

import math
import time
import warnings

import numpy as np
import pytest
import torch

from vecfit import limits
from vecfit.scene import Circle, Ellipse, Path, Rect, Scene, Shape, Solid
from vecfit.scene.dashes import dash_count, dash_path, dash_pattern, outline_path

from helpers import slow_unless

SAMPLES = 20_000


def bezier(ctrl: np.ndarray, t: np.ndarray) -> np.ndarray:
    d = len(ctrl) - 1
    return sum(math.comb(d, i) * ((1 - t) ** (d - i) * t ** i)[:, None] * ctrl[i] for i in range(d + 1))


def polyline(path: Path, subpath: int) -> np.ndarray:
    """The subpath sampled densely, [n, 2] (float64)."""
    pts = path.points.detach().double().numpy()
    first, count, closed = path.subpaths[subpath]
    p0, n = path.subpath_point_ranges()[subpath]
    out, k = [pts[p0][None]], 0
    t = np.linspace(0, 1, SAMPLES + 1)[1:]
    for d in path.degrees[first:first + count]:
        idx = [p0 + ((k + i) % n if closed else k + i) for i in range(d + 1)]
        out.append(bezier(pts[idx], t))
        k += d
    return np.concatenate(out)


def arclength(poly: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.sqrt((np.diff(poly, axis=0) ** 2).sum(1)))])


def at_length(poly: np.ndarray, s: float) -> np.ndarray:
    cum = arclength(poly)
    return np.stack([np.interp(s, cum, poly[:, 0]), np.interp(s, cum, poly[:, 1])])


def reference_dashes(length: float, closed: bool, pattern, offset: float) -> list[list[tuple[float, float]]]:
    """Per dash its arc-length ranges, by walking the pattern from the offset."""
    pattern = list(pattern) * (2 if len(pattern) % 2 else 1)
    period = sum(pattern)
    phase = offset % period  # Python's modulo: negative offsets wrap
    i, left = 0, pattern[0]
    while phase > left or (phase == left and left != 0):
        phase -= left
        i = (i + 1) % len(pattern)
        left = pattern[i]
    left -= phase
    first_on, first_len = i % 2 == 0, left
    dashes, s, j = [], 0.0, 0
    while s < length:
        if i % 2 == 0 and not (closed and j == 0):
            dashes.append([(s, min(s + left, length))])
        s += left
        i = (i + 1) % len(pattern)
        left = pattern[i]
        j += 1
    if closed and first_on:
        last_on = (i - 1) % 2 == 0 and j > 1  # the last interval walked was on
        if last_on:
            if first_len > 0:
                dashes[-1].append((0.0, min(first_len, length)))
        else:
            dashes.append([(0.0, min(first_len, length))])
    return dashes


def check_dashes(path: Path, pattern, offset: float, tol: float = 1e-3) -> Path:
    out = dash_path(path, pattern, offset)
    expected = []
    for s, (_, _, closed) in enumerate(path.subpaths):
        poly = polyline(path, s)
        for ranges in reference_dashes(arclength(poly)[-1], closed, pattern, offset):
            expected.append((poly, ranges))
    assert len(out.subpaths) == len(expected)
    for k, (poly, ranges) in enumerate(expected):
        dash = polyline(out, k)
        length = sum(b - a for a, b in ranges)
        assert abs(arclength(dash)[-1] - length) < tol, (k, arclength(dash)[-1], ranges)
        assert np.allclose(dash[0], at_length(poly, ranges[0][0]), atol=tol), (k, dash[0], ranges)
        assert np.allclose(dash[-1], at_length(poly, ranges[-1][1]), atol=tol), (k, dash[-1], ranges)
        assert not out.subpaths[k][2]  # open
    return out


def make(points, degrees, closed=False) -> Path:
    return Path(points=torch.tensor(points, dtype=torch.float64), degrees=np.array(degrees),
                subpaths=[(0, len(degrees), closed)])


LINE = make([[0, 0], [100, 0]], [1])
CUBIC = make([[0, 0], [30, 60], [70, -60], [100, 0]], [3])
POLYGON = make([[0, 0], [40, 0], [40, 30], [0, 30]], [1, 1, 1, 1], closed=True)
MIXED = make([[0, 0], [30, 60], [70, -60], [100, 0], [120, 30], [140, 10], [90, 80]], [3, 2, 1], closed=True)


@pytest.mark.parametrize("offset", slow_unless([0.0, 3.0, -4.0, 37.0, -100.0, 15.0], [0.0, 37.0, -100.0]))
@pytest.mark.parametrize("path", [LINE, CUBIC, POLYGON, MIXED], ids=["line", "cubic", "polygon", "mixed"])
def test_dash_lengths_follow_the_pattern(path, offset):
    check_dashes(path, (10.0, 5.0), offset)


@pytest.mark.parametrize("path", [LINE, CUBIC, POLYGON], ids=["line", "cubic", "polygon"])
def test_odd_patterns_repeat(path):
    out = check_dashes(path, (5.0, 3.0, 2.0), 1.5)
    assert dash_pattern((5, 3, 2)) == (5.0, 3.0, 2.0, 5.0, 3.0, 2.0)
    same = dash_path(path, (5.0, 3.0, 2.0, 5.0, 3.0, 2.0), 1.5)
    assert torch.equal(out.points, same.points)


def test_closed_dash_runs_through_the_start():
    """A square of side 40 (160 around), pattern 30 on 20 off: 0-30, 50-80, 100-130 and
    150-180, whose last runs through the start: 150-160 then 0-30 are one dash of 40."""
    square = make([[0, 0], [40, 0], [40, 40], [0, 40]], [1, 1, 1, 1], closed=True)
    out = check_dashes(square, (30.0, 20.0), 0.0)
    assert len(out.subpaths) == 3
    last = polyline(out, 2)
    assert np.allclose(last[0], [0, 10]) and np.allclose(last[-1], [30, 0])
    # offset 10: the first dash starts inside the pattern; nothing joins (ends at 160 off)
    check_dashes(square, (30.0, 20.0), 10.0)
    # one dash longer than the whole outline: a single open dash around it
    whole = check_dashes(square, (500.0, 1.0), 0.0)
    assert len(whole.subpaths) == 1 and abs(arclength(polyline(whole, 0))[-1] - 160) < 1e-6


def test_subpaths_restart_the_pattern():
    path = Path(points=torch.tensor([[0.0, 0.0], [26.0, 0.0], [0.0, 10.0], [26.0, 10.0]]), degrees=np.array([1, 1]),
                subpaths=[(0, 1, False), (1, 1, False)])
    out = check_dashes(path, (10.0, 5.0), 2.0)
    starts = [polyline(out, k)[0] for k in range(len(out.subpaths))]
    assert np.allclose(starts[0], [0, 0]) and any(np.allclose(p, [0, 10]) for p in starts)


def test_zero_length_dashes_are_points():
    out = check_dashes(LINE, (0.0, 20.0), 0.0)
    assert len(out.subpaths) == 5  # at 0, 20, 40, 60, 80 (not at 100: an interval starting at the end)
    assert all(d == 1 for d in out.degrees)
    pts = out.points.numpy().reshape(-1, 2, 2)
    assert np.allclose(pts[:, 0], pts[:, 1]) and np.allclose(pts[:, 0, 0], [0, 20, 40, 60, 80])
    # closed: the dot at the start comes once, at the end
    square = make([[0, 0], [40, 0], [40, 40], [0, 40]], [1, 1, 1, 1], closed=True)
    dots = dash_path(square, (0.0, 40.0), 0.0)
    assert len(dots.subpaths) == 4
    assert sorted(map(tuple, dots.points.numpy()[::2].round(6).tolist())) == [(0, 0), (0, 40), (40, 0), (40, 40)]


@pytest.mark.parametrize("array", [None, (), (1, -1), (-0.0, 2), (0, 0), (0,), (float("nan"), 1),
                                   (float("inf"), 1), ("x", 1)])
def test_patterns_that_draw_solid(array):
    assert dash_pattern(array) is None
    assert dash_path(LINE, array, 0.0) is None


def test_non_finite_offset_draws_solid():
    assert dash_path(LINE, (1, 1), float("nan")) is None
    assert dash_path(LINE, (1, 1), float("inf")) is None


def test_zero_length_subpath_has_no_dashes():
    point = make([[5, 5], [5, 5]], [1])
    out = dash_path(point, (1, 1), 0)
    assert out is not None and out.subpaths == [] and len(out.points) == 0


def test_widths_follow_the_dashes():
    path = Path(points=torch.tensor([[0.0, 0.0], [100.0, 0.0]]), degrees=np.array([1]), subpaths=[(0, 1, False)],
                widths=torch.tensor([2.0, 12.0]))
    out = dash_path(path, (10.0, 15.0), 0.0)
    x = out.points[:, 0]
    assert torch.allclose(out.widths, 2 + x / 10, atol=1e-5)


def test_outlines_start_where_svg_says():
    """Circles and ellipses start at (cx + rx, cy) and go on towards +y; rects at (x + rx, y)."""
    circle = outline_path(Circle(torch.tensor([50.0, 40.0]), torch.tensor(10.0)))
    assert torch.allclose(circle.points[0], torch.tensor([60.0, 40.0]))
    first = dash_path(circle, (1.0, 100.0), 0.0)
    assert float(first.points[-1, 1]) > 40 and abs(float(first.points[-1, 0]) - 60) < 0.1
    ellipse = outline_path(Ellipse(torch.tensor([0.0, 0.0]), torch.tensor([20.0, 10.0])))
    assert torch.allclose(ellipse.points[3], torch.tensor([0.0, 10.0]))
    # a circle's length: 2 pi r within the cubic approximation's 0.03%
    assert abs(dash_count(circle, (1.0, 1.0)) - 2 - math.pi * 10) < 0.01 * math.pi
    rect = outline_path(Rect(torch.tensor([1.0, 2.0]), torch.tensor([11.0, 22.0]), torch.tensor([3.0, 3.0])))
    assert torch.allclose(rect.points[0], torch.tensor([4.0, 2.0]))


def test_many_dashes_fall_back_quickly():
    long = make([[0, 0], [1e5, 0], [1e5, 1e5]], [1, 1])
    start = time.perf_counter()
    assert dash_count(long, (1e-9, 1e-9)) > 1e13
    assert dash_path(long, (1e-9, 1e-9), 0.0) is None
    assert dash_path(long, (0.001, 0.001), 0.0) is None
    assert time.perf_counter() - start < 1.0
    assert dash_path(long, (10.0, 10.0), 0.0) is not None  # 10,000 dashes: under the limit
    assert limits.MAX_DASHES >= 10_000


def test_dashes_closer_than_the_width_count_more():
    """Each dash counts max(1, width / pattern length): overlapping dashes cost the backward
    pass in proportion."""
    assert dash_count(LINE, (1.0, 1.0)) == pytest.approx(52)
    assert dash_count(LINE, (1.0, 1.0), width=1.5) == pytest.approx(52)
    assert dash_count(LINE, (1.0, 1.0), width=20.0) == pytest.approx(520)
    line = make([[0, 0], [65, 0]], [1])
    assert dash_path(line, (1e-3, 1e-3), 0.0) is not None   # 32,500 hairline dashes: drawn
    assert dash_path(line, (1e-3, 1e-3), 0.0, width=6.0) is None  # each overlapping 3,000: solid


@pytest.mark.parametrize("path, pattern, offset", [
    (CUBIC, (7.0, 3.0, 2.0, 4.0), 2.5),
    (MIXED, (7.0, 3.0, 2.0, 4.0), 2.5),
    (MIXED, (30.0, 5.0), 3.0),
    (MIXED, (0.0, 9.0), 3.0),
], ids=["cubic", "closed", "closed-long", "dots"])
def test_gradients_match_central_differences(path, pattern, offset):
    """Moving a control point moves every dash end along the path (the arc lengths before
    it change): the dashes' points as functions of the path's, exactly to first order."""
    def dashes(p):
        return dash_path(Path(points=p, degrees=path.degrees, subpaths=path.subpaths), pattern, offset).points

    p0 = path.points.detach().clone()
    p = p0.clone().requires_grad_(True)
    out = dashes(p)
    weights = torch.randn(out.shape, generator=torch.Generator().manual_seed(1), dtype=torch.float64)
    (out * weights).sum().backward()
    fd = torch.zeros_like(p0)
    h = 1e-5
    for i in range(p0.numel()):
        plus, minus = p0.clone(), p0.clone()
        plus.view(-1)[i] += h
        minus.view(-1)[i] -= h
        a, b = dashes(plus), dashes(minus)
        assert a.shape == out.shape == b.shape
        fd.view(-1)[i] = ((a - b) * weights).sum() / (2 * h)
    assert torch.allclose(p.grad, fd, atol=1e-5 * max(1.0, float(fd.abs().max()))), (p.grad, fd)
