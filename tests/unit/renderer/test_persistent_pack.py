"""The fitting loop's persistent pack (vecfit/renderer/persistent.py): the same image and
the same gradients as packing the Scene on every call, where it applies, and no pack
(None, with the reason logged) where it does not. The pack does not check itself when it
is built: its agreement with packing anew (the floats, and their gradients for a random
adjoint, where a missed or wrong route shows) is asserted here, on every kind of value a
route serves and on the shared scenes."""
from __future__ import annotations

import warnings

import pytest
import torch

from vecfit.errors import VecfitWarning
from vecfit.fitting import loop
from vecfit.fitting.loop import Settings, Target, optimize
from vecfit.fitting.rates import parameter_kinds
from vecfit.renderer.forward import FLOAT_INPUTS, packed_for_core
from vecfit.renderer.persistent import PersistentPack
from vecfit.renderer.raster import render
from vecfit.svg.read import load_svg

from shared_data import SHARED

# Every kind of float the core reads that an affine route serves: path points under a
# group's scale and a shape's rotation, per-point and uniform stroke widths, circles and
# ellipses, solid colours under fixed opacities (one a layer), user-space and bounding-box
# gradients (the latter on a shape whose geometry stays put: see RATES), a viewBox.
MIXED = """<svg xmlns="http://www.w3.org/2000/svg" width="64" height="48" viewBox="0 0 128 96">
  <defs>
    <linearGradient id="lin" gradientUnits="userSpaceOnUse" x1="10" y1="10" x2="100" y2="80">
      <stop offset="0.1" stop-color="#f00"/><stop offset="0.9" stop-color="#00f" stop-opacity="0.6"/>
    </linearGradient>
    <radialGradient id="rad" gradientUnits="userSpaceOnUse" cx="90" cy="30" r="30" fx="80" fy="25">
      <stop offset="0" stop-color="#ff0"/><stop offset="1" stop-color="#0a0"/>
    </radialGradient>
  </defs>
  <path d="M0 0 H128 V96 H0 Z" fill="#eee"/>
  <g transform="translate(4 6) scale(1.2)" opacity="0.7">
    <path d="M10 10 C40 0 60 40 90 20 L80 70 Q40 90 12 60 Z" fill="url(#lin)" stroke="#123"
          stroke-width="3" stroke-opacity="0.5"/>
    <path d="M20 20 L50 25 L40 60 Z" fill="#c84" fill-opacity="0.8"/>
  </g>
  <circle cx="90" cy="30" r="20" fill="url(#rad)" stroke="#345" stroke-width="2"/>
  <ellipse cx="40" cy="70" rx="20" ry="9" fill="#48c" transform="rotate(25 40 70)" opacity="0.6"
           stroke="#000" stroke-width="1.5"/>
  <path d="M5 90 C30 60 60 95 120 70" fill="none" stroke="#a0a" stroke-width="4" stroke-linecap="round"/>
</svg>"""

RATES = {"points": 1.0, "colors": 0.01, "stroke_widths": 0.1, "radii": 0.5, "gradient_points": 1.0,
         "gradient_radii": 0.5, "stop_offsets": 0.01}


def _scene(tmp_path, text=MIXED):
    path = tmp_path / "scene.svg"
    path.write_text(text)
    return load_svg(path)


def _image_and_gradients(scene, kinds, w, h, pack):
    """The image and each kind's gradient for a fixed image adjoint: through the Scene's
    tensors (pack None) or through the persistent pack's leaves."""
    for k in kinds:
        k.zero_grad()
    leaves = [k.flat.detach().requires_grad_() for k in kinds]
    image = render(scene, w, h, seed=5, threads=2, interior_samples=1,
                   packed=pack.arrays(leaves) if pack is not None else None)
    weights = torch.linspace(-1, 1, image.numel()).reshape(image.shape)
    (image * weights).sum().backward()
    return image.detach(), {k.name: k.gradient(leaf if pack is not None else None) for k, leaf in zip(kinds, leaves)}


def _assert_same(scene, kinds, w, h):
    pack = PersistentPack.build(scene, w, h, kinds)
    assert pack is not None
    image, grads = _image_and_gradients(scene, kinds, w, h, None)
    image2, grads2 = _image_and_gradients(scene, kinds, w, h, pack)
    assert torch.allclose(image, image2, atol=1e-6)
    for name, g in grads.items():
        assert g.abs().max() > 0, name  # (the scene exercises every kind)
        assert torch.allclose(grads2[name], g, rtol=1e-5, atol=1e-6 * float(g.abs().max())), name


def _assert_agrees(scene, kinds, w, h, pack=None):
    """The persistent pack's floats are those of packing the scene anew, and so are their
    gradients w.r.t. every kind for a random adjoint of the floats (what the build used
    to check on every build of a fit). Returns how many kinds had a gradient."""
    pack = pack or PersistentPack.build(scene, w, h, kinds)
    assert pack is not None
    leaves = [k.flat.detach().clone().requires_grad_() for k in kinds]
    _, mine = pack.arrays(leaves)
    for k in kinds:
        k.zero_grad()
    _, packed = packed_for_core(scene, w, h)  # through the Scene's tensors (views of the kinds)
    for name, a, b in zip(FLOAT_INPUTS, mine, packed):
        assert a.shape == b.shape, name
        assert torch.allclose(a.detach(), b.detach(), rtol=1e-5, atol=1e-5), name
    generator = torch.Generator().manual_seed(0)
    adjoints = [torch.randn(f.shape, generator=generator) for f in packed]
    sum((a * g).sum() for a, g in zip(mine, adjoints)).backward()
    sum((f * g).sum() for f, g in zip(packed, adjoints) if f.requires_grad).backward()
    checked = 0
    for k, leaf in zip(kinds, leaves):
        reference = k.gradient()  # the Scene's tensors' own
        fast = leaf.grad if leaf.grad is not None else torch.zeros_like(reference)
        scale = float(reference.abs().max()) if reference.numel() else 0.0
        assert torch.allclose(fast, reference, rtol=1e-4, atol=1e-4 * max(1.0, scale)), k.name
        checked += scale > 0
    return checked


def test_mixed_scene_same_image_and_gradients(tmp_path):
    scene = _scene(tmp_path)
    kinds = parameter_kinds(scene, RATES, 64, 48)
    assert {k.name for k in kinds} == set(RATES)
    _assert_same(scene, kinds, 64, 48)
    _assert_same(scene, kinds, 37, 29)  # another size: other matrices


@pytest.mark.parametrize("size", [(64, 48), (37, 29)])
def test_mixed_scene_floats_and_their_gradients_agree(tmp_path, size):
    scene = _scene(tmp_path)
    kinds = parameter_kinds(scene, RATES, *size)
    assert _assert_agrees(scene, kinds, *size) == len(RATES)  # every kind reaches a float


def test_a_wrong_route_shows(tmp_path):
    """The agreement check sees a route that is off (here: one point's coefficient)."""
    scene = _scene(tmp_path)
    kinds = parameter_kinds(scene, {"points": 1.0}, 64, 48)
    pack = PersistentPack.build(scene, 64, 48, kinds)
    _assert_agrees(scene, kinds, 64, 48, pack)
    pack._coefficient[3] *= 1.5
    with pytest.raises(AssertionError):
        _assert_agrees(scene, kinds, 64, 48, pack)


AGREEMENT_CASES = {
    "square rect": ('<path d="M0 0 H128 V96 H0 Z" fill="#eee"/>',
                    '<rect x="3" y="4" width="100" height="80" fill="#eee" stroke="#f00"/>'),
    "bounding-box gradient, colours": ('id="lin" gradientUnits="userSpaceOnUse"', 'id="lin"'),
    "rounded rect, colours": ('<path d="M0 0 H128 V96 H0 Z" fill="#eee"/>',
                              '<rect width="128" height="96" rx="9" fill="#eee"/>'),
    "nested opacity layers": ('<path d="M20 20 L50 25 L40 60 Z" fill="#c84" fill-opacity="0.8"/>',
                              '<g opacity="0.5"><path d="M20 20 L50 25 L40 60 Z" fill="#c84"/>'
                              '<path d="M30 20 L60 25 L50 60 Z" fill="#4c8" stroke="#00f"/></g>'),
    "circle of radius 0": ('r="20" fill="url(#rad)"', 'r="0" fill="url(#rad)"'),
}


@pytest.mark.parametrize("case", sorted(AGREEMENT_CASES))
def test_floats_and_gradients_agree(tmp_path, case):
    old, new = AGREEMENT_CASES[case]
    assert old in MIXED
    scene = _scene(tmp_path, MIXED.replace(old, new))
    # (", colours": the geometry enters non-linearly there; the paints and widths do not)
    rates = {k: v for k, v in RATES.items() if k not in ("points", "radii")} if "colours" in case else RATES
    _assert_agrees(scene, parameter_kinds(scene, rates, 64, 48), 64, 48)


def _shared_scenes():
    """The shared scenes, the large ones (seconds each) marked slow."""
    folder = SHARED / "data" / "scenes"
    paths = sorted(folder.glob("*.svg")) if folder.is_dir() else []
    return [pytest.param(p.name, marks=[pytest.mark.slow] if p.stat().st_size > 200_000 else []) for p in paths]


@pytest.mark.parametrize("name", _shared_scenes())
def test_shared_scenes_agree_or_say_why_not(name):
    """Each shared scene with the default rates: the pack agrees, or there is none and the
    reason says why (clip paths, masks, filters or dashes: what the scene has)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (what the reader leaves out is not the point here)
        scene = load_svg(SHARED / "data" / "scenes" / name)
    w, h = output_size_at_most(scene, 96)
    kinds = parameter_kinds(scene, loop.Settings.defaults().lr, w, h)
    pack = PersistentPack.attempt(scene, w, h, kinds)
    if isinstance(pack, str):
        reason = pack
        if scene.has_effects():
            assert "clip paths, masks or filters" in reason
        else:
            assert "dashed strokes" in reason and any(s.dash_array is not None for s in scene.shapes)
        return
    assert _assert_agrees(scene, kinds, w, h) > 0


def output_size_at_most(scene, side: int) -> tuple[int, int]:
    s = side / max(float(scene.width), float(scene.height))
    return max(1, round(float(scene.width) * s)), max(1, round(float(scene.height) * s))


def _clipped(tmp_path):
    return _scene(tmp_path, MIXED.replace(
        "<defs>", '<defs><clipPath id="c"><rect width="60" height="60"/></clipPath>').replace(
        '<circle cx="90"', '<circle clip-path="url(#c)" cx="90"'))


def test_declines_say_why(tmp_path):
    scene = _scene(tmp_path)
    assert PersistentPack.build(scene, 64, 48, parameter_kinds(scene, {"transforms": 0.01}, 64, 48)) is None
    assert PersistentPack.attempt(scene, 64, 48, parameter_kinds(scene, {"transforms": 0.01}, 64, 48)) == \
        "transforms optimised"
    assert isinstance(PersistentPack.attempt(scene, 64, 48, parameter_kinds(scene, {"points": 1.0}, 64, 48)),
                      PersistentPack)
    clipped = _clipped(tmp_path)
    assert PersistentPack.attempt(clipped, 64, 48, parameter_kinds(clipped, {"points": 1.0}, 64, 48)) == \
        "clip paths, masks or filters (drawn in layers, several packs a render)"


def test_a_declined_pack_is_a_warning_once_a_run(tmp_path):
    """The loop asks for a pack at each image size (coarse, then fine); where the pack is
    declined the run says so once, as a VecfitWarning with the reason."""
    target = Target(torch.rand(96, 128, 4, generator=torch.Generator().manual_seed(1)), background=(1, 1, 1))
    target.image[..., 3] = 1
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        optimize(_clipped(tmp_path), target, Settings.defaults(iterations=4, threads=2, coarse=0.5, max_size=0))
    declined = [w for w in said if "packed on every iteration" in str(w.message)]
    assert [(w.category, str(w.message)) for w in declined] == [
        (VecfitWarning, "the scene is packed on every iteration, which is slower: clip paths, masks or filters "
                        "(drawn in layers, several packs a render)")]


def test_square_rect(tmp_path):
    scene = _scene(tmp_path, MIXED.replace('<path d="M0 0 H128 V96 H0 Z" fill="#eee"/>',
                                           '<rect x="3" y="4" width="100" height="80" fill="#eee" stroke="#f00"/>'))
    kinds = parameter_kinds(scene, RATES, 64, 48)
    _assert_same(scene, kinds, 64, 48)
    pack = PersistentPack.build(scene, 64, 48, kinds)
    flats = [k.flat for k in kinds]
    rect = scene.shapes[0].geometry
    with torch.no_grad():
        rect.p_max[0] = 2.0  # narrower than nothing: no longer drawn
        assert not pack.still_valid(flats)
        rect.p_max[0] = 103.0
        assert pack.still_valid(flats)
        rect.corner_radii.fill_(2.0)  # rounded: another path
        assert not pack.still_valid(flats)


def test_per_point_widths(tmp_path):
    scene = _scene(tmp_path)
    path = scene.shapes[-1].geometry
    path.widths = torch.linspace(1.0, 6.0, len(path.points))
    kinds = parameter_kinds(scene, {"points": 1.0, "stroke_widths": 0.1}, 64, 48)
    _assert_same(scene, kinds, 64, 48)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["peppers", "kitty"])
def test_adobe_trace_bit_identical(name):
    svg = SHARED / "data" / "photos" / f"{name}.svg"
    if not svg.exists():
        pytest.skip("shared data not here")
    scene = load_svg(svg)
    w, h = int(scene.width) // 2, int(scene.height) // 2
    kinds = parameter_kinds(scene, loop.Settings.defaults().lr, w, h)
    pack = PersistentPack.build(scene, w, h, kinds)
    image, grads = _image_and_gradients(scene, kinds, w, h, None)
    image2, grads2 = _image_and_gradients(scene, kinds, w, h, pack)
    assert torch.equal(image, image2)
    for name in grads:
        assert torch.equal(grads[name], grads2[name])


def test_no_pack_where_values_enter_non_linearly(tmp_path):
    scene = _scene(tmp_path)
    assert PersistentPack.build(scene, 64, 48, parameter_kinds(scene, {"transforms": 0.01}, 64, 48)) is None
    assert PersistentPack.build(scene, 64, 48, parameter_kinds(scene, {"opacities": 0.01}, 64, 48)) is None
    # a rect's corners (points kind) become path points through rect_as_path
    rect = MIXED.replace('<path d="M0 0 H128 V96 H0 Z" fill="#eee"/>', '<rect width="128" height="96" rx="9" fill="#eee"/>')
    scene = _scene(tmp_path, rect)
    assert PersistentPack.build(scene, 64, 48, parameter_kinds(scene, {"points": 1.0}, 64, 48)) is None
    assert PersistentPack.build(scene, 64, 48, parameter_kinds(scene, {"colors": 0.01}, 64, 48)) is not None
    # a bounding-box gradient's geometry: its bounds enter the paint's matrix
    bbox = MIXED.replace('id="lin" gradientUnits="userSpaceOnUse"', 'id="lin"')
    scene = _scene(tmp_path, bbox)
    assert PersistentPack.build(scene, 64, 48, parameter_kinds(scene, {"points": 1.0}, 64, 48)) is None
    # ... but the colours alone are affine there too
    assert PersistentPack.build(scene, 64, 48, parameter_kinds(scene, {"colors": 0.01}, 64, 48)) is not None


def test_draws_that_come_and_go_make_it_stale(tmp_path):
    scene = _scene(tmp_path)
    kinds = parameter_kinds(scene, {"stroke_widths": 0.1, "radii": 0.5}, 64, 48)
    pack = PersistentPack.build(scene, 64, 48, kinds)
    flats = [k.flat for k in kinds]
    assert pack.still_valid(flats)
    with torch.no_grad():
        scene.shapes[-1].stroke_width.fill_(0.0)  # the open path's stroke disappears
    assert not pack.still_valid(flats)


@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_radius_crossing_zero_keeps_the_pack(tmp_path, mode):
    """A circle whose radius crosses 0 keeps its draw, its axes 0 while the radius is <= 0
    (the core draws nothing there): the pack stays valid, and its images and gradients
    are those of packing the Scene anew (to float rounding, as _assert_same), either
    side of 0 (10,000 tiny circles were packed anew on every iteration, issue 28)."""
    scene = _scene(tmp_path)
    kinds = parameter_kinds(scene, {"points": 1.0, "colors": 0.01, "radii": 0.5}, 64, 48)
    pack = PersistentPack.build(scene, 64, 48, kinds)
    flats = [k.flat for k in kinds]
    circle = scene.shapes[3].geometry
    for radius in (-0.5, 0.0, 20.0, -3.0):
        with torch.no_grad():
            circle.radius.fill_(radius)
        assert pack.still_valid(flats)
        for with_pack in (False, True):
            for k in kinds:
                k.zero_grad()
            leaves = [k.flat.detach().requires_grad_() for k in kinds]
            image = render(scene, 64, 48, seed=5, threads=2, mode=mode,
                           packed=pack.arrays(leaves) if with_pack else None)
            (image * torch.linspace(-1, 1, image.numel()).reshape(image.shape)).sum().backward()
            grads = {k.name: k.gradient(leaf if with_pack else None) for k, leaf in zip(kinds, leaves)}
            if not with_pack:
                expected = (image.detach(), grads)
        assert torch.allclose(image.detach(), expected[0], atol=1e-6), radius
        for name, g in grads.items():
            assert torch.allclose(g, expected[1][name], rtol=1e-5, atol=1e-6 * max(1.0, float(g.abs().max()))), name
    # a fresh build where the radius is already <= 0 opens the gate once it is > 0
    pack = PersistentPack.build(scene, 64, 48, kinds)
    assert pack is not None
    with torch.no_grad():
        circle.radius.fill_(20.0)
    assert pack.still_valid(flats)
    leaves = [k.flat.detach().requires_grad_() for k in kinds]
    assert torch.allclose(render(scene, 64, 48, seed=5, threads=2, mode=mode, packed=pack.arrays(leaves)).detach(),
                          render(scene, 64, 48, seed=5, threads=2, mode=mode).detach(), atol=1e-6)


def test_loop_same_fit_either_way(tmp_path, monkeypatch):
    """Same seed, same fit, whether the loop packs once or on every iteration."""
    target = Target(torch.rand(48, 64, 4, generator=torch.Generator().manual_seed(1)), background=(1, 1, 1))
    target.image[..., 3] = 1
    results = []
    for persistent in (True, False):
        monkeypatch.setattr(loop, "PERSISTENT_PACK", persistent)
        scene = _scene(tmp_path)
        lr = dict(RATES)
        result = optimize(scene, target, Settings.defaults(iterations=12, threads=2, lr=lr, coarse=0.0))
        results.append((result.losses, scene.shapes[1].geometry.points.detach().clone()))
    (losses_a, points_a), (losses_b, points_b) = results
    assert losses_a == pytest.approx(losses_b, rel=1e-5)
    assert torch.allclose(points_a, points_b, atol=1e-4)


@pytest.mark.slow
def test_loop_same_seed_same_result(tmp_path):
    """The same seed gives the same fit: bit for bit on the same thread count, and to
    rounding on another (the core's gradients are summed per thread, DESIGN.md)."""
    target = Target(torch.rand(48, 64, 4, generator=torch.Generator().manual_seed(2)), background=(1, 1, 1))
    target.image[..., 3] = 1
    runs = []
    for threads in (2, 2, 1, 3):
        scene = _scene(tmp_path)
        result = optimize(scene, target, Settings.defaults(iterations=10, threads=threads, lr=dict(RATES), coarse=0.0))
        runs.append((result.losses, torch.cat([t.detach().reshape(-1) for ts in scene.parameters().values()
                                               for t in ts])))
    assert runs[0][0] == runs[1][0] and torch.equal(runs[0][1], runs[1][1])
    for losses, values in runs[2:]:
        assert losses == pytest.approx(runs[0][0], rel=1e-4)
        assert torch.allclose(values, runs[0][1], atol=1e-3)


def test_the_routes_of_a_dashed_stroke_mark_its_geometry(tmp_path):
    """The persistent pack declines dashes before it reads routes; the routes say so too:
    the dashes' points and widths are not affine in the outline's (they are cut where its
    arc lengths say), so the outline's tensors are marked, and its dash path gets no route."""
    from vecfit.renderer.pack import pack_scene
    from vecfit.renderer.routes import routes_of
    scene = _scene(tmp_path, MIXED.replace('stroke-linecap="round"', 'stroke-linecap="round" stroke-dasharray="9 4"'))
    path = scene.shapes[-1].geometry
    path.widths = torch.linspace(1.0, 6.0, len(path.points))
    routes = routes_of(scene, pack_scene(scene, 64, 48))
    assert {id(path.points), id(path.widths)} <= routes.nonlinear
    assert not any(r.tensor is path.points or r.tensor is path.widths for r in routes.routes)
    assert id(scene.shapes[1].geometry.points) not in routes.nonlinear  # (an undashed path's are routed)
