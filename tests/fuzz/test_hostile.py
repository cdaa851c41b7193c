"""Hostile inputs the fuzzer (tests/fuzz/fuzzing.py) found, kept as fixed inputs, and the
resource limits (vecfit/limits.py): each refusal is one line with the limit in it.

The cases run in the fuzzer's worker process, so that a crash or a hang fails a test
instead of ending the run. About 50 s in all, most of it the 10^5-segment renders and the
second campaign's cases (issue 28: wide short targets, scenes that barely touch the
target, long paths in both modes; the pydiffvg scripts are in test_pydiffvg_scripts.py)."""
from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
import torch

import vecfit
from fuzzing import NS, Case, Runner, run_case, verdict
from helpers import quiet_load, run
from vecfit import limits

HOSTILE = sorted((Path(__file__).parent / "hostile").glob("*.svg"))


@pytest.fixture(scope="module")
def runner():
    r = Runner()
    yield r
    r.close()


def check(runner, command_args, files, outputs=(), timeout=30.0):
    """Runs the command line on the files and returns the outcome; fails on a broken rule."""
    case = Case(0, "fixed", command_args[0], list(command_args), dict(files), timeout, list(outputs))
    problem, outcome = run_case(runner, case)
    assert problem is None, f"{command_args}: {problem}\n{outcome}"
    return outcome


@pytest.mark.slow
@pytest.mark.parametrize("svg", HOSTILE, ids=[p.stem for p in HOSTILE])
def test_fixed_inputs_end_cleanly(runner, svg):
    files = {"in.svg": svg.read_bytes()}
    for mode in ("mc", "analytic"):
        check(runner, ["render", "in.svg", "-o", "out.png", "--width", "64", "--mode", mode], files, ["out.png"])
    check(runner, ["render", "in.svg", "-o", "out.png"], files, ["out.png"])
    check(runner, ["info", "in.svg"], files)


def test_nested_scales_render_and_differentiate(tmp_path):
    """50 nested scale(2): coordinates of 10^15 px (a segfault in the tile binning)."""
    scene = quiet_load(Path(__file__).parent / "hostile" / "nested-scale-segfault.svg")
    for mode in ("mc", "analytic"):
        for t in scene.parameters()["points"]:
            t.requires_grad_(True)
        image = vecfit.render(scene, 64, 64, mode=mode, samples=1)
        assert torch.isfinite(image).all()
        image.sum().backward()
        assert all(torch.isfinite(t.grad).all() for t in scene.parameters()["points"])


@pytest.mark.parametrize("name, solid, skipped", [
    ("dasharray-negative", ["neg", "negsum", "minuszero"], []),
    ("dasharray-zeros", ["zeros", "zero-one"], ["zero-one"]),
    ("dasharray-tiny-on-long-path", ["long", "rect"], ["long", "rect"]),
    ("dasharray-nan-inf", ["nan", "inf", "huge", "big"], []),
    ("dasharray-percent", ["poly"], ["poly"]),
])
def test_hostile_dashes(name, solid, skipped):
    """Dash patterns that draw solid (negative, zero sum, NaN or infinite text: SVG's rule)
    or that would make millions of dashes (1e-9 on a long path, tiny percentages: the
    limit, with a warning naming the element): read, rendered and differentiated quickly."""
    start = time.perf_counter()
    scene = quiet_load(Path(__file__).parent / "hostile" / f"{name}.svg")
    for shape in scene.shapes:
        assert (shape.dash_array is None) == (shape.source in solid), shape.source
    assert scene.skipped.get("stroke-dasharray", []) == skipped
    for mode in ("mc", "analytic"):
        for t in scene.parameters()["points"]:
            t.requires_grad_(True)
            t.grad = None
        image = vecfit.render(scene, 64, None, mode=mode, samples=1)
        assert torch.isfinite(image).all()
        image.sum().backward()
        assert all(t.grad is None or torch.isfinite(t.grad).all() for t in scene.parameters()["points"])
    assert time.perf_counter() - start < 20


def test_huge_coordinates_render_quickly(tmp_path):
    """10^28 px coordinates (as viewBox="0 0 3 1e-30" made at 64 px wide, which grew past
    6 GB before canvases that thin were refused): the boundary samples of the backward
    pass are capped by the canvas, not by 10^28 px of length."""
    body = ('<path d="M 0 0 C 1 2 3 4 2 1" stroke="green" stroke-width="0.5"/>'
            '<circle cx="1" cy="1" r="1" stroke="blue" fill="red"/>')
    svg = tmp_path / "huge.svg"
    svg.write_text(f'<svg {NS} viewBox="0 0 3 1">' + '<g transform="scale(1 1e7)">' * 4 + body
                   + "</g>" * 4 + "</svg>")
    scene = quiet_load(svg)
    for t in scene.parameters()["points"]:
        t.requires_grad_(True)
    start = time.perf_counter()
    image = vecfit.render(scene, 64, None, samples=2)
    image.sum().backward()  # boundary samples: capped by the canvas, not 10^30 px of length
    assert image.shape == (21, 64, 4) and time.perf_counter() - start < 20


@pytest.mark.parametrize("root, reason", [
    ('viewBox="0 0 1e308 1e308"', "the canvas is 1e+308 x 1e+308 px"),
    ('width="10" height="1e308"', "the canvas is 10 x 1e+308 px"),
    ('viewBox="0 0 1e300 1e-300" height="50%"', "between 0.001 and 1e+07 px"),
    ('viewBox="0 0 1e400 1"', "not finite"),
    ('width="nan" viewBox="0 0 1e300 1e300"', "1e+07"),
])
def test_canvas_limits(tmp_path, root, reason):
    svg = tmp_path / "c.svg"
    svg.write_text(f'<svg {NS} {root}><rect width="5" height="5"/></svg>')
    for args in (["render", svg, "-o", tmp_path / "o.png", "--width", "64"], ["info", svg]):
        r = run(*args)
        assert r.exit_code == 1 and reason in r.stderr and "Traceback" not in r.output
    assert not (tmp_path / "o.png").exists()


def test_render_size_limit_names_it(tmp_path):
    svg = tmp_path / "big.svg"
    svg.write_text(f'<svg {NS} width="1e7" height="1e7"><rect width="5" height="5"/></svg>')
    r = run("render", svg, "-o", tmp_path / "o.png")
    assert r.exit_code == 1 and "10000000 x 10000000 pixels is too large" in r.stderr
    assert f"at most {limits.MAX_PIXELS // 1_000_000} million pixels" in r.stderr


@pytest.mark.slow
def test_segment_limit(runner):
    """A 10^6-point path (analytical mode ran past 40 s) and a 6.9 MB d attribute."""
    points = " ".join(f"{i % 64} {(i * 7) % 64}" for i in range(1_000_000))
    big = f'<svg {NS} width="64" height="64"><path d="M 0 0 L {points} Z"/></svg>'.encode()
    start = time.perf_counter()
    out = check(runner, ["render", "in.svg", "-o", "out.png", "--mode", "analytic"], {"in.svg": big}, ["out.png"])
    assert out["exit_code"] == 1 and f"more than {limits.MAX_SEGMENTS} path segments" in out["stderr"]
    many = f'<svg {NS} width="64" height="64">' + "".join(
        f'<path d="M 0 0 L {points[:20 * 10_000]}"/>' for _ in range(30)) + "</svg>"
    out = check(runner, ["info", "in.svg"], {"in.svg": many.encode()})
    assert out["exit_code"] == 1 and "path segments" in out["stderr"]
    assert time.perf_counter() - start < 25


@pytest.mark.slow
def test_element_limit_covers_entities(runner):
    """Entities expanding to 10^5 rects took 25 s: the <use> cap did not count them."""
    ents = '<!ENTITY a "<rect width=\'1\' height=\'1\'/>">' + "".join(
        f'<!ENTITY {c} "{f"&{p};" * 10}">' for p, c in zip("abcde", "bcdef"))
    svg = f'<?xml version="1.0"?><!DOCTYPE svg [{ents}]><svg {NS} width="64" height="64">&f;&f;</svg>'
    start = time.perf_counter()
    out = check(runner, ["render", "in.svg", "-o", "out.png"], {"in.svg": svg.encode()}, ["out.png"])
    assert out["exit_code"] == 1 and f"more than {limits.MAX_ELEMENTS} elements" in out["stderr"]
    assert time.perf_counter() - start < 15


def test_nesting_limit(tmp_path):
    svg = tmp_path / "deep.svg"
    svg.write_text(f'<svg {NS}>' + "<g>" * 300 + '<rect width="1" height="1"/>' + "</g>" * 300 + "</svg>")
    r = run("info", svg)
    assert r.exit_code == 1 and "at most 200 levels" in r.stderr
    svg.write_text(f'<svg {NS}>' + "<g>" * 150 + '<rect width="1" height="1"/>' + "</g>" * 150 + "</svg>")
    assert run("info", svg).exit_code == 0


def test_image_limit(tmp_path):
    """A PNG header declaring 100,000 x 100,000 pixels is refused before decoding."""
    from fuzzing import _png_chunk
    import struct
    import zlib
    png = tmp_path / "huge.png"
    png.write_bytes(b"\x89PNG\r\n\x1a\n" + _png_chunk(b"IHDR", struct.pack(">IIBBBBB", 100_000, 100_000, 8, 2, 0, 0, 0))
                    + _png_chunk(b"IDAT", zlib.compress(b"\0" * 100)) + _png_chunk(b"IEND", b""))
    r = run("trace", png, "-o", tmp_path / "o.svg", "-q")
    assert r.exit_code == 1 and "100 million pixels (the limit)" in r.stderr
    assert not list(tmp_path.glob("o*"))


def test_huge_arcs_load(tmp_path):
    scene = quiet_load(Path(__file__).parent / "hostile" / "arc-huge-numbers.svg")
    pts = torch.cat([t.detach().reshape(-1) for t in scene.parameters()["points"]])
    assert torch.isfinite(pts).all() and math.isfinite(float(np.abs(pts.numpy()).max()))


def test_root_in_another_namespace_says_so(tmp_path):
    """The fuzzer's mutation of xmlns gave "the root element is <svg>, not <svg>"."""
    svg = tmp_path / "ns.svg"
    svg.write_text('<svg xmlns="999http://www.w3.org/2000/svg" width="9" height="9"/>')
    r = run("info", svg)
    assert r.exit_code == 1 and "namespace '999http://www.w3.org/2000/svg', not SVG's" in r.stderr


# ----------------------------------------------- issue 28: the second fuzzing campaign

def _png(array) -> bytes:
    import io
    from PIL import Image
    buf = io.BytesIO()
    Image.fromarray(array).save(buf, format="PNG")
    return buf.getvalue()


def _noise_png(width: int, height: int, seed: int = 0) -> bytes:
    return _png((np.random.default_rng(seed).random((height, width, 3)) * 255).astype(np.uint8))


WIDE_SVG = (f'<svg {NS} width="700" height="11"><rect width="700" height="11" fill="#ddd"/>'
            '<circle cx="100" cy="5" r="4" fill="red"/><path d="M 300 1 L 400 10 L 350 2 Z" fill="blue"/></svg>')
FIT_OUTPUTS = ["out.svg", "out.report.json", "out.compare.png"]
QUICK = ["--iterations", "2", "-q", "--threads", "1"]


@pytest.mark.slow
@pytest.mark.parametrize("args", [
    ["paint", "wide.png", "--paths", "4"],
    ["refine", "wide.png", "wide.svg"],
    ["trace", "wide.png", "--paths", "4"],
    ["edit", "wide.svg", "wide.png", "--max-size", "512"],
    ["retarget", "wide.svg", "--width", "600"],
], ids=lambda a: a[0])
def test_wide_short_images_fit(runner, args):
    """A 700 x 11 target: paint's 512-px working size made it 8 px high, under SSIM's
    11 x 11 window (a traceback); retarget's 512-px working image likewise."""
    files = {"wide.png": _noise_png(700, 11), "wide.svg": WIDE_SVG.encode()}
    out = check(runner, [*args, "-o", "out.svg", *QUICK], files, FIT_OUTPUTS)
    assert out["exit_code"] == 0, out["stderr"]


@pytest.mark.slow
def test_wide_short_images_batch(runner):
    case = Case(0, "fixed", "batch", ["batch", "in", "-o", "out", "--mode", "paint", "--config", "it.toml", "-q"],
                {}, 60.0, [])
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "in").mkdir()
        (folder / "in" / "wide.png").write_bytes(_noise_png(700, 11))
        (folder / "it.toml").write_text("[optimize]\niterations = 2\n")
        outcome = runner.run(case, folder)
        assert verdict(case, folder, outcome) is None and outcome["exit_code"] == 0, outcome
        assert (folder / "out" / "wide.svg").exists() and (folder / "out" / "wide.report.json").exists()


def _circles(n: int, size: float, radius: float, offset: float = 0.0, seed: int = 0) -> str:
    rng = np.random.default_rng(seed)
    body = "".join(f'<circle cx="{offset + x:.2f}" cy="{offset + y:.2f}" r="{r:.2f}" fill="#{c:06x}"/>'
                   for x, y, r, c in zip(rng.uniform(0, size, n), rng.uniform(0, size, n),
                                         rng.uniform(0, radius, n), rng.integers(0, 1 << 24, n)))
    return f'<svg {NS} width="{size:g}" height="{size:g}">{body}</svg>'


BARELY = [
    # 300 circles of radius 0-5 on 200 px against a 64 px target: radii cross 0 (draws
    # come and go), so the fit's last, no-grad evaluation packed the scene anew and the
    # pack's gradient self-check ran without a graph ("does not require grad")
    ("tiny-circles", _circles(300, 200, 5)),
    # every shape below a pixel at the target's size
    ("below-a-pixel", f'<svg {NS} width="20000" height="20000"><rect x="100" y="100" width="20" height="20" '
                      'fill="red"/><circle cx="5000" cy="5000" r="30" fill="blue"/><path d="M 9000 9000 '
                      'C 9010 9000 9010 9010 9000 9010 Z" fill="green" stroke="black" stroke-width="3"/></svg>'),
    # every shape off the canvas
    ("off-canvas", f'<svg {NS} width="200" height="200"><rect x="300" y="10" width="20" height="20" fill="red"/>'
                   '<circle cx="-50" cy="50" r="30" fill="blue"/><path d="M 10 -90 C 50 -90 50 -50 10 -50 Z" '
                   'fill="green" stroke="black" stroke-width="3"/></svg>'),
    # radii 0 to 0.05 px: few of the parameters reach a pixel, none of them much
    ("dust", _circles(400, 64, 0.05, seed=1)),
]


@pytest.mark.slow
@pytest.mark.parametrize("name, svg", BARELY, ids=[n for n, _ in BARELY])
@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_scenes_that_barely_touch_the_target(runner, name, svg, mode):
    files = {"target.png": _noise_png(64, 64, seed=2), "in.svg": svg.encode()}
    out = check(runner, ["refine", "target.png", "in.svg", "-o", "out.svg", "--iterations", "3", "--mode", mode,
                         "-q", "--threads", "1", "--samples", "1"], files, FIT_OUTPUTS)
    assert out["exit_code"] == 0, out["stderr"]


def _long_path(n: int, kinds: str, step: float, seed: int = 0) -> str:
    rng = np.random.default_rng(seed)
    counts = {"L": 1, "Q": 2, "C": 3}
    xy = np.array([100.0, 100.0])
    out = ["M 100 100"]
    for i in range(n):
        k = kinds[i % len(kinds)]
        pts = []
        for _ in range(counts[k]):
            xy = np.clip(xy + rng.uniform(-step, step, 2), 0, 200)
            pts.append(f"{xy[0]:.1f} {xy[1]:.1f}")
        out.append(k + " ".join(pts))
    return " ".join(out) + " Z"


@pytest.mark.parametrize("name, body", [
    # 30,000 cubics: the analytical mode measured each curve at every pixel of its box
    ("cubics", lambda: f'<path d="{_long_path(30_000, "C", 60.0)}" fill="#3a6"/>'),
    # mixed segments, a gradient fill and a stroke 10^7 wide: every stroke item was listed
    # in every tile and measured at every pixel (past 20 s and 2 GB)
    ("mixed-wide-stroke", lambda: '<defs><linearGradient id="g"><stop offset="0" stop-color="red"/><stop offset="1" '
     f'stop-color="blue"/></linearGradient></defs><path d="{_long_path(30_000, "LQC", 4.0, 1)}" fill="url(#g)" '
     'stroke="green" stroke-width="1e7"/>'),
], ids=["cubics", "mixed-wide-stroke"])
@pytest.mark.slow
@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_long_paths_render_in_both_modes(runner, name, body, mode):
    svg = f'<svg {NS} width="200" height="200">{body()}</svg>'.encode()
    out = check(runner, ["render", "in.svg", "-o", "out.png", "--width", "64", "--mode", mode, "--threads", "1"],
                {"in.svg": svg}, ["out.png"], timeout=20)
    assert out["exit_code"] == 0, out["stderr"]
