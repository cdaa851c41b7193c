"""Closed strokes made the polygons they are (vecfit/fitting/polygons.py): a small ring
traced as a smooth loop comes back with its sides and corners; a round ring stays round."""
from __future__ import annotations

import math

import numpy as np

from vecfit.fitting.polygons import polygon_of, sharpen_loops
from vecfit.scene.segments import subpath_segments
from test_fillets import rgb, stroke_scene

DIAMOND = [np.array([[32.0, 12.0], [52.0, 32.0]]), np.array([[52.0, 32.0], [32.0, 52.0]]),
           np.array([[32.0, 52.0], [12.0, 32.0]]), np.array([[12.0, 32.0], [32.0, 12.0]])]


def rounded_loop(corners: np.ndarray, pull: float) -> list[np.ndarray]:
    """A smooth closed loop through the middles of a polygon's sides, each corner cut by a
    cubic whose handles reach ``pull`` of the way to it (as a thinned ring's trace goes)."""
    k = len(corners)
    mids = [(corners[i] + corners[(i + 1) % k]) / 2 for i in range(k)]
    return [np.stack([mids[i - 1], mids[i - 1] + pull * (corners[i] - mids[i - 1]),
                      mids[i] + pull * (corners[i] - mids[i]), mids[i]]) for i in range(k)]


def test_a_diamond_traced_round_is_made_its_polygon():
    target = rgb(stroke_scene([(DIAMOND, True)]))
    loop = rounded_loop(np.array([[32.0, 12.0], [52.0, 32.0], [32.0, 52.0], [12.0, 32.0]]), 0.8)
    scene = stroke_scene([(loop, True)])
    before = float(((rgb(scene) - target) ** 2).mean())
    stats, _ = sharpen_loops(scene, rgb, target, (64, 64))
    after = float(((rgb(scene) - target) ** 2).mean())
    assert stats == {"loops": 1, "sharpened": 1}
    assert after < 0.5 * before, (before, after)
    segs, closed = subpath_segments(scene.shapes[0].geometry)[0]
    assert closed and len(segs) == 4 and all(len(c) == 2 for c in segs)
    corners = np.array([c[0] for c in segs])
    for true in ([32, 12], [52, 32], [32, 52], [12, 32]):  # each corner within 1.5 px of the drawn one (the fit goes on)
        assert np.hypot(*(corners - true).T).min() < 1.5, corners


def test_a_ring_that_is_round_stays_round():
    k = 4 / 3 * math.tan(math.pi / 8) * 16
    c = np.array([32.0, 32.0])
    circle = [np.array([c + [16, 0], c + [16, k], c + [k, 16], c + [0, 16]]),
              np.array([c + [0, 16], c + [-k, 16], c + [-16, k], c + [-16, 0]]),
              np.array([c + [-16, 0], c + [-16, -k], c + [-k, -16], c + [0, -16]]),
              np.array([c + [0, -16], c + [k, -16], c + [16, -k], c + [16, 0]])]
    target = rgb(stroke_scene([(circle, True)]))
    scene = stroke_scene([(circle, True)])
    before = scene.shapes[0].geometry.points.clone()
    stats, _ = sharpen_loops(scene, rgb, target, (64, 64))
    assert stats["sharpened"] == 0
    assert np.array_equal(scene.shapes[0].geometry.points.numpy(), before.numpy())


def test_polygon_of_refuses_a_loop_of_too_many_sides():
    t = np.linspace(0, 2 * np.pi, 41)[:-1]
    wobbly = np.stack([32 + 16 * np.cos(t) + 3 * np.cos(9 * t), 32 + 16 * np.sin(t)], 1)
    segs = [np.stack([wobbly[i], wobbly[(i + 1) % 40]]) for i in range(40)]
    assert polygon_of(segs, 1.0) is None
