"""Rounded corners for strokes (vecfit/fitting/fillets.py): a fillet's geometry, and the
render deciding which corners of a stroke are rounded and by how much."""
from __future__ import annotations

import math

import numpy as np
import torch

from vecfit.fitting.fillets import _arc, corners, filleted, round_corners
from vecfit.scene.segments import path_segments, subpath_segments
from vecfit.renderer.raster import render
from vecfit.scene import Path, Scene, Shape, Solid
from vecfit.scene.segments import layout_of

BLACK = Solid(torch.tensor([0.0, 0.0, 0.0, 1.0]))
WIDTH = 8.0  # the strokes' width: half width 4


def _eval(c: np.ndarray, t: np.ndarray) -> np.ndarray:
    return ((1 - t) ** 3)[:, None] * c[0] + (3 * t * (1 - t) ** 2)[:, None] * c[1] + \
        (3 * t ** 2 * (1 - t))[:, None] * c[2] + (t ** 3)[:, None] * c[3]


def stroke_scene(subpaths: list[tuple[list, bool]], size: int = 64) -> Scene:
    points, degrees, table = [], [], []
    for segs, closed in subpaths:
        p, d = layout_of([np.asarray(c, float) for c in segs], closed)
        table.append((len(degrees), len(d), closed))
        points.append(p)
        degrees += d
    path = Path(points=torch.tensor(np.concatenate(points), dtype=torch.float32), degrees=np.array(degrees),
                subpaths=table)
    shape = Shape(path, stroke=BLACK, stroke_width=torch.tensor(WIDTH), linecap="round", linejoin="round")
    return Scene(size, size, [shape])


def rgb(scene: Scene, seed: int = 0) -> np.ndarray:
    image = render(scene, int(scene.width), int(scene.height), samples=4, seed=seed, background=[1, 1, 1, 1])
    return image.numpy()[..., :3].astype(np.float64)


def rounded_square(x0, y0, x1, y1, r) -> list[np.ndarray]:
    """A closed square centerline with corners of radius r (cubic arcs), starting on its top."""
    k = 4 / 3 * math.tan(math.pi / 8) * r
    return [np.array([[x0 + r, y0], [x1 - r, y0]]), np.array([[x1 - r, y0], [x1 - r + k, y0], [x1, y0 + r - k], [x1, y0 + r]]),
            np.array([[x1, y0 + r], [x1, y1 - r]]), np.array([[x1, y1 - r], [x1, y1 - r + k], [x1 - r + k, y1], [x1 - r, y1]]),
            np.array([[x1 - r, y1], [x0 + r, y1]]), np.array([[x0 + r, y1], [x0 + r - k, y1], [x0, y1 - r + k], [x0, y1 - r]]),
            np.array([[x0, y1 - r], [x0, y0 + r]]), np.array([[x0, y0 + r], [x0, y0 + r - k], [x0 + r - k, y0], [x0 + r, y0]])]


def test_a_fillet_is_tangent_to_both_lines_at_the_radius():
    segs = [np.array([[0.0, 0.0], [30.0, 0.0]]), np.array([[30.0, 0.0], [30.0, 30.0]])]
    out = filleted(segs, False, 1, 5.0)
    assert [len(c) - 1 for c in out] == [1, 3, 1]
    assert np.allclose(out[0][-1], [25, 0]) and np.allclose(out[2][0], [30, 5])  # trimmed by r at 90 degrees
    arc = out[1]
    assert np.allclose(arc[1] - arc[0], [abs(arc[1][0] - arc[0][0]), 0])  # leaves along the first line
    pts = _eval(arc, np.linspace(0, 1, 21))
    r = np.hypot(*(pts - [25.0, 5.0]).T)  # about the fillet's centre
    assert np.abs(r - 5).max() < 5 * 3e-4


def test_a_fillet_at_a_closed_subpaths_start_goes_last():
    square = [np.array([[10.0, 10.0], [50.0, 10.0]]), np.array([[50.0, 10.0], [50.0, 50.0]]),
              np.array([[50.0, 50.0], [10.0, 50.0]]), np.array([[10.0, 50.0], [10.0, 10.0]])]
    out = filleted(square, True, 0, 4.0)
    assert [len(c) - 1 for c in out] == [1, 1, 1, 1, 3]
    assert np.allclose(out[0][0], [14, 10]) and np.allclose(out[-1][0], [10, 14]) and np.allclose(out[-1][-1], out[0][0])


def test_a_corner_too_near_a_short_segment_is_left():
    segs = [np.array([[0.0, 0.0], [3.0, 0.0]]), np.array([[3.0, 0.0], [3.0, 30.0]])]
    assert filleted(segs, False, 1, 5.0) is None


def test_the_corners_of_a_square_traced_sharp_are_rounded_as_drawn():
    """The picture: a square frame whose centerline has corners of radius 4, the stroke's
    half width (Tabler's rects). Traced with sharp corners, the round joins draw the
    outside 1.7 px inside the picture's at each corner; the fillets close that."""
    target = rgb(stroke_scene([(rounded_square(12, 12, 52, 52, 4.0), True)]))
    sharp = [np.array([[12.0, 12.0], [52.0, 12.0]]), np.array([[52.0, 12.0], [52.0, 52.0]]),
             np.array([[52.0, 52.0], [12.0, 52.0]]), np.array([[12.0, 52.0], [12.0, 12.0]])]
    scene = stroke_scene([(sharp, True)])
    before = float(((rgb(scene) - target) ** 2).mean())
    stats, _ = round_corners(scene, rgb, target, (64, 64))
    after = float(((rgb(scene) - target) ** 2).mean())
    assert stats["corners"] == 4 and stats["rounded"] == 4
    assert after < 0.2 * before, (before, after)
    segs, closed = subpath_segments(scene.shapes[0].geometry)[0]
    assert closed and sorted(len(c) - 1 for c in segs) == [1, 1, 1, 1, 3, 3, 3, 3]


def test_sharp_corners_drawn_sharp_stay():
    sharp = [np.array([[12.0, 12.0], [52.0, 12.0]]), np.array([[52.0, 12.0], [52.0, 52.0]]),
             np.array([[52.0, 52.0], [12.0, 52.0]]), np.array([[12.0, 52.0], [12.0, 12.0]])]
    target = rgb(stroke_scene([(sharp, True)]))
    scene = stroke_scene([(sharp, True)])
    stats, _ = round_corners(scene, rgb, target, (64, 64))
    assert stats["corners"] == 4 and stats["rounded"] == 0
    assert np.allclose(scene.shapes[0].geometry.points.numpy(), stroke_scene([(sharp, True)]).shapes[0].geometry.points.numpy())


def test_a_corner_traced_as_curves_between_two_lines_is_made_of_them():
    """An L whose corner the trace drew as two wobbling cubics: the lines, extended to meet,
    and a fillet of the radius the picture has."""
    drawn = [np.array([[10.0, 12.0], [48.0, 12.0]]),
             np.array([[48.0, 12.0], [48.0 + 4 * 0.5523, 12.0], [52.0, 16.0 - 4 * 0.5523], [52.0, 16.0]]),
             np.array([[52.0, 16.0], [52.0, 54.0]])]
    target = rgb(stroke_scene([(drawn, False)]))
    traced = [np.array([[10.0, 12.0], [40.0, 12.0]]), np.array([[40.0, 12.0], [47.0, 11.0], [50.0, 11.0], [51.5, 15.0]]),
              np.array([[51.5, 15.0], [53.0, 19.0], [52.5, 22.0], [52.0, 26.0]]), np.array([[52.0, 26.0], [52.0, 54.0]])]
    scene = stroke_scene([(traced, False)])
    found = corners(scene, path_segments(scene))
    assert [(c.vertex, c.last) for c in found] == [(1, 3)] and np.allclose(found[0].at, [52, 12], atol=1e-6)
    before = float(((rgb(scene) - target) ** 2).mean())
    stats, _ = round_corners(scene, rgb, target, (64, 64))
    after = float(((rgb(scene) - target) ** 2).mean())
    assert stats["rounded"] == 1 and after < 0.3 * before, (before, after)
    segs, _ = subpath_segments(scene.shapes[0].geometry)[0]
    assert [len(c) - 1 for c in segs] == [1, 3, 1]
    assert np.allclose(segs[0][0], [10, 12], atol=1e-4) and np.allclose(segs[-1][-1], [52, 54], atol=1e-4)


def test_arc_handles_are_a_circles():
    c = _arc(np.array([10.0, 0.0]), np.array([0.0, 1.0]), np.array([0.0, 10.0]), np.array([-1.0, 0.0]))
    assert np.allclose(c[1], [10, 10 * 4 / 3 * math.tan(math.pi / 8)])


def test_a_square_corner_traced_as_one_cubic_is_made_sharp_again():
    """A diamond's corner the trace drew as one round cubic (tabler-088's): the curve's end
    tangents, extended, meet at the corner, and two lines with a round join draw it."""
    drawn = [np.array([[12.0, 32.0], [32.0, 12.0]]), np.array([[32.0, 12.0], [52.0, 32.0]]),
             np.array([[52.0, 32.0], [32.0, 52.0]])]
    target = rgb(stroke_scene([(drawn, False)]))
    # (its neighbours curves too, straight as drawn: else it is a corner between two lines)
    traced = [np.array([[12.0, 32.0], [32.0, 12.0]]), np.array([[32.0, 12.0], [35.0, 15.0], [37.0, 17.0], [40.0, 20.0]]),
              np.array([[40.0, 20.0], [49.0, 29.0], [49.0, 35.0], [40.0, 44.0]]),
              np.array([[40.0, 44.0], [37.0, 47.0], [35.0, 49.0], [32.0, 52.0]])]
    scene = stroke_scene([(traced, False)])
    found = corners(scene, path_segments(scene))
    assert any(c.one_curve and c.vertex == 2 and np.allclose(c.at, [52, 32]) for c in found)
    before = float(((rgb(scene) - target) ** 2).mean())
    stats, _ = round_corners(scene, rgb, target, (64, 64))
    after = float(((rgb(scene) - target) ** 2).mean())
    assert stats["rounded"] >= 1 and after < 0.1 * before, (before, after)
    segs, _ = subpath_segments(scene.shapes[0].geometry)[0]
    corner = [k for k, c in enumerate(segs) if len(c) == 2 and np.allclose(c[1], [52, 32], atol=1e-3)]
    assert corner and len(segs[corner[0] + 1]) == 2  # two lines, the corner sharp where they meet


def test_a_frame_with_round_corners_is_traced_with_them(tmp_path):
    """Tabler's frames: a rect whose corners have the stroke's half width for radius. It
    thins to sharp corners, on which a bevel beat round joins; the trace now comes back
    round-joined, each corner a quarter arc of that radius (the tracer chose bevel before,
    and the fit kept the corners cut)."""
    from PIL import Image

    import vecfit
    (tmp_path / "frame.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="128" height="128"><path fill="none" stroke="#202020" '
        'stroke-width="12" d="M30 25 H98 A6 6 0 0 1 104 31 V97 A6 6 0 0 1 98 103 H30 A6 6 0 0 1 24 97 V31 '
        'A6 6 0 0 1 30 25 Z"/></svg>')
    image = vecfit.render(vecfit.load_svg(tmp_path / "frame.svg"), 128, 128, samples=4,
                          background=[1, 1, 1, 1]).numpy()
    Image.fromarray((np.clip(image, 0, 1) * 255 + 0.5).astype(np.uint8)).save(tmp_path / "frame.png")
    written, report = vecfit.trace(tmp_path / "frame.png", settings={"optimize": {"threads": 1}}, effort="quick",
                                   style="strokes")
    assert 'stroke-linejoin="round"' in written
    assert report["traced_corners"]["rounded"] == 4
    (tmp_path / "traced.svg").write_text(written)
    path = [s for s in vecfit.load_svg(tmp_path / "traced.svg").shapes if s.stroke is not None][0].geometry
    segs, closed = subpath_segments(path)[0]
    arcs = [c for c in segs if len(c) == 4]
    assert closed and len(arcs) == 4 and sum(len(c) == 2 for c in segs) in (4, 5)  # (a side split where the loop starts)
    for c in arcs:  # a quarter arc of radius 6: its ends 6 sqrt(2) apart
        assert abs(np.hypot(*(c[3] - c[0])) - 6 * math.sqrt(2)) < 1.0, c
