"""`vecfit paint`: random primitives fitted to a photo, re-seeding, frames."""
from __future__ import annotations

import io
import json

import numpy as np
import pytest
import torch
from PIL import Image

import vecfit
from helpers import photo_png, quiet_load, run
from vecfit.fitting.metrics import compare
from vecfit.fitting.loop import Step, Target
from vecfit.initial.strokes import PaintSettings, Reseeder, initial_document
from vecfit.scene import Path as PathGeometry, Scene, Shape, Solid


@pytest.fixture(scope="module")
def astronaut(tmp_path_factory):
    return photo_png(tmp_path_factory, "astronaut", (64, 64))


@pytest.mark.slow
def test_paint_strokes_fit_the_target(astronaut, tmp_path):
    """64 strokes, 60 iterations at 64 px: the loss falls at least 4x (it falls ~6x)."""
    out = tmp_path / "p.svg"
    r = run("paint", astronaut, "-o", out, "--paths", 64, "--iters", 60, "--threads", 2, "-q",
            "--frames", tmp_path / "frames")
    assert r.exit_code == 0, r.output
    report = json.loads((tmp_path / "p.report.json").read_text())
    curve = report["loss_curve"]
    assert len(curve) == 60
    assert min(curve) < curve[0] / 4
    assert report["optimized"]["psnr"] > report["initial"]["psnr"] + 6
    assert report["paint"]["kind"] == "strokes" and report["paint"]["paths"] == 64
    scene = quiet_load(out)
    # the canvas colour (from the target's corners) as a first rect, then the strokes
    assert len(scene.shapes) == 65 and scene.shapes[0].source == "vecfit-background"
    # strokes, some perhaps thinned to nothing (written as width 0, read back as no stroke)
    assert all(s.fill is None and (s.stroke is not None or float(s.stroke_width) == 0)
               for s in scene.shapes[1:])
    # frames every 5 iterations, and a GIF of them
    assert report["frames"]["count"] == 12
    assert (tmp_path / "frames" / "frame_00055.png").exists()
    with Image.open(tmp_path / "frames" / "optimization.gif") as gif:
        assert gif.n_frames == 12


def test_paint_shapes_and_resvg_agrees(astronaut, tmp_path):
    resvg_py = pytest.importorskip("resvg_py")
    out = tmp_path / "s.svg"
    r = run("paint", astronaut, "-o", out, "--kind", "shapes", "--paths", 32, "--iters", 30,
            "--threads", 2, "-q")
    assert r.exit_code == 0, r.output
    report = json.loads((tmp_path / "s.report.json").read_text())
    assert report["optimized"]["psnr"] > report["initial"]["psnr"] + 3
    scene = quiet_load(out)
    assert all(s.fill is not None and s.stroke is None for s in scene.shapes[-32:])
    png = bytes(resvg_py.svg_to_bytes(svg_path=str(out), width=256))
    theirs = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), np.float64) / 255
    ours = vecfit.render(scene, 256, 256, samples=4, background=[1, 1, 1, 1]).numpy()[..., :3]
    assert compare(ours.astype(np.float64), theirs)["psnr"] >= 30


def test_initial_svg_is_random_but_reproducible():
    target = np.ones((40, 60, 4), np.float32)
    a = initial_document(target, PaintSettings.defaults(paths=10, seed=1)).text()
    assert a == initial_document(target, PaintSettings.defaults(paths=10, seed=1)).text()
    assert a != initial_document(target, PaintSettings.defaults(paths=10, seed=2)).text()
    assert a.count("<path") == 10 and 'viewBox="0 0 60 40"' in a


def _stroke(points, alpha=1.0, width=2.0):
    pts = torch.tensor(points, dtype=torch.float32)
    return Shape(PathGeometry(pts, np.array([3]), [(0, 1, False)]), fill=None,
                 stroke=Solid(torch.tensor([0.0, 0.0, 0.0, alpha])), stroke_width=torch.tensor(width))


def test_reseeding_moves_wasted_strokes_to_the_error():
    """An off-canvas stroke and a faded one are re-seeded into the only region of error
    (a red square at the bottom right); a healthy stroke is left alone."""
    healthy = _stroke([[5, 5], [8, 6], [10, 8], [12, 12]])
    off = _stroke([[-30, -30], [-25, -28], [-22, -26], [-20, -20]])
    faded = _stroke([[20, 5], [22, 6], [25, 8], [28, 9]], alpha=0.01)
    scene = Scene(40, 40, [healthy, off, faded])
    goal = np.ones((40, 40, 4), np.float32)
    goal[28:36, 28:36, :3] = (1, 0, 0)
    image = torch.ones((40, 40, 4))  # the current render: all white, so error only at the square
    target = Target(torch.from_numpy(goal), (1.0, 1.0, 1.0, 1.0))
    resets = []
    before = healthy.geometry.points.clone()
    reseeder = Reseeder(PaintSettings.defaults(reseed_every=10, radius=0.1), iterations=100)
    with torch.no_grad():
        reseeder(Step(9, image, scene, target, resets.append))
    assert reseeder.reseeded == 2 and reseeder.history == [(10, 2)]
    assert torch.equal(healthy.geometry.points, before)
    for s in (off, faded):
        start = s.geometry.points[0]
        assert 24 <= float(start[0]) <= 40 and 24 <= float(start[1]) <= 40, start
        assert s.stroke.color.tolist() == pytest.approx([1.0, 0.0, 0.0, 1.0])
    assert {id(t) for t in resets} >= {id(off.geometry.points), id(faded.stroke.color)}
    # not in the last fifth of a run: the final primitives settle undisturbed
    late = Reseeder(PaintSettings.defaults(reseed_every=10), iterations=100)
    off.geometry.points -= 100
    with torch.no_grad():
        late(Step(89, image, scene, target, resets.append))
    assert late.reseeded == 0


def test_bad_paint_options_are_usage_errors(astronaut, tmp_path):
    r = run("paint", astronaut, "--kind", "blobs")
    assert r.exit_code == 2
    r = run("paint", astronaut, "--paths", 0)
    assert r.exit_code == 2
    r = run("paint", astronaut, "--preset", "nope")
    assert r.exit_code == 2 and "unknown preset 'nope'" in r.output
