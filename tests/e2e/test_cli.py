"""The command line: outputs, sizes, exit codes and messages (no tracebacks)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from helpers import run, slow_unless

SQUARE = """<svg xmlns="http://www.w3.org/2000/svg" width="40" height="20" viewBox="0 0 40 20">
<rect x="10" y="5" width="20" height="10" fill="#ff0000"/></svg>"""


@pytest.fixture
def svg(tmp_path):
    p = tmp_path / "square.svg"
    p.write_text(SQUARE)
    return p


def test_render_writes_rgba_png(svg, tmp_path):
    out = tmp_path / "out.png"
    r = run("render", svg, "-o", out)
    assert r.exit_code == 0, r.output
    im = Image.open(out)
    assert im.mode == "RGBA" and im.size == (40, 20)
    umask = os.umask(0)
    os.umask(umask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask  # as a plain open would make it
    a = np.asarray(im)
    assert tuple(a[10, 20]) == (255, 0, 0, 255) and a[0, 0, 3] == 0


def test_width_keeps_aspect_and_background(svg, tmp_path):
    out = tmp_path / "out.png"
    assert run("render", svg, "-o", out, "--width", 101, "--background", "white").exit_code == 0
    im = Image.open(out)
    assert im.size == (101, 50)  # 50.5 rounds to the nearest (even) pixel
    assert tuple(np.asarray(im)[0, 0]) == (255, 255, 255, 255)


def test_out_dir_names_outputs_after_inputs(svg, tmp_path):
    second = tmp_path / "second.svg"
    second.write_text(SQUARE)
    r = run("render", svg, second, "--out-dir", tmp_path / "pngs", "--mode", "analytic")
    assert r.exit_code == 0, r.output
    assert sorted(os.listdir(tmp_path / "pngs")) == ["second.png", "square.png"]


def test_one_bad_input_fails_the_run_but_not_the_others(svg, tmp_path):
    bad = tmp_path / "bad.svg"
    bad.write_text("<svg><path d='M 0 0 L")
    r = run("render", svg, bad, tmp_path / "missing.svg", "--out-dir", tmp_path / "pngs")
    assert r.exit_code == 1
    assert "bad.svg" in r.output and "missing.svg" in r.output
    assert "Traceback" not in r.output
    assert os.listdir(tmp_path / "pngs") == ["square.png"]  # nothing half-written


@pytest.mark.parametrize("args", [
    ["render", "x.svg"],                                  # no output given
    ["render", "a.svg", "b.svg", "-o", "x.png"],          # -o with several inputs
    ["render", "a.svg", "-o", "x.png", "--samples", "0"],
    ["render", "a.svg", "-o", "x.png", "--mode", "fast"],
    ["render", "a.svg", "-o", "x.png", "--background", "mauve-ish"],
])
def test_bad_usage_exits_2(args):
    r = run(*args)
    assert r.exit_code == 2
    assert "Traceback" not in r.output


def test_info_lists_content(svg):
    r = run("info", svg)
    assert r.exit_code == 0, r.output
    assert "rect" in r.output.lower()


def test_info_on_non_svg_is_a_clear_error(tmp_path):
    p = tmp_path / "notes.svg"
    p.write_text("hello, not xml")
    r = run("info", p)
    assert r.exit_code == 1 and "notes.svg" in r.output and "Traceback" not in r.output


HEAVY = ("torch", "scipy", "skimage")  # over a second, 0.2 s and 0.1 s of start-up


def _modules_after(*args) -> tuple[str, set]:
    """Runs the command line in a fresh Python with ``args``; its output and which of the
    HEAVY modules were imported by the end."""
    code = ("import sys\nfrom vecfit.cli.commands import main\n"
            f"sys.argv = ['vecfit', *{list(map(str, args))!r}]\n"
            "try:\n    main()\nexcept SystemExit:\n    pass\n"
            f"print(','.join(m for m in {HEAVY!r} if m in sys.modules) or '-')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    lines = out.stdout.split()
    return out.stdout + out.stderr, set(lines[-1].split(",")) - {"-"} if lines else set(HEAVY)


@pytest.mark.parametrize("args", [["--version"], ["info", "--build"]])
def test_version_starts_without_torch(args):
    """`vecfit --version` and `info --build` say the core's build without importing torch
    (a second of start-up)."""
    output, imported = _modules_after(*args)
    assert "vecfit 0" in output and not imported, output


@pytest.mark.parametrize("name", slow_unless(["tiger.svg", "golden"], ["golden"]))
def test_info_runs_without_torch(name, tmp_path):
    """`vecfit info` reads the SVG into NumPy arrays (vecfit.scene.arrays): no torch."""
    if name == "golden":
        path = tmp_path / "effects.svg"  # a gradient, a group with opacity, a clip path, a use
        path.write_text(
            '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
            'width="40" height="30" viewBox="0 0 80 60"><defs><linearGradient id="g"><stop offset="0"/>'
            '<stop offset="1" stop-color="red"/></linearGradient><clipPath id="c"><circle cx="20" cy="20" '
            'r="15"/></clipPath></defs><g opacity="0.5" clip-path="url(#c)"><rect id="r" width="50" '
            'height="40" fill="url(#g)"/></g><use xlink:href="#r" x="30"/><ellipse cx="9" cy="9" rx="4" '
            'ry="3" stroke="blue"/></svg>')
    else:
        path = Path(__file__).resolve().parents[2] / "examples" / name
    output, imported = _modules_after("info", path)
    assert "shapes:" in output and "Traceback" not in output, output
    assert not imported, output


@pytest.mark.slow
def test_trace_without_refining_runs_without_torch(tmp_path):
    """`vecfit trace --no-refine` renders and writes the trace from NumPy arrays (no torch),
    and writes what the Python API writes for optimize.iterations 0."""
    yy, xx = np.mgrid[:64, :48]
    image = np.zeros((64, 48, 3), np.uint8)
    image[...] = (240, 230, 200)
    image[(yy - 30) ** 2 + (xx - 22) ** 2 < 15 ** 2] = (200, 30, 40)
    image[5:20, 30:44] = (20, 60, 200)
    png = tmp_path / "blobs.png"
    Image.fromarray(image).save(png)
    output, imported = _modules_after("trace", png, "--no-refine", "-o", tmp_path / "cli.svg")
    assert "Traceback" not in output and "0 iterations" in output, output
    assert not imported, output  # no torch, and none of SciPy (tracer/labels.py) or scikit-image
    import json

    import vecfit
    svg, report = vecfit.trace(image, settings={"optimize": {"iterations": 0}})
    assert svg == (tmp_path / "cli.svg").read_text()
    written = json.loads((tmp_path / "cli.report.json").read_text())
    assert written["optimized"] == report["optimized"] and report["optimized"]["psnr"] > 25


@pytest.mark.parametrize("table, refused", [('loss = "nope"', "loss must be one of"),
                                            ('[optimize.lr]\npoints = -1.0', "learning rate of points"),
                                            ('[optimize.lr]\nwiggle = 1.0', "unknown setting")])
def test_trace_without_refining_still_checks_the_loop_settings(tmp_path, table, refused):
    """The [optimize] table is checked (vecfit.fitting.settings) even where no loop will
    run, and checking it imports no torch: a bad file is refused as it is for refine."""
    Image.fromarray(np.full((24, 24, 3), 200, np.uint8)).save(tmp_path / "flat.png")
    config = tmp_path / "bad.toml"
    config.write_text(f"[optimize]\n{table}\n" if not table.startswith("[") else table + "\n")
    output, imported = _modules_after("trace", tmp_path / "flat.png", "--no-refine", "--config", config,
                                            "-o", tmp_path / "out.svg")
    assert refused in output and "Traceback" not in output, output
    assert not (tmp_path / "out.svg").exists()
    assert "torch" not in imported, output
