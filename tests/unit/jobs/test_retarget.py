"""`vecfit retarget`: seam carving, points carried through seams, the canvas written back,
and the command end to end (resvg renders the result; the salient disc keeps its shape)."""
from __future__ import annotations

import io
import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import torch
from PIL import Image

from editing_cases import structure
from helpers import quiet_load, run
from vecfit.editing.points import carve_points
from vecfit.editing.seams import carve, energy, foreground, remove_seam, shift, vertical_seam
from vecfit.jobs.retarget import parse_size
from vecfit.scene import Path, Scene, Shape, Solid

resvg_py = pytest.importorskip("resvg_py")

# A face (a disc with eyes) on the left, a small box on the right, flat background between:
# the seams should go through the flat parts and leave both shapes their widths.
PICTURE = """<svg xmlns="http://www.w3.org/2000/svg" width="96" height="48" viewBox="0 0 192 96">
<rect id="ground" x="-4" y="-4" width="200" height="104" fill="#e8eef4"/>
<g id="face" transform="translate(48 48)">
  <circle id="head" r="30" fill="#d02020"/>
  <circle id="eye-l" cx="-10" cy="-8" r="5" fill="#ffffff"/>
  <circle id="eye-r" cx="10" cy="-8" r="5" fill="#ffffff"/>
</g>
<rect id="box" x="150" y="30" width="24" height="36" fill="#2050c0"/>
</svg>"""


def resvg_rgba(svg_path) -> np.ndarray:
    png = bytes(resvg_py.svg_to_bytes(svg_path=str(svg_path)))
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), np.float64) / 255


def extent(rgba, colour) -> tuple[int, int]:
    """Width and height of the bounding box of pixels near ``colour`` (RGB 0-1)."""
    near = (np.abs(rgba[..., :3] - np.asarray(colour)).max(axis=2) < 0.15) & (rgba[..., 3] > 0.5)
    ys, xs = np.nonzero(near)
    return int(xs.max() - xs.min() + 1), int(ys.max() - ys.min() + 1)


# ------------------------------------------------------------------ seams

def test_vertical_seam_follows_the_least_energy_path():
    e = np.ones((6, 8))
    path = [2, 3, 3, 4, 5, 4]  # an 8-connected path of zero energy
    e[np.arange(6), path] = 0
    assert vertical_seam(e).tolist() == path
    image = np.arange(48).reshape(6, 8)
    carved = remove_seam(image, np.array(path))
    assert carved.shape == (6, 7)
    assert all(path[y] * 1 + y * 8 not in carved[y] for y in range(6))


def test_carve_removes_flat_columns_first():
    image = np.zeros((10, 20, 3), np.float32)
    image[:, 5:8] = (1, 0, 0)      # a red bar
    image[:, 14:15] = (0, 0, 1)    # a blue line
    # the bar's inside is as flat as the background: gradient energy alone cuts it
    assert float(energy(image)[:, 6].max()) == 0.0
    carved, _ = carve(image, 6)
    assert (carved[..., 0] > 0.5).sum(axis=1).tolist() == [2] * 10
    # with the foreground's salience the seams go through the background only
    carved, seams = carve(image, 6, salience=foreground(image, np.zeros(3)))
    assert carved.shape == (10, 14, 3)
    assert (carved[..., 0] > 0.5).sum(axis=1).tolist() == [3] * 10
    assert (carved[..., 2] > 0.5).sum(axis=1).tolist() == [1] * 10


def test_shift_moves_points_by_the_seams_to_their_left():
    seams = [np.array([3, 3, 4]), np.array([0, 0, 0])]
    x = np.array([1.0, 3.5, 5.0, 4.0])
    y = np.array([0.2, 1.5, 2.0, 2.9])
    # first seam: rows 0, 1 at 3, row 2 at 4; then column 0 everywhere
    # (4, 2.9) lies at the left edge of its row's first seam pixel: only the second moves it
    assert shift(x, y, seams).tolist() == [0.0, 2.0, 3.0, 3.0]


def test_carve_points_maps_through_the_shapes_transforms():
    pts = torch.tensor([[2.0, 1.0], [10.0, 1.0], [10.0, 6.0]])
    shape = Shape(Path(pts.clone(), np.array([1, 1, 1]), [(0, 3, True)]), fill=Solid(torch.ones(4)),
                  transform=torch.tensor([[2.0, 0, 0], [0, 2.0, 0], [0, 0, 1]]))
    scene = Scene(40.0, 20.0, [shape])
    # 3 seams at column 10 of every row of the 40 x 20 render: the points at x = 20 px
    # (local 10) move left 3 px (1.5 local units), the one at x = 4 px stays
    carve_points(scene, [np.full(20, 10)] * 3, 40, 20, axis=0)
    assert torch.allclose(shape.geometry.points, torch.tensor([[2.0, 1.0], [8.5, 1.0], [8.5, 6.0]]))
    carve_points(scene, [np.full(40, 1)], 40, 20, axis=1)  # one horizontal seam at y = 1
    assert torch.allclose(shape.geometry.points[:, 1], torch.tensor([0.5, 0.5, 5.5]))


def test_sizes_in_pixels_or_percent():
    assert parse_size("120", 200, "--width") == 120
    assert parse_size("120px", 200, "--width") == 120
    assert parse_size("65%", 200, "--width") == 130
    with pytest.raises(Exception, match="percentage"):
        parse_size("wide", 200, "--width")


# ------------------------------------------------------------- end to end

@pytest.fixture()
def picture(tmp_path):
    (tmp_path / "picture.svg").write_text(PICTURE)
    (tmp_path / "fast.toml").write_text(
        "[retarget]\nsteps = 2\niterations_per_step = 15\nfinal_iterations = 15\nwork_size = 0\n")
    return tmp_path


@pytest.mark.slow
def test_retarget_narrows_the_canvas_and_keeps_the_face_round(picture):
    out = picture / "narrow.svg"
    r = run("retarget", picture / "picture.svg", "--width", "70%", "-o", out, "--config",
            picture / "fast.toml", "--threads", 2, "-q")
    assert r.exit_code == 0, r.output
    root = ET.parse(out).getroot()
    assert float(root.get("width")) == pytest.approx(67.2) and float(root.get("height")) == 48
    assert [float(v) for v in root.get("viewBox").split()] == pytest.approx([0, 0, 134.4, 96])
    assert structure(out) == structure(picture / "picture.svg")
    rgba = resvg_rgba(out)
    assert rgba.shape[:2] == (48, 67)
    before = resvg_rgba(picture / "picture.svg")
    (fw0, fh0), (fw, fh) = extent(before, (0.816, 0.125, 0.125)), extent(rgba, (0.816, 0.125, 0.125))
    # plain scaling would make the face 70% as wide; carving keeps it within 10%
    assert fw >= 0.9 * fw0 and abs(fh - fh0) <= 2, ((fw0, fh0), (fw, fh))
    bw0, bw = extent(before, (0.125, 0.314, 0.753))[0], extent(rgba, (0.125, 0.314, 0.753))[0]
    assert bw >= 0.85 * bw0
    report = json.loads((picture / "narrow.report.json").read_text())
    assert report["command"] == "retarget" and report["seams"]["vertical"] == 29
    assert report["optimized"]["psnr"] > 25 and report["interrupted"] is False
    with Image.open(picture / "narrow.compare.png") as im:
        assert im.width == 96 + 67 + 67 + 2 * 4 and im.height == 48  # input | scaled | retargeted
    assert len(quiet_load(out).shapes) == 5


@pytest.mark.parametrize("case", ["enlarge", "same", "bad_width", "no_shapes", "tiny"])
def test_bad_input_is_one_clear_line(case, picture):
    svg, width, words = picture / "picture.svg", "50%", ""
    if case == "enlarge":
        width, words = "120", "cannot enlarge"
    elif case == "same":
        width, words = "96", "nothing to retarget"
    elif case == "bad_width":
        width, words = "wide", "percentage"
    elif case == "tiny":
        width, words = "5", "too small"
    else:
        (picture / "empty.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="64" height="48"/>')
        svg, words = picture / "empty.svg", "no shapes"
    r = run("retarget", svg, "--width", width, "-o", picture / "out.svg", "--threads", 2, "-q")
    assert r.exit_code == 1, r.output
    lines = [line for line in r.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and words in lines[0], r.output
    assert not (picture / "out.svg").exists()


def test_ctrl_c_writes_the_best_result_so_far(picture):
    """Interrupted in the first round: the SVG is written at that round's width, with
    every element, and the report says so."""
    from vecfit.jobs.config import resolve
    from vecfit.jobs.protocol import Inputs, Outputs
    from vecfit.jobs.retarget import run as retarget

    calls = []

    def stop(progress):
        calls.append(progress)
        if len(calls) == 10:
            raise KeyboardInterrupt

    config = resolve("retarget", config_file=picture / "fast.toml",
                     overrides={"optimize": {"threads": 2}, "retarget": {"width": "50%"}})
    outputs = Outputs.beside(picture / "picture.svg", picture / "stopped.svg")
    report = retarget(Inputs(svg=picture / "picture.svg"), config, outputs, progress=stop)
    assert report["interrupted"] is True and report["iterations"] == 10
    width = float(ET.parse(outputs.svg).getroot().get("width"))
    assert width == pytest.approx(72)  # stopped in the first of two rounds: half the seams
    assert structure(outputs.svg) == structure(picture / "picture.svg")
    assert json.loads(outputs.report.read_text())["interrupted"] is True


def test_iterations_sets_the_whole_runs_adam_steps(picture):
    """--iterations N: N steps in all, divided like the config divides them (2 rounds of 15
    and 15 at the end: 18 gives 2 rounds of 6 and 6 at the end)."""
    out = picture / "short.svg"
    r = run("retarget", picture / "picture.svg", "--width", "70%", "-o", out, "--config",
            picture / "fast.toml", "--iterations", 18, "--threads", 2, "-q")
    assert r.exit_code == 0, r.output
    report = json.loads((picture / "short.report.json").read_text())
    assert report["iterations"] == 18
    assert report["config"]["retarget"]["iterations_per_step"] == 6
    assert report["config"]["retarget"]["final_iterations"] == 6
    assert report["config"]["retarget"]["width"] == "70%"  # the size is part of the settings


@pytest.mark.slow
def test_batch_retargets_every_svg_of_a_folder(picture):
    folder = picture / "in"
    folder.mkdir()
    (folder / "a.svg").write_text(PICTURE)
    (folder / "b.svg").write_text(PICTURE.replace('width="96" height="48"', 'width="80" height="40"'))
    (folder / "notes.txt").write_text("not an SVG")
    out = picture / "out"
    def args(width):
        return ("batch", folder, "-o", out, "--mode", "retarget", "--width", width, "--config",
                picture / "fast.toml", "-q")

    r = run(*args("75%"))
    assert r.exit_code == 0, r.output
    for name, (w, h) in (("a", (72, 48)), ("b", (60, 40))):
        root = ET.parse(out / f"{name}.svg").getroot()
        assert float(root.get("width")) == pytest.approx(w, abs=1) and float(root.get("height")) == h
        assert structure(out / f"{name}.svg") == structure(folder / f"{name}.svg")
    rows = json.loads((out / "summary.json").read_text())["images"]
    assert [(row["file"], row["status"]) for row in rows] == [("a.svg", "done"), ("b.svg", "done")]
    again = run(*args("75%"))  # finished with the same settings: skipped
    assert again.exit_code == 0 and "2 skipped" in again.output, again.output
    wider = run(*args("90%"))  # another size: done again
    assert wider.exit_code == 0 and "2 done" in wider.output, wider.output


@pytest.mark.parametrize("argv,words", [
    (("--mode", "retarget"), "needs --width"),
    (("--mode", "trace", "--width", "50%"), "for --mode retarget"),
])
def test_batch_size_options_are_checked(picture, argv, words):
    r = run("batch", picture, "-o", picture / "out", *argv, "-q")
    assert r.exit_code == 2 and words in r.output, r.output
