"""The jobs from Python (vecfit.trace, vecfit.refine, vecfit.paint): the image as a path,
bytes, an array or a PIL image, the SVG as a path or text; the same SVG as the command for
the same settings and seed; nothing written unless asked."""
from __future__ import annotations

import io
import os

import numpy as np

import vecfit
from helpers import run, two_shapes_png

FAST = {"optimize": {"iterations": 4, "threads": 1}}


def test_trace_returns_the_commands_svg_and_writes_nothing(tmp_path, monkeypatch):
    image = two_shapes_png(tmp_path / "in.png")
    run("trace", tmp_path / "in.png", "-o", tmp_path / "cli.svg", "--iterations", 4, "--threads", 1,
        "--paths", 12, "-q")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    settings = {**FAST, "trace": {"paths": 12}}
    texts = []
    for source in (tmp_path / "in.png", str(tmp_path / "in.png"), (tmp_path / "in.png").read_bytes(), image,
                   np.asarray(image)):
        svg, report = vecfit.trace(source, settings=settings)
        texts.append(svg)
        assert report["iterations"] == 4 and report["output"] is None
    assert all(t == texts[0] for t in texts)
    assert texts[0] == (tmp_path / "cli.svg").read_text()
    assert os.listdir(work) == []


def test_refine_takes_svg_text_or_a_path_and_writes_when_asked(tmp_path):
    two_shapes_png(tmp_path / "in.png")
    svg = tmp_path / "init.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="48" height="36">'
                   '<circle id="c" cx="20" cy="18" r="10" fill="#884444"/></svg>')
    from_path, _ = vecfit.refine(tmp_path / "in.png", svg, settings=FAST)
    from_text, report = vecfit.refine(tmp_path / "in.png", svg.read_text(), settings=FAST)
    assert from_path == from_text and 'id="c"' in from_text
    assert report["optimized"]["mse"] < report["initial"]["mse"]
    written, _ = vecfit.refine(io.BytesIO((tmp_path / "in.png").read_bytes()).getvalue(), svg, settings=FAST,
                               output=tmp_path / "out.svg")
    assert (tmp_path / "out.svg").read_text() == written == from_path
    assert (tmp_path / "out.report.json").exists() and (tmp_path / "out.compare.png").exists()


def test_paint_and_bad_images_are_refused_clearly(tmp_path):
    svg, report = vecfit.paint(np.full((20, 30, 3), 0.5, np.float32), settings={**FAST, "paint": {"paths": 3}})
    assert svg.count("<path") == 3 and report["iterations"] == 4
    for bad, words in ((b"not an image", "cannot be read"), (np.zeros((4, 4, 2)), "[H, W, 3]"),
                       (np.full((20, 20, 3), 2.0), "[0, 1]"), (np.zeros((5, 5, 3), np.uint8), "too small")):
        try:
            vecfit.trace(bad, settings=FAST)
        except vecfit.VecfitError as e:
            assert words in str(e), str(e)
        else:
            raise AssertionError(f"{words}: not refused")


def test_edit_and_retarget_from_python(tmp_path, monkeypatch):
    svg = ('<svg xmlns="http://www.w3.org/2000/svg" width="48" height="36" viewBox="0 0 48 36">'
           '<rect id="bg" width="48" height="36" fill="#eeeeee"/>'
           '<circle id="c" cx="16" cy="18" r="9" fill="#cc3322"/><rect id="r" x="28" y="8" width="14" '
           'height="20" fill="#2255aa"/></svg>')
    scene_image = vecfit.render(vecfit.load_svg(_write(tmp_path / "d.svg", svg)), 48, 36, samples=2)
    edited = (scene_image.numpy() * 255 + 0.5).astype(np.uint8)
    edited[14:22, 12:20, :3] = (30, 160, 60)  # paint over the circle's middle
    monkeypatch.chdir(tmp_path)
    before = sorted(os.listdir(tmp_path))
    out, report = vecfit.edit(svg, edited, settings={"optimize": {"iterations": 8, "threads": 1}})
    assert report["command"] == "edit" and report["iterations"] == 8 and 'id="c"' in out
    narrow, report = vecfit.retarget(tmp_path / "d.svg", "75%", settings={
        "optimize": {"threads": 1}, "retarget": {"steps": 1, "iterations_per_step": 2, "final_iterations": 2,
                                                 "work_size": 0}})
    assert report["size"][0] == 36 and 'width="36"' in narrow and 'id="r"' in narrow
    assert sorted(os.listdir(tmp_path)) == before  # nothing written


def _write(path, text):
    path.write_text(text)
    return path
