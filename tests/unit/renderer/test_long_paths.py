"""Long paths (issue 28): the tile lists follow the pixels a segment reaches (a curve of a
fill is listed only in the tiles its sub-pieces' boxes reach; a stroke wide against a tile
lists no items in the tiles that lie inside one of its pieces), and the analytical
distance measures a curve only near its sub-pieces; the analytical passes compute a tile's
long fill entries segment by segment (scene/field.h). None of it may change an image: each
scene here is rendered through the tiles and brute force (every item of every draw at
every sample), in both modes, and the analytical mode with every entry a tile at a time
and none. Timings are in benchmarks/long_paths.py."""
from __future__ import annotations

import random

import numpy as np
import pytest
import torch

import vecfit
from vecfit import _core
from helpers import brute_force, quiet_load, slow_unless

NS = 'xmlns="http://www.w3.org/2000/svg"'


def walk(n: int, size: float, step: float, kinds: str, seed: int = 0) -> str:
    """Path data: n segments (L, Q, C in turn from `kinds`) of a random walk."""
    r = random.Random(seed)
    x = y = size / 2
    out = [f"M {x:.2f} {y:.2f}"]
    for i in range(n):
        k = kinds[i % len(kinds)]
        pts = []
        for _ in range({"L": 1, "Q": 2, "C": 3}[k]):
            x = min(max(x + r.uniform(-step, step), 0), size)
            y = min(max(y + r.uniform(-step, step), 0), size)
            pts.append(f"{x:.2f} {y:.2f}")
        out.append(k + " " + " ".join(pts))
    return " ".join(out)


GRADIENT = ('<defs><linearGradient id="g"><stop offset="0" stop-color="red"/><stop offset="1" stop-color="blue"/>'
            '</linearGradient></defs>')

SCENES = {
    # curves across the whole canvas: each was listed in every tile of its box
    "cubics-across": f'<path d="{walk(300, 64, 64, "C", 1)} Z" fill="url(#g)" fill-rule="evenodd"/>',
    "walk-mixed": f'<path d="{walk(1500, 64, 6, "LQC", 2)} Z" fill="#3a6"/>',
    # strokes 10^7 px wide (every tile inside the first line's rectangle) and wide against
    # a tile: round joins (disks), miter joins, butt and square caps, curves among lines
    "stroke-1e7": f'<path d="{walk(600, 64, 10, "LQC", 3)}" fill="url(#g)" stroke="green" stroke-width="1e7"/>',
    "stroke-wide-round": f'<path d="{walk(40, 64, 20, "LC", 4)}" fill="none" stroke="#800" stroke-width="30" '
                         'stroke-linejoin="round" stroke-linecap="round" opacity="0.7"/>',
    "stroke-wide-miter": f'<path d="{walk(30, 64, 25, "LLQ", 5)}" fill="none" stroke="#008" stroke-width="40" '
                         'stroke-linejoin="miter" stroke-linecap="square"/>'
                         f'<path d="M 5 60 L 60 5" stroke="#080" stroke-width="26" stroke-linecap="butt"/>',
    "stroke-wide-transformed": f'<g transform="matrix(1.5 0.4 -0.2 0.7 3 2)"><path d="{walk(30, 40, 15, "LC", 6)}" '
                               'fill="none" stroke="#088" stroke-width="33" stroke-linejoin="bevel"/></g>',
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SCENES))
@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_tiles_match_brute_force(tmp_path, name, mode):
    svg = tmp_path / f"{name}.svg"
    svg.write_text(f'<svg {NS} width="64" height="64">{GRADIENT}{SCENES[name]}</svg>')
    scene = quiet_load(svg)
    for size in (40, 64):
        fast = vecfit.render(scene, size, size, samples=2, mode=mode, threads=2)
        with brute_force():
            brute = vecfit.render(scene, size, size, samples=2, mode=mode)
        assert fast[..., 3].sum() > 0
        assert torch.allclose(fast, brute, atol=1e-6, rtol=0), float((fast - brute).abs().max())


@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_wide_stroke_gradients_unchanged_inside(tmp_path, mode):
    """A tile inside a wide stroke lists none of its items: the stroke's gradients there
    are 0 as they were (inside by more than the kernel, or a boundary piece covered by
    another piece), and they stay finite and equal across thread counts."""
    svg = tmp_path / "s.svg"
    svg.write_text(f'<svg {NS} width="64" height="64"><path d="M 4 30 L 60 34 L 30 60" fill="none" '
                   'stroke="#800" stroke-width="40" stroke-linejoin="round"/></svg>')
    grads = []
    for threads in (1, 2):
        scene = quiet_load(svg)
        pts = scene.parameters()["points"]
        for t in pts:
            t.requires_grad_(True)
        image = vecfit.render(scene, 64, 64, samples=2, mode=mode, threads=threads, seed=3)
        (image * torch.linspace(0, 1, 64)[:, None, None]).sum().backward()
        grads.append(torch.cat([t.grad.reshape(-1) for t in pts]))
    assert torch.isfinite(grads[0]).all() and grads[0].abs().sum() > 0
    assert torch.allclose(grads[0], grads[1], rtol=1e-5, atol=1e-5)


# Strokes with every kind of end piece, for the stroke entries' bounds (scene/field.h).
BOUND_SCENES = {
    "joins-caps": f'<path d="{walk(60, 64, 40, "LQC", 11)}" fill="none" stroke="#800" stroke-width="1.5" '
                  'stroke-opacity="0.5" stroke-linejoin="miter" stroke-miterlimit="10" stroke-linecap="square"/>'
                  f'<path d="{walk(60, 64, 40, "LC", 12)}" fill="none" stroke="#080" stroke-width="1" '
                  'stroke-opacity="0.5" stroke-linejoin="bevel" stroke-linecap="butt"/>'
                  f'<path d="{walk(60, 64, 40, "QC", 13)}" fill="none" stroke="#008" stroke-width="2.5" '
                  'stroke-opacity="0.5" stroke-linejoin="round" stroke-linecap="round"/>'
                  f'<g transform="matrix(1.5 0.4 -0.2 0.7 3 2)"><path d="{walk(40, 40, 25, "LC", 6)} Z" fill="none" '
                  'stroke="#088" stroke-width="2" stroke-opacity="0.5"/></g>',
    "wide": f'<path d="{walk(30, 64, 25, "LLQC", 5)}" fill="none" stroke="#008" stroke-width="9" '
            'stroke-linejoin="miter" stroke-linecap="square"/>'
            f'<g transform="scale(0.3)"><path d="{walk(30, 200, 80, "QC", 8)}" fill="none" stroke="#800" '
            'stroke-width="12" stroke-linecap="round"/></g>',
}


def packed_arrays(scene, size: int = 64) -> dict:
    from vecfit.renderer.raster import FLOAT_INPUTS, packed_for_core

    structure, floats = packed_for_core(scene, size, size)
    return dict(structure, **{name: t.detach().numpy() for name, t in zip(FLOAT_INPUTS, floats)})


def point_widths_scene():
    from vecfit.scene import Path, Scene, Shape, Solid

    r = random.Random(9)
    pts = torch.tensor([[r.uniform(0, 64), r.uniform(0, 64)] for _ in range(31)])
    path = Path(points=pts, degrees=np.array([3] * 10), subpaths=[(0, 10, False)],
                widths=torch.tensor([r.uniform(0.5, 6) for _ in range(31)]))
    return Scene(width=64, height=64, shapes=[Shape(geometry=path, stroke=Solid(torch.tensor([0.1, 0.2, 0.6, 1.0])),
                                                    linejoin="miter", linecap="square")])


@pytest.mark.parametrize("name", [*BOUND_SCENES, "point-widths"])
def test_stroke_bounds_lie_below_the_distances(tmp_path, name):
    """A stroke item's bound (what the analytical passes set items aside by) is at most its
    signed distance, at points all over and around the canvas, and where the distance is
    the sweep's along a straight side, within rounding of it: the sweep, butt ends, caps
    and joins of every kind, a non-uniform transform, per-point widths."""
    if name == "point-widths":
        scene = point_widths_scene()
    else:
        svg = tmp_path / f"{name}.svg"
        svg.write_text(f'<svg {NS} width="64" height="64">{BOUND_SCENES[name]}</svg>')
        scene = quiet_load(svg)
    grid = torch.arange(-3.0, 67.0, 1.37, dtype=torch.float64)
    points = torch.stack(torch.meshgrid(grid, grid, indexing="xy"), -1).reshape(-1, 2).numpy()
    most, mean, pairs = _core.stroke_bound_gaps(packed_arrays(scene), points)
    assert pairs > 20_000
    assert -1e-3 < most <= 0, most
    assert mean < 0


FIELD_SCENES = {
    **{k: SCENES[k] for k in ("cubics-across", "walk-mixed")},
    "stroke-1e7": SCENES["stroke-1e7"].replace('stroke="green"', 'stroke="green" stroke-opacity="0.5"'),
    # a rect's corners and edges on pixel centres (samples on edges and vertices: the args'
    # second segment), a self-crossing star (nonzero), curves meeting at their ends
    "edges": '<path d="M 8.5 8.5 H 40.5 V 40.5 H 8.5 Z M 20 4 L 36 60 L 4 24 L 60 24 L 12 60 Z" fill="#a50"/>'
             f'<path d="{walk(60, 64, 16, "QC", 7)} Z" fill="#05a" fill-opacity="0.6"/>',
    # thin strokes crowding every tile (issue 41's kind, the stroke entries' bounds and
    # cells): miter (long ones), bevel and round joins, square, butt and round caps, a
    # stroke under a non-uniform transform, all translucent so that each is measured
    "strokes-crowded": BOUND_SCENES["joins-caps"],
}


@pytest.mark.parametrize("name", list(FIELD_SCENES))
@pytest.mark.parametrize("samples,filt", slow_unless([(1, "box"), (2, "box"), (3, "tent")], [(1, "box")]))
def test_fields_match_per_sample(tmp_path, name, samples, filt):
    """The analytical passes with every fill and stroke entry computed a tile at a time
    give the per-sample images and gradients, bit for bit."""
    svg = tmp_path / f"{name}.svg"
    svg.write_text(f'<svg {NS} width="64" height="64">{GRADIENT}{FIELD_SCENES[name]}</svg>')
    results = []
    old = _core.field_min_items(0)
    try:
        for threshold in (0, 1 << 30):
            _core.field_min_items(threshold)
            scene = quiet_load(svg)
            pts = scene.parameters()["points"]
            for t in pts:
                t.requires_grad_(True)
            image = vecfit.render(scene, 48, 48, samples=samples, mode="analytic", filter=filt,
                                  filter_radius=1.0, threads=2)
            weights = torch.rand(image.shape, generator=torch.Generator().manual_seed(5))
            (image * weights).sum().backward()
            results.append((image.detach(), torch.cat([t.grad.reshape(-1) for t in pts])))
    finally:
        _core.field_min_items(old)
    (fi, fg), (si, sg) = results
    assert fi[..., 3].sum() > 0 and sg.abs().sum() > 0
    assert torch.equal(fi, si), float((fi - si).abs().max())
    assert torch.equal(fg, sg), float((fg - sg).abs().max())


# README's "Limits and guarantees" states what the core holds for a render by segment:
# these bounds are the figures it names (bytes per segment).
PREPARED_PER_FILLED_SEGMENT = 600
PREPARED_PER_STROKED_SEGMENT = 1_400
TILE_LISTS_PER_SHORT_SEGMENT = 64


def footprint_per_segment(tmp_path, body: str, segments: int, mode: str = "mc") -> dict:
    from vecfit.renderer.options import RenderOptions
    from vecfit.renderer.raster import FLOAT_INPUTS, packed_for_core

    svg = tmp_path / "scene.svg"
    svg.write_text(f'<svg {NS} width="64" height="64">{GRADIENT}{body}</svg>')
    structure, floats = packed_for_core(quiet_load(svg), 64, 64)
    arrays = dict(structure, **{name: t.detach().numpy() for name, t in zip(FLOAT_INPUTS, floats)})
    parts = _core.footprint(arrays, RenderOptions(64, 64, mode=mode).core())
    return {part: size / segments for part, size in parts.items()}


@pytest.mark.parametrize("kinds", ["L", "Q", "C", "LQC"])
def test_memory_per_segment_within_the_stated_limits(tmp_path, kinds):
    n = 3000
    filled = footprint_per_segment(tmp_path, f'<path d="{walk(n, 64, 2, kinds)} Z" fill="#3a6"/>', n)
    assert filled["fill_items"] <= PREPARED_PER_FILLED_SEGMENT, filled
    assert filled["tile_items"] <= TILE_LISTS_PER_SHORT_SEGMENT, filled
    for mode in ("mc", "analytic"):
        stroked = footprint_per_segment(
            tmp_path, f'<path d="{walk(n, 64, 6, kinds)}" fill="url(#g)" stroke="green" stroke-width="1e7"/>',
            n, mode)
        assert stroked["stroke_items"] + stroked["segments"] <= PREPARED_PER_STROKED_SEGMENT, stroked
        assert stroked["fill_items"] <= PREPARED_PER_FILLED_SEGMENT, stroked
