"""Clip paths, masks and filters drawn in layers (vecfit/renderer/layers.py, filters.py):
pictures against values known in closed form, and the layered path against the one pass
of the core where both apply."""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import vecfit
from vecfit.renderer import filters
from vecfit.scene import (Circle, ClipPath, Filter, FilterStep, Group, Mask, Rect, Scene, Shape,
                          Solid)

SIZE = 64


def solid(*rgba):
    return Solid(torch.tensor(rgba, dtype=torch.float32))


def rect(x0, y0, x1, y1, color=(1, 0, 0, 1), **kw):
    return Shape(geometry=Rect(p_min=torch.tensor([float(x0), float(y0)]), p_max=torch.tensor([float(x1), float(y1)])),
                 fill=solid(*color), **kw)


def circle(cx, cy, r, color=(0, 0, 0, 1), **kw):
    return Shape(geometry=Circle(center=torch.tensor([float(cx), float(cy)]), radius=torch.tensor(float(r))),
                 fill=solid(*color), **kw)


def content(*shapes, view=None):
    scene = Scene(width=1, height=1, shapes=list(shapes))
    if view is not None:
        scene.view = torch.tensor(view, dtype=torch.float32)
    return scene


def render(scene, **kw):
    kw.setdefault("samples", 4)
    kw.setdefault("mode", "analytic")
    return vecfit.render(scene, SIZE, SIZE, **kw)


def test_a_clip_lets_through_its_shape_area():
    shape = rect(0, 0, 64, 64, clip=ClipPath(content(circle(32, 32, 20))))
    alpha = render(Scene(width=SIZE, height=SIZE, shapes=[shape]))[..., 3]
    assert float(alpha.sum()) == pytest.approx(math.pi * 400, rel=2e-3)
    assert float(alpha[32, 32]) == 1 and float(alpha[2, 2]) == 0


def test_clip_rule_transform_and_bounding_box_units():
    # A ring (evenodd of two circles) in bounding-box units of a 40 x 40 square at 12, 12,
    # moved by the clip's own transform 4 px right (in user space: after the box).
    ring = content(Shape(geometry=_two_circles(0.5, 0.5, 0.5, 0.25), fill=solid(0, 0, 0, 1), fill_rule="evenodd"),
                   view=[[1, 0, 4], [0, 1, 0], [0, 0, 1]])
    clip = ClipPath(ring, units="objectBoundingBox")
    shape = rect(12, 12, 52, 52, clip=clip)
    alpha = render(Scene(width=SIZE, height=SIZE, shapes=[shape]))[..., 3]
    # The ring (radii 20 and 10 around 36, 32) less the cap of it right of the square's
    # edge at x = 52, 16 from its centre.
    cap = 400 * math.acos(16 / 20) - 16 * math.sqrt(400 - 256)
    assert float(alpha.sum()) == pytest.approx(math.pi * (400 - 100) - cap, rel=5e-3)
    assert float(alpha[32, 36]) == 0  # the hole, centred at 36, 32
    assert float(alpha[32, 36 + 13]) == 1


def _two_circles(cx, cy, r1, r2):
    from vecfit.scene import Path
    k = 0.5522847498307936
    pts, degrees, subpaths = [], [], []
    for r in (r1, r2):
        start = len(degrees)
        ring = [(cx + r, cy), (cx + r, cy + k * r), (cx + k * r, cy + r), (cx, cy + r),
                (cx - k * r, cy + r), (cx - r, cy + k * r), (cx - r, cy), (cx - r, cy - k * r),
                (cx - k * r, cy - r), (cx, cy - r), (cx + k * r, cy - r), (cx + r, cy - k * r)]
        pts += ring
        degrees += [3, 3, 3, 3]
        subpaths.append((start, 4, True))
    return Path(points=torch.tensor(pts, dtype=torch.float32), degrees=np.array(degrees), subpaths=subpaths)


def test_a_clip_on_a_group_clips_the_composite_and_a_clip_on_the_clip_intersects():
    inner = ClipPath(content(rect(0, 0, 32, 64, color=(0, 0, 0, 1))))
    clip = ClipPath(content(circle(32, 32, 20)), clip=inner)
    group = Group(clip=clip, opacity=torch.tensor(0.5))
    scene = Scene(width=SIZE, height=SIZE, groups=[group],
                  shapes=[rect(0, 0, 64, 64, color=(1, 0, 0, 1), group=0), rect(0, 0, 64, 64, color=(0, 0, 1, 1), group=0)])
    image = render(scene)
    assert float(image[..., 3].sum()) == pytest.approx(0.5 * math.pi * 400 / 2, rel=3e-3)
    assert image[32, 20].tolist() == pytest.approx([0, 0, 1, 0.5])  # the blue on top, at half opacity


def test_luminance_and_alpha_masks_with_their_region():
    grey = rect(0, 0, 64, 64, color=(0.5, 0.5, 0.5, 0.8))
    for kind, expected in (("luminance", 0.5 * 0.8), ("alpha", 0.8)):
        # Region: the masked square's box grown by 10% (the default), so half of it
        # lies outside the mask's own content here.
        mask = Mask(content(grey), kind=kind)
        image = render(Scene(width=SIZE, height=SIZE, shapes=[rect(16, 16, 48, 48, mask=mask)]))
        assert float(image[32, 32, 3]) == pytest.approx(expected, abs=1e-5)
        assert float(image[8, 8, 3]) == 0
    # User-space region: only the part left of x = 32 lets through.
    mask = Mask(content(rect(0, 0, 64, 64, color=(1, 1, 1, 1))), units="userSpaceOnUse", region=(0, 0, 32, 64))
    alpha = render(Scene(width=SIZE, height=SIZE, shapes=[rect(4, 4, 60, 60, mask=mask)]))[..., 3]
    assert float(alpha.sum()) == pytest.approx(28 * 56, rel=1e-4)


def test_a_blur_spreads_a_layer_as_a_gaussian_and_keeps_its_ink():
    step = FilterStep("GaussianBlur", ["SourceGraphic"], params={"std": (3.0, 1.0)}, linear_rgb=False)
    blurred = rect(24, 24, 40, 40, color=(0, 0, 0, 1), filter=Filter([step], units="userSpaceOnUse",
                                                                     region=(0, 0, 64, 64)))
    alpha = render(Scene(width=SIZE, height=SIZE, shapes=[blurred]))[..., 3]
    assert float(alpha.sum()) == pytest.approx(16 * 16, rel=2e-3)  # mass kept (well inside the canvas)
    row = alpha[32].double().numpy()
    # Across x the edge at 24 is spread by a Gaussian of deviation 3 (the error function).
    x = np.arange(SIZE) + 0.5
    expected = 0.5 * (_erf((x - 24) / (3 * math.sqrt(2))) - _erf((x - 40) / (3 * math.sqrt(2))))
    assert np.abs(row - expected).max() < 0.02


def _erf(x):
    return np.vectorize(math.erf)(x)


def test_drop_shadow_offset_flood_and_merge():
    shadow = FilterStep("DropShadow", ["SourceGraphic"], linear_rgb=False,
                        params={"std": (0.0, 0.0), "dx": 8.0, "dy": 4.0, "color": (0.0, 0.0, 1.0, 0.5)})
    shape = rect(16, 16, 32, 32, color=(1, 0, 0, 1), filter=Filter([shadow], units="userSpaceOnUse",
                                                                   region=(0, 0, 64, 64)))
    image = render(Scene(width=SIZE, height=SIZE, shapes=[shape]))
    assert image[20, 20].tolist() == pytest.approx([1, 0, 0, 1])
    assert image[34, 36].tolist() == pytest.approx([0, 0, 1, 0.5])  # the shadow alone
    flood = FilterStep("Flood", [], params={"color": (0, 1, 0, 1)}, region=(8.0, None, 8.0, None))
    offset = FilterStep("Offset", ["SourceGraphic"], result="moved", params={"dx": 10.0, "dy": 0.0})
    merge = FilterStep("Merge", ["", "moved"])
    shape = rect(16, 16, 32, 32, color=(1, 0, 0, 1), filter=Filter([offset, flood, merge], units="userSpaceOnUse",
                                                                   region=(0, 0, 64, 64)))
    image = render(Scene(width=SIZE, height=SIZE, shapes=[shape]))
    assert image[40, 10].tolist() == pytest.approx([0, 1, 0, 1])   # the flood's strip, x 8..16
    assert image[20, 38].tolist() == pytest.approx([1, 0, 0, 1])   # the moved square
    assert image[20, 20, 3] == 0 and image[40, 30, 3] == 0        # (the source is not merged)


def test_linear_rgb_round_trip_and_colour_matrix():
    image = torch.rand(5, 5, 4)
    image[..., :3] *= image[..., 3:]
    assert torch.allclose(filters.to_srgb(filters.to_linear(image)), image, atol=1e-5)
    out = filters.color_matrix(image, "saturate", [0.0])
    grey = out[..., :3] / out[..., 3:]
    assert torch.allclose(grey[..., 0], grey[..., 1], atol=1e-5)


def test_a_layer_keeps_its_place_in_the_paint_order():
    under = rect(8, 8, 56, 56, color=(1, 0, 0, 1))
    middle = circle(32, 32, 12, color=(0, 0, 1, 0.7))
    top = rect(28, 28, 36, 36, color=(0, 1, 0, 1), group=0)
    groups = [Group(opacity=torch.tensor(0.6))]
    plain = Scene(width=SIZE, height=SIZE, shapes=[under, middle, top], groups=groups)
    # The same scene with a clip that lets everything through on the middle shape.
    everything = ClipPath(content(rect(-10, -10, 80, 80)))
    clipped = Scene(width=SIZE, height=SIZE, groups=groups,
                    shapes=[under, Shape(**{**middle.__dict__, "clip": everything}), top])
    blue_over_red = 0.7 * torch.tensor([0.0, 0, 1]) + 0.3 * torch.tensor([1.0, 0, 0])
    expected = 0.6 * torch.tensor([0.0, 1, 0]) + 0.4 * blue_over_red
    for mode in ("analytic", "mc"):
        a = render(plain, mode=mode, background=(1, 1, 1))
        b = render(clipped, mode=mode, background=(1, 1, 1))
        assert b[32, 32, :3].tolist() == pytest.approx(expected.tolist(), abs=1e-5)
        assert a[32, 32].tolist() == pytest.approx(b[32, 32].tolist(), abs=1e-5)
        # Elsewhere they differ only where edges of the layer and of the shapes under it
        # share a pixel (compositing coverages, each from samples of its own, as resvg
        # composites anti-aliased layers).
        assert (a - b).abs().mean() < (2e-4 if mode == "analytic" else 3e-3)


def test_effects_that_leave_nothing():
    empty = Scene(width=SIZE, height=SIZE, shapes=[rect(0, 0, 64, 64, clip=ClipPath(content()))])
    assert float(render(empty)[..., 3].sum()) == 0
    no_steps = Scene(width=SIZE, height=SIZE, shapes=[rect(0, 0, 64, 64, filter=Filter([]))])
    assert float(render(no_steps)[..., 3].sum()) == 0
    line = Shape(geometry=Rect(p_min=torch.tensor([0.0, 10.0]), p_max=torch.tensor([64.0, 10.0])),
                 stroke=solid(0, 0, 0, 1), stroke_width=torch.tensor(4.0),
                 clip=ClipPath(content(rect(0, 0, 1, 1)), units="objectBoundingBox"))
    assert float(render(Scene(width=SIZE, height=SIZE, shapes=[line]))[..., 3].sum()) == 0


def test_a_huge_deviation_fades_and_takes_little_time():
    import time
    step = FilterStep("GaussianBlur", ["SourceGraphic"], params={"std": (1e6, 1e6)})
    shape = rect(16, 16, 48, 48, filter=Filter([step]))
    start = time.perf_counter()
    alpha = render(Scene(width=SIZE, height=SIZE, shapes=[shape]))[..., 3]
    assert time.perf_counter() - start < 5
    assert float(alpha.max()) < 1e-3 and torch.isfinite(alpha).all()


def test_blend_modes_onto_what_is_below_and_isolation():
    below = rect(0, 0, 64, 64, color=(0.2, 0.6, 1.0, 1))
    top = rect(16, 16, 48, 48, color=(0.5, 0.5, 0.5, 1), blend="multiply", group=0)
    # A plain group does not isolate: its multiply reaches the rect below the group.
    image = render(Scene(width=SIZE, height=SIZE, shapes=[below, top], groups=[Group()]))
    assert image[32, 32].tolist() == pytest.approx([0.1, 0.3, 0.5, 1], abs=1e-5)
    assert image[4, 4].tolist() == pytest.approx([0.2, 0.6, 1.0, 1], abs=1e-5)
    # isolation: isolate: it multiplies what is in the group only (nothing), so over.
    image = render(Scene(width=SIZE, height=SIZE, shapes=[below, top], groups=[Group(isolate=True)]))
    assert image[32, 32].tolist() == pytest.approx([0.5, 0.5, 0.5, 1], abs=1e-5)
    for mode, expected in (("screen", [0.6, 0.8, 1.0]), ("darken", [0.2, 0.5, 0.5]), ("lighten", [0.5, 0.6, 1.0])):
        shape = rect(16, 16, 48, 48, color=(0.5, 0.5, 0.5, 1), blend=mode)
        image = render(Scene(width=SIZE, height=SIZE, shapes=[below, shape]))
        assert image[32, 32, :3].tolist() == pytest.approx(expected, abs=1e-5), mode
