"""`vecfit trace` end to end: trace, refine, outputs, budgets, presets and bad input."""
from __future__ import annotations

import json
import os

import numpy as np
import pytest
from PIL import Image

import vecfit
from helpers import photo_png, quiet_load, run
from vecfit.fitting.metrics import compare


@pytest.fixture(scope="module")
def coffee(tmp_path_factory):
    return photo_png(tmp_path_factory, "coffee", (96, 64))


@pytest.mark.slow
def test_trace_and_refine(coffee, tmp_path):
    """A 96 x 64 photo, at most 60 paths: the trace parses, renders, keeps the budget, and
    30 iterations of refinement gain >= 1 dB (measured ~2.5 dB)."""
    out = tmp_path / "c.svg"
    r = run("trace", coffee, "-o", out, "--paths", 60, "--iterations", 30, "--threads", 2, "-q")
    assert r.exit_code == 0, r.output
    report = json.loads((tmp_path / "c.report.json").read_text())
    # (the background rect of an opaque image is not counted against the budget)
    assert report["command"] == "trace" and report["trace"]["paths"] <= 60 + 1
    scene = quiet_load(out)
    assert 10 <= len(scene.shapes) <= 60 + 1
    assert report["optimized"]["psnr"] >= report["initial"]["psnr"] + 1.0
    assert report["initial"]["psnr"] > 18  # the trace alone already resembles the photo
    target = np.asarray(Image.open(coffee).convert("RGB"), np.float64) / 255
    img = vecfit.render(scene, 96, 64, samples=4, background=[1, 1, 1, 1]).numpy()[..., :3]
    assert abs(compare(img.astype(np.float64), target)["psnr"] - report["optimized"]["psnr"]) < 0.5


def test_no_refine_writes_the_trace(coffee, tmp_path):
    out = tmp_path / "t.svg"
    r = run("trace", coffee, "-o", out, "--no-refine", "--preset", "poster", "-q")
    assert r.exit_code == 0, r.output
    report = json.loads((tmp_path / "t.report.json").read_text())
    assert report["iterations"] == 0 and report["loss_curve"] == []
    assert report["optimized"] == report["initial"]
    assert report["config"]["trace"]["palette"] is True
    scene = quiet_load(out)
    colors = {tuple(np.round(s.fill.color.numpy(), 3)) for s in scene.shapes if s.fill is not None}
    assert len(colors) <= 12  # the poster preset's palette


def test_transparent_target_stays_transparent(tmp_path):
    a = np.zeros((40, 40, 4), np.uint8)
    yy, xx = np.mgrid[0:40, 0:40]
    r2 = (xx - 20) ** 2 + (yy - 20) ** 2
    a[(r2 >= 36) & (r2 < 196)] = (200, 30, 30, 255)  # a ring: its hole stays transparent too
    Image.fromarray(a, "RGBA").save(tmp_path / "ring.png")
    r = run("trace", tmp_path / "ring.png", "--iterations", 10, "-q")
    assert r.exit_code == 0, r.output
    scene = quiet_load(tmp_path / "ring.vecfit.svg")
    img = vecfit.render(scene, 40, 40, samples=2).numpy()
    assert img[0, 0, 3] == 0 and img[20, 20, 3] == 0 and img[20, 30, 3] > 0.99
    assert "vecfit-background" not in (tmp_path / "ring.vecfit.svg").read_text()


@pytest.mark.parametrize("case", ["missing", "not an image", "folder"])
def test_bad_target(case, tmp_path):
    path = {"missing": tmp_path / "nope.png", "not an image": tmp_path / "x.png",
            "folder": tmp_path / "d"}[case]
    if case == "not an image":
        path.write_bytes(b"\x89PNG but not really")
    if case == "folder":
        path.mkdir()
    before = sorted(os.listdir(tmp_path))
    r = run("trace", path, "-q")
    assert r.exit_code in (1, 2), r.output
    assert "Traceback" not in r.output and str(path) in r.output, r.output
    assert sorted(os.listdir(tmp_path)) == before


def test_bad_trace_setting_is_a_usage_error(coffee, tmp_path):
    cfg = tmp_path / "t.toml"
    cfg.write_text("[trace]\ncolours = 5\n")
    r = run("trace", coffee, "--config", cfg)
    assert r.exit_code == 2 and "unknown setting 'trace.colours'" in r.output
