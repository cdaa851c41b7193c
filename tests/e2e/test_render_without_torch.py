"""`vecfit render` without torch (issue 41): importing torch took 1.2 s of a 3.4 s command
whose render took 0.06 s. The command reads each SVG into NumPy arrays and renders it
with render_numpy where that draws it as vecfit.render does
(vecfit.renderer.forward.renders_without_torch); other files (clip paths, masks,
filters, dashes, gradients, rotations) import torch and render as before."""
from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import vecfit
from vecfit.io.colors import parse_background
from vecfit.io.png import save_png
from vecfit.renderer.forward import FLOAT_INPUTS, output_size, packed_for_core, render_numpy, renders_without_torch
from vecfit.scene.arrays import numpy_arrays, to_numpy

from helpers import slow_unless

ROOT = Path(__file__).resolve().parents[2]
TIGER = ROOT / "examples" / "tiger.svg"
GOLDEN = sorted((ROOT / "tests" / "oracles" / "golden").glob("*.svg"))
NS = 'xmlns="http://www.w3.org/2000/svg"'
GRADIENT = (f'<svg {NS} width="40" height="30"><linearGradient id="g"><stop offset="0" stop-color="red"/>'
            '<stop offset="1" stop-color="blue"/></linearGradient><rect width="30" height="20" fill="url(#g)"/>'
            '<text x="1" y="9">skipped</text></svg>')
PLAIN = f'<svg {NS} width="40" height="30"><circle cx="20" cy="15" r="9" fill="#3a6" stroke="#000"/></svg>'


def _render_command(*args, module: str = "torch") -> tuple[str, bool]:
    """`vecfit render ARGS` in a fresh Python: its output, and whether it imported
    ``module``."""
    code = ("import sys\nfrom vecfit.cli.commands import main\n"
            f"sys.argv = ['vecfit', 'render', *{list(map(str, args))!r}]\n"
            "try:\n    main()\nexcept SystemExit:\n    pass\n"
            f"print({module!r} in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    lines = out.stdout.split()
    return out.stdout + out.stderr, (lines[-1] == "True") if lines else True


@pytest.mark.parametrize("module", slow_unless(["cv2", "PIL"], ["PIL"]))
def test_a_plain_render_imports_no_image_library(tmp_path, module):
    """OpenCV's import is a tenth of a second, a fifth of the command, and Pillow's image
    plugins (which its PNG writer loads) another: the reader and the PNG writer have no
    use for either (issue 41: `vecfit render` within 3x resvg's). Tiger writes its colours
    in hex; a colour keyword would load Pillow's table of them."""
    output, loaded = _render_command(TIGER, "-o", tmp_path / "tiger.png", module=module)
    assert "[1/1]" in output and not loaded, output


def test_a_plain_render_imports_nothing_it_does_not_use(tmp_path):
    """Tiger's transform list (a scale and a translation) is multiplied by the reader, the
    PNG's temporary file made with os.open, the dash lengths' quadrature rule made when
    dashes are: svgelements, tempfile (with shutil and random) and numpy.polynomial were a
    fifth of the command's imports after NumPy's and click's."""
    modules = ["svgelements", "tempfile", "shutil", "random", "numpy.polynomial"]
    code = ("import sys\nfrom vecfit.cli.commands import main\n"
            f"sys.argv = ['vecfit', 'render', {str(TIGER)!r}, '-o', {str(tmp_path / 't.png')!r}]\n"
            "try:\n    main()\nexcept SystemExit:\n    pass\n"
            f"print(','.join(m for m in {modules!r} if m in sys.modules) or '-')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert "[1/1]" in out.stderr and out.stdout.split()[-1:] == ["-"], out.stdout + out.stderr


def _with_torch(svg, png, **options) -> bytes:
    """The PNG that vecfit.render makes of ``svg`` (a Scene of tensors), as the command
    made it before."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(svg)
    save_png(vecfit.render(scene, **options), png)
    return png.read_bytes()


@pytest.mark.slow
@pytest.mark.parametrize("args, options", [
    ([], {}),
    (["--mode", "analytic", "--width", "200"], dict(mode="analytic", width=200)),
    (["--samples", "3", "--filter", "gaussian", "--filter-radius", "1.5", "--height", "120"],
     dict(samples=3, filter="gaussian", filter_radius=1.5, height=120)),
    (["--background", "#336699", "--seed", "5", "--threads", "1"],
     dict(background=parse_background("#336699"), seed=5, threads=1)),
], ids=["defaults", "analytic", "gaussian", "background"])
def test_tiger_renders_without_torch_as_with_it(tmp_path, args, options):
    out = tmp_path / "tiger.png"
    output, torch_loaded = _render_command(TIGER, "-o", out, *args)
    assert "Traceback" not in output and "[1/1]" in output, output
    assert not torch_loaded, output
    assert out.read_bytes() == _with_torch(TIGER, tmp_path / "expected.png", **options)


@pytest.mark.slow
def test_files_that_need_torch_render_as_before(tmp_path):
    """--out-dir with a file that needs torch (a gradient) among others: each PNG is
    vecfit.render's, and the reader's warning (a <text>) is said once."""
    (tmp_path / "gradient.svg").write_text(GRADIENT)
    (tmp_path / "plain.svg").write_text(PLAIN)
    inputs = [TIGER, tmp_path / "plain.svg", tmp_path / "gradient.svg"]
    output, torch_loaded = _render_command(*inputs, "--out-dir", tmp_path / "out", "--width", "64")
    assert "[3/3]" in output and "Traceback" not in output, output
    assert torch_loaded and output.count("warning:") == 1 and "text" in output, output
    for svg in inputs:
        assert (tmp_path / "out" / f"{svg.stem}.png").read_bytes() == _with_torch(
            svg, tmp_path / "expected.png", width=64), svg.name


@pytest.mark.parametrize("svg", [TIGER, *GOLDEN], ids=lambda p: p.stem)
def test_render_numpy_packs_what_vecfit_render_packs(svg):
    """Where renders_without_torch says so, the NumPy path packs torch's float32 values
    (then the core draws the same image), but for stroke widths and stroke metrics, scaled
    by a square root that torch (MKL) takes off by its last bit for 1 in 5 values (the
    products then differ by up to 2 units in the last place); the
    goldens with gradients, rotations or dashes are the files it sends to torch."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with numpy_arrays():
            plain = vecfit.load_svg(svg)
        tensors = vecfit.load_svg(svg)
    if not renders_without_torch(plain):
        pytest.skip("renders with torch")
    for width in (64, 200, None):
        size = output_size(plain, width, None)
        (structure, floats), (expected_structure, expected) = packed_for_core(plain, *size), packed_for_core(tensors, *size)
        for name in structure:
            assert np.array_equal(structure[name], to_numpy(expected_structure[name])), name
        for name, got, want in zip(FLOAT_INPUTS, floats, map(to_numpy, expected)):
            if name == "draw_params":  # (stroke width, miter limit, stroke-space metric)
                np.testing.assert_array_equal(got[:, 1], want[:, 1])
                np.testing.assert_array_max_ulp(got, want, maxulp=2)
            else:
                assert np.array_equal(got, want), name
    options = dict(width=64, mode="analytic", samples=3, filter="tent", filter_radius=1.0)
    if svg != TIGER:  # (tiger's strokes at 64 px are a bit wider in torch)
        assert np.array_equal(render_numpy(plain, **options), vecfit.render(tensors, **options).numpy())


@pytest.mark.slow
def test_ctrl_c_while_a_render_imports_torch(tmp_path):
    """A file that needs torch imports it once read, with Ctrl-C held until the import is
    done (cli/commands.py): exit 130, no traceback. (tests/e2e/test_interrupt.py's rect
    now renders without torch.)"""
    import signal
    import time
    svg = tmp_path / "gradient.svg"
    svg.write_text(GRADIENT)
    proc = subprocess.Popen([sys.executable, "-m", "vecfit", "render", str(svg), "-o", str(tmp_path / "g.png")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(0.8)  # read by now, well before torch's import (over a second) is done
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "interrupted" in err and "Traceback" not in err, err
    assert not (tmp_path / "g.png").exists()


@pytest.mark.parametrize("given, expected", [(None, "4"), ("12", "12")])
def test_importing_vecfit_lets_openblas_idle_threads_sleep(given, expected):
    """OpenBLAS's worker threads, started as NumPy loads, spin for 2^28 cycles before they
    sleep: a tenth of a second of a core taken from the command's start-up on a busy
    2-core machine. vecfit sets OPENBLAS_THREAD_TIMEOUT (2^4 cycles) before NumPy loads,
    unless the user set it."""
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_THREAD_TIMEOUT"}
    if given is not None:
        env["OPENBLAS_THREAD_TIMEOUT"] = given
    code = "import os, vecfit, numpy\nprint(os.environ.get('OPENBLAS_THREAD_TIMEOUT'))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60)
    assert out.stdout.split() == [expected], out.stdout + out.stderr


def test_the_command_leaves_its_objects_out_of_the_final_collections():
    """The `vecfit` script and `python -m vecfit` freeze the collector's objects once the
    command is done: the interpreter's final collections then skip NumPy's, click's and
    the command's objects (a tenth of `vecfit render` on a busy machine), and the command's
    output is the same."""
    code = ("import atexit, gc, sys\n"
            "atexit.register(lambda: print('frozen', gc.get_freeze_count() > 0))\n"
            "sys.argv = ['vecfit', '--version']\nfrom vecfit.__main__ import run\nrun()")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.startswith("vecfit ") and out.stdout.split()[-2:] == ["frozen", "True"], \
        out.stdout + out.stderr
