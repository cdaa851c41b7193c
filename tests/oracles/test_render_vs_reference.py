"""vecfit.render against the NumPy reference renderer on small scenes built in code.

Images are compared premultiplied (straight colour is meaningless where alpha is near zero).

Tolerances, Monte Carlo mode (vecfit samples=8, i.e. 64 stratified jittered samples per pixel;
reference samples=16, a regular 16 x 16 grid):
- Per pixel, max < 0.25: the coverage of a pixel crossed by one straight edge, estimated from
  s x s stratified jittered samples, has variance at most s * (1/4) / s^4 (only the ~s strata
  the edge crosses are uncertain, each a Bernoulli of weight 1 / s^2): a standard deviation
  below 1 / (2 s^1.5) = 0.022 for s = 8, so about 0.09 at 4 sigma over a few hundred edge
  pixels; the reference's own grid adds at most ~1/16 on an edge pixel; corners and joins double
  the uncertain strata. A missing cap, join or shape leaves whole pixels wrong by far more.
- Mean absolute error per channel over the image, < 0.01: edge-pixel errors are zero-mean and
  edge pixels a small fraction of the image. Measured with the reference itself standing in for
  the core (jittered 8 x 8 vs regular 16 x 16, two seeds, every scene below): mean <= 0.0013,
  max <= 0.062, so the bounds leave a margin of about 7x and 4x. A systematic error of half a
  pixel along a 60 px edge of an opaque shape (30 px^2 of a 4096 px image: 0.007 in alpha,
  up to that again in a colour channel) is at the edge of detection; larger ones fail.
Analytic mode (samples=1): the prefilter approximates the box-filtered coverage from the
distance to the closest curve with a parabolic kernel; a straight edge at a quarter pixel from
the centre already differs by ~0.09 from the box filter, corners and joins more, so we only
require mean < 0.03 and max < 0.5 (the max still catches a missing cap, join or shape).

The stroke scenes are also compared at 32 x 32 samples on both sides with max < 0.04 (see
PRECISE_SCENES): a systematic geometric difference of a tenth of a pixel's coverage hides in
the noise allowance above but not there.

On failure, tests/failures/render_vs_reference-<scene>-<mode>.png holds
expected | |difference| x 4 | actual (premultiplied, over a checkerboard, scaled x4).
"""
from __future__ import annotations

import math
from pathlib import Path as FsPath

import numpy as np
import pytest
import torch

from helpers import slow_unless
from reference_render import premultiply, render_reference
from vecfit.scene import (Circle, Ellipse, Group, LinearGradient, Path, RadialGradient,
                                   Rect, Scene, Shape, Solid)

pytest.importorskip(
    "vecfit._core", reason="vecfit._core is not built (compile the C++ core to run these tests)")

FAILURES = FsPath(__file__).resolve().parents[1] / "failures"

MC_MEAN, MC_MAX = 0.01, 0.25
AN_MEAN, AN_MAX = 0.03, 0.5


def T(x):
    return torch.tensor(x, dtype=torch.float32)


def solid(*c):
    return Solid(T(list(c) if len(c) == 4 else list(c) + [1.0]))


def poly(pts, closed=True):
    pts = np.asarray(pts, dtype=np.float64)
    n = len(pts) if closed else len(pts) - 1
    return Path(T(pts), np.ones(n, dtype=np.int32), [(0, n, closed)])


def rot(deg, cx=0.0, cy=0.0):
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    return T([[c, -s, cx - c * cx + s * cy], [s, c, cy - s * cx - c * cy], [0, 0, 1]])


def _star(c, R, a0=-90.0 + 7.0):
    ang = [math.radians(a0) + k * 4 * math.pi / 5 for k in range(5)]
    return [[c[0] + R * math.cos(a), c[1] + R * math.sin(a)] for a in ang]


def _stops(*cols):
    k = len(cols)
    return T(list(np.linspace(0, 1, k))), T([list(c) for c in cols])


# ------------------------------------------------------------------------------ scenes
# Each builder returns (scene, width, height). Sizes 48..64 px.

def scene_polygon():
    pts = [[6, 8], [40, 5], [58, 30], [36, 26], [30, 56], [12, 40]]  # concave
    return Scene(64, 64, [Shape(poly(pts), fill=solid(0.9, 0.3, 0.1))]), 64, 64


def scene_cubic_blob():
    p = [[10, 40], [5, 5], [55, 0], [50, 30], [45, 60], [20, 62]]
    path = Path(T(p), np.array([3, 3]), [(0, 2, True)])
    return Scene(64, 64, [Shape(path, fill=solid(0.2, 0.5, 0.8))]), 64, 64


def scene_star_rules():
    a = Shape(poly(_star((16, 25), 15)), fill=solid(0.1, 0.6, 0.2), fill_rule="nonzero")
    b = Shape(poly(_star((47, 25), 15)), fill=solid(0.6, 0.1, 0.5), fill_rule="evenodd")
    return Scene(64, 48, [a, b]), 64, 48


def scene_circle():
    c = Shape(Circle(T([24.3, 23.6]), T(15.2)), fill=solid(1.0, 0.8, 0.0),
              stroke=solid(0.1, 0.1, 0.4), stroke_width=T(3.0))
    return Scene(48, 48, [c]), 48, 48


def scene_ellipse_rotated():
    e = Shape(Ellipse(T([0.0, 0.0]), T([24.0, 10.0])), fill=solid(0.3, 0.7, 0.9),
              stroke=solid(0.0, 0.0, 0.0), stroke_width=T(2.5),
              transform=T([[math.cos(0.5), -math.sin(0.5), 32], [math.sin(0.5), math.cos(0.5), 31],
                           [0, 0, 1]]))
    return Scene(64, 64, [e]), 64, 64


def scene_rounded_rect():
    r = Shape(Rect(T([7.0, 9.5]), T([55.0, 50.0]), T([10.0, 6.0])), fill=solid(0.8, 0.8, 0.2),
              stroke=solid(0.6, 0.0, 0.0), stroke_width=T(4.0))
    return Scene(64, 64, [r]), 64, 64


def scene_caps():
    shapes = []
    for i, cap in enumerate(["butt", "round", "square"]):
        # generic coordinates: an end tangent at 45 degrees through an integer point would put
        # a butt or square cap's edge exactly on a diagonal row of the reference's regular grid
        y = 12.3 + 18.0 * i
        path = Path(T([[10.2, y + 4.1], [22.3, y - 8.2], [38.1, y + 14.3], [52.4, y + 0.3]]),
                    np.array([3]), [(0, 1, False)])
        shapes.append(Shape(path, stroke=solid(0.1, 0.2 + 0.3 * i, 0.7), stroke_width=T(6.0),
                            linecap=cap))
    return Scene(64, 64, shapes), 64, 64


def scene_caps_on_tight_arcs():
    """Half circles of radius 10 stroked 8 wide: square caps (top) and round caps (bottom). The
    square cap is only the half-square beyond the end; a w x w square centred on the end pokes
    out of the curved stroke's outer side (about 1 px^2 per end here)."""
    k = 0.5522847498
    shapes = []
    for cap, (cx, cy), sgn in [("square", (32.3, 22.6), -1.0), ("round", (31.7, 42.4), 1.0)]:
        r = 10.0
        # from (cx - r, cy) over the top (sgn -1: towards smaller y) to (cx + r, cy)
        P = [[cx - r, cy], [cx - r, cy + sgn * k * r], [cx - k * r, cy + sgn * r],
             [cx, cy + sgn * r], [cx + k * r, cy + sgn * r], [cx + r, cy + sgn * k * r],
             [cx + r, cy]]
        shapes.append(Shape(Path(T(P), np.array([3, 3]), [(0, 2, False)]),
                            stroke=solid(0.1, 0.3, 0.6), stroke_width=T(8.0), linecap=cap))
    return Scene(64, 64, shapes), 64, 64


def scene_joins():
    shapes = []
    # (join, miter limit, interior angle in degrees)
    cases = [("miter", 4.0, 60.0),   # ratio 1 / sin(30) = 2 <= 4: miter
             ("miter", 4.0, 20.0),   # ratio 1 / sin(10) = 5.8 > 4: bevel
             ("round", 4.0, 60.0), ("bevel", 4.0, 60.0)]
    for i, (join, limit, ang) in enumerate(cases):
        cx, cy = 16.0 + 32.0 * (i % 2), 10.0 + 30.0 * (i // 2)
        a = math.radians(ang)
        v = np.array([cx, cy])
        p0 = v + 18 * np.array([-math.sin(a / 2), math.cos(a / 2)])
        p2 = v + 18 * np.array([math.sin(a / 2), math.cos(a / 2)])
        shapes.append(Shape(poly([p0, v, p2], closed=False), stroke=solid(0.2, 0.2, 0.2),
                            stroke_width=T(5.0), linejoin=join, miter_limit=limit))
    return Scene(64, 64, shapes), 64, 64


def scene_closed_stroke():
    # closed subpath of lines and a quadratic, ending with an explicit closing line
    p = [[10, 12], [50, 8], [56, 40], [30, 60], [14, 44]]
    path = Path(T(p), np.array([1, 1, 2, 1]), [(0, 4, True)])
    return Scene(64, 64, [Shape(path, fill=solid(0.9, 0.9, 0.9), stroke=solid(0.0, 0.3, 0.6),
                                stroke_width=T(5.0))]), 64, 64


def scene_nonuniform_stroke():
    # a circle-ish cubic loop and a polyline, under a non-uniform scale with skew: the stroke
    # width must vary around the outline as in local space
    m = T([[2.2, 0.6, 6.0], [0.0, 0.7, 14.0], [0, 0, 1]])
    k = 0.5522847498
    c, r = np.array([10.0, 25.0]), 8.0
    P = c + r * np.array([[1, 0], [1, k], [k, 1], [0, 1], [-k, 1], [-1, k], [-1, 0], [-1, -k],
                          [-k, -1], [0, -1], [k, -1], [1, -k]])
    loop = Shape(Path(T(P), np.array([3, 3, 3, 3]), [(0, 4, True)]), stroke=solid(0.8, 0.1, 0.1),
                 stroke_width=T(3.0), transform=m)
    line = Shape(poly([[2, 2], [14, 8], [20, 2]], closed=False), stroke=solid(0.1, 0.1, 0.8),
                 stroke_width=T(2.0), linecap="square", transform=m)
    return Scene(64, 64, [loop, line]), 64, 64


def scene_linear_gradients():
    off, col = _stops((1, 0, 0, 1), (0, 0, 1, 0.6), (0, 1, 0, 1))
    user = LinearGradient(T([4.0, 4.0]), T([30.0, 20.0]), off, col, units="userSpaceOnUse")
    bbox = LinearGradient(T([0.0, 0.0]), T([0.0, 1.0]), off, col,
                          transform=T([[1.0, 0.3, 0.0], [0.0, 1.0, 0.0], [0, 0, 1]]))
    a = Shape(Rect(T([2.0, 2.0]), T([30.0, 60.0])), fill=user)
    b = Shape(poly([[34, 4], [62, 10], [58, 60], [38, 50]]), fill=bbox)
    return Scene(64, 64, [a, b]), 64, 64


def scene_radial_gradients():
    off, col = _stops((1, 1, 0, 1), (1, 0, 0, 1), (0, 0, 0.5, 1))
    focal = RadialGradient(T([16.0, 20.0]), T(14.0), T([11.0, 15.0]), off, col,
                           units="userSpaceOnUse")
    bbox = RadialGradient(T([0.5, 0.5]), T(0.5), T([0.35, 0.5]), off, col,
                          units="objectBoundingBox")
    a = Shape(Circle(T([16.0, 20.0]), T(15.0)), fill=focal)
    b = Shape(Rect(T([34.0, 4.0]), T([62.0, 60.0])), fill=bbox, stroke=focal,
              stroke_width=T(3.0))
    return Scene(64, 64, [a, b]), 64, 64


def scene_transparency():
    a = Shape(Circle(T([22.0, 22.0]), T(15.0)), fill=solid(1, 0, 0, 0.5))
    b = Shape(Circle(T([34.0, 26.0]), T(15.0)), fill=solid(0, 0, 1, 0.5))
    c = Shape(Rect(T([10.0, 30.0]), T([40.0, 44.0])), fill=solid(0, 0.8, 0, 1.0),
              fill_opacity=T(0.5))
    return Scene(48, 48, [a, b, c]), 48, 48


def scene_shape_opacity_layer():
    s = Shape(Rect(T([12.0, 12.0]), T([40.0, 36.0])), fill=solid(1, 0, 0),
              stroke=solid(0, 0, 1), stroke_width=T(8.0), opacity=T(0.5))
    t = Shape(Circle(T([30.0, 30.0]), T(10.0)), fill=solid(0, 0.7, 0), stroke=solid(0, 0, 0, 0.5),
              stroke_width=T(4.0), opacity=T(0.6), stroke_opacity=T(0.8))
    return Scene(48, 48, [s, t]), 48, 48


def scene_nested_groups():
    groups = [Group(transform=rot(10.0, 32, 32), opacity=T(0.7)),
              Group(transform=T([[1.0, 0, 4.0], [0, 1.0, -2.0], [0, 0, 1]]), opacity=T(0.5),
                    parent=0)]
    shapes = [Shape(Rect(T([6.0, 6.0]), T([40.0, 40.0])), fill=solid(1, 0, 0), group=0),
              Shape(Circle(T([38.0, 36.0]), T(16.0)), fill=solid(0, 0, 1), group=1),
              Shape(Rect(T([30.0, 20.0]), T([56.0, 30.0])), fill=solid(0, 1, 0), group=1),
              Shape(poly([[4, 60], [60, 44], [60, 60]]), fill=solid(0.5, 0.5, 0.5), group=0),
              Shape(Circle(T([12.0, 52.0]), T(8.0)), fill=solid(1, 1, 0, 0.8))]
    return Scene(64, 64, shapes, groups), 64, 64


def scene_zero_length_subpaths():
    shapes = []
    for i, cap in enumerate(["round", "square", "butt"]):
        p = [14.0 + 18.0 * i, 20.0]
        shapes.append(Shape(Path(T([p, p]), np.array([1]), [(0, 1, False)]),
                            stroke=solid(0.1, 0.1, 0.1), stroke_width=T(9.0), linecap=cap))
        # a closed "M x y Z" dot, rotated: the square follows the local axes
        q = [14.0 + 18.0 * i, 40.0]
        shapes.append(Shape(Path(T([[0.0, 0.0]]), np.array([1]), [(0, 1, True)]),
                            stroke=solid(0.6, 0.1, 0.1), stroke_width=T(9.0), linecap=cap,
                            transform=T([[1.0, 0, q[0]], [0, 1.0, q[1]], [0, 0, 1]]) @ rot(30.0)))
    return Scene(64, 56, shapes), 64, 56


def scene_view_and_resolution():
    # scene units differ from pixels: a 32 x 24 scene with a view transform, drawn at 64 x 48
    view = T([[0.8, 0.0, 3.0], [0.0, 0.8, 2.0], [0, 0, 1]])
    s = Shape(Path(T([[2, 2], [30, 4], [20, 22], [4, 14]]), np.array([2, 1, 1]), [(0, 3, True)]),
              fill=solid(0.3, 0.3, 0.9), stroke=solid(0, 0, 0), stroke_width=T(1.5),
              linejoin="round")
    return Scene(32, 24, [s], view=view), 64, 48


SCENES = {f.__name__[len("scene_"):]: f for f in [
    scene_polygon, scene_cubic_blob, scene_star_rules, scene_circle, scene_ellipse_rotated,
    scene_rounded_rect, scene_caps, scene_caps_on_tight_arcs, scene_joins, scene_closed_stroke,
    scene_nonuniform_stroke, scene_linear_gradients, scene_radial_gradients, scene_transparency,
    scene_shape_opacity_layer, scene_nested_groups, scene_zero_length_subpaths,
    scene_view_and_resolution]}

_REFERENCE: dict[str, np.ndarray] = {}


def reference(name):
    if name not in _REFERENCE:
        scene, w, h = SCENES[name]()
        _REFERENCE[name] = render_reference(scene, w, h, samples=16, premultiplied=True)
    return _REFERENCE[name]


# -------------------------------------------------------------------------- comparison

def _checker(h, w, cell=4):
    y, x = np.mgrid[0:h, 0:w]
    return np.where(((x // cell) + (y // cell)) % 2 == 0, 0.8, 1.0)[..., None]


def save_failure(name, expected, actual):
    """expected | |difference| x 4 | actual, premultiplied RGBA over a checkerboard, x4."""
    from PIL import Image
    FAILURES.mkdir(exist_ok=True)
    h, w = expected.shape[:2]
    over = lambda img: img[..., :3] + (1 - img[..., 3:4]) * _checker(h, w)
    diff = np.clip(4 * np.abs(expected - actual).max(axis=-1, keepdims=True), 0, 1)
    gap = np.ones((h, 2, 3))
    row = np.concatenate([over(expected), gap, np.repeat(diff, 3, axis=-1), gap, over(actual)],
                         axis=1)
    img = Image.fromarray((np.clip(row, 0, 1) * 255 + 0.5).astype(np.uint8))
    img = img.resize((img.width * 4, img.height * 4), Image.NEAREST)
    path = FAILURES / f"render_vs_reference-{name}.png"
    img.save(path)
    return path


def compare(name, expected, actual, mean_tol, max_tol):
    assert actual.shape == expected.shape, f"shape {actual.shape}, expected {expected.shape}"
    err = np.abs(actual - expected)
    mean = err.reshape(-1, 4).mean(axis=0)
    worst = float(err.max())
    flat = int(np.argmax(err.max(axis=-1)))
    where = tuple(int(i) for i in np.unravel_index(flat, err.shape[:2]))
    if not (np.all(mean < mean_tol) and worst < max_tol):
        path = save_failure(name, expected, actual)
        pytest.fail(f"{name}: mean abs error per channel (RGBA, premultiplied) {np.round(mean, 4)} "
                    f"(tolerance {mean_tol}), max {worst:.3f} at pixel (y, x) = {where} "
                    f"(tolerance {max_tol}); picture: {path}")
    return mean, worst


def _render(scene, w, h, **kw):
    import vecfit
    img = vecfit.render(scene, w, h, **kw)
    img = img.detach().cpu().double().numpy() if hasattr(img, "detach") else np.asarray(img)
    assert img.shape == (h, w, 4)
    assert np.isfinite(img).all() and img.min() >= -1e-6 and img.max() <= 1 + 1e-6
    return premultiply(np.clip(img, 0.0, 1.0))


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SCENES))
def test_mc_matches_reference(name):
    scene, w, h = SCENES[name]()
    actual = _render(scene, w, h, samples=8, mode="mc", seed=0)
    compare(f"{name}-mc", reference(name), actual, MC_MEAN, MC_MAX)


@pytest.mark.parametrize("name", slow_unless(list(SCENES), ["circle", "cubic_blob", "joins", "transparency"]))
def test_analytic_matches_reference(name):
    scene, w, h = SCENES[name]()
    actual = _render(scene, w, h, samples=1, mode="analytic")
    compare(f"{name}-analytic", reference(name), actual, AN_MEAN, AN_MAX)


# Stroke geometry (caps, joins, sweeps) at high sampling, where a small systematic difference
# cannot hide in the noise: 32 x 32 samples on both sides. MC standard deviation on a straight
# edge pixel <= 1 / (2 * 32^1.5) = 0.0028 (0.014 at 5 sigma, twice that at a corner); the
# regular 32 x 32 grid errs by < 1/32 even where an edge runs along a row of samples, which the
# scenes avoid. Measured with the reference standing in for the core (jittered vs regular):
# max <= 0.016 over all scenes.
PRECISE_SCENES = ["caps", "caps_on_tight_arcs", "joins", "closed_stroke", "nonuniform_stroke",
                  "zero_length_subpaths"]
PRECISE_MAX, PRECISE_MEAN = 0.04, 0.002
_PRECISE_REF: dict[str, np.ndarray] = {}


@pytest.mark.slow
@pytest.mark.parametrize("name", PRECISE_SCENES)
def test_mc_matches_reference_precisely(name):
    scene, w, h = SCENES[name]()
    if name not in _PRECISE_REF:
        _PRECISE_REF[name] = render_reference(scene, w, h, samples=32, premultiplied=True)
    actual = _render(scene, w, h, samples=32, mode="mc", seed=0)
    compare(f"{name}-mc32", _PRECISE_REF[name], actual, PRECISE_MEAN, PRECISE_MAX)


def test_background_matches_reference():
    scene, w, h = scene_transparency()
    bg = (0.2, 0.4, 0.6, 1.0)
    expected = render_reference(scene, w, h, samples=16, background=bg, premultiplied=True)
    actual = _render(scene, w, h, samples=8, mode="mc", background=bg)
    compare("transparency-background-mc", expected, actual, MC_MEAN, MC_MAX)
