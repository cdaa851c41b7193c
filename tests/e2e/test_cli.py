"""The command line: outputs, sizes, exit codes and messages (no tracebacks)."""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from helpers import run

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


def test_version_starts_without_torch():
    """`vecfit --version` says the core's build without importing torch (a second of start-up)."""
    code = ("import sys\nfrom vecfit.cli.commands import main\nsys.argv = ['vecfit', '--version']\n"
            "try:\n    main()\nexcept SystemExit:\n    pass\nprint('torch' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.split()[-1] == "False" and out.stdout.startswith("vecfit "), out.stdout + out.stderr
