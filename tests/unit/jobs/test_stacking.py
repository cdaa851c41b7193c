"""--stacking cutouts and --gap-filler through the jobs, the command line and batch."""
from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image, ImageDraw

import vecfit
from helpers import run
from vecfit.svg.layers import group_by_colour


def poster_png(path, size=(72, 56)):
    """Flat colours on a flat page, overlapping."""
    image = Image.new("RGB", size, (240, 240, 235))
    draw = ImageDraw.Draw(image)
    draw.ellipse((6, 5, 38, 37), fill=(200, 60, 40))
    draw.rectangle((30, 14, 64, 44), fill=(40, 90, 180))
    draw.polygon([(10, 50), (40, 30), (50, 52)], fill=(250, 200, 30))
    image.save(path)


def test_trace_writes_cutouts_and_reports_what_the_file_scores(tmp_path):
    poster_png(tmp_path / "in.png")
    out = tmp_path / "out.svg"
    result = run("trace", tmp_path / "in.png", "-o", out, "--stacking", "cutouts", "--iterations", 20, "-q")
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    cut = report["cutouts"]
    assert cut["pieces"] == report["file"]["paths"] >= 4
    assert cut["followed"] >= cut["chains"] // 2
    assert abs(cut["psnr"] - report["optimized"]["psnr"]) < 1.0  # the same picture
    assert report["file"]["crossed_outlines"] == 0 and report["file"]["translucent_paints"] == 0
    assert "vecfit-background" not in out.read_text()  # the page is a piece like the others
    # one layer a colour: nothing overlaps, so no colour needs two
    _, layers = group_by_colour(out.read_bytes())
    assert not layers["split"]


def test_the_gap_filler_is_written_first(tmp_path):
    poster_png(tmp_path / "in.png")
    svg, report = vecfit.trace(tmp_path / "in.png", settings={
        "optimize": {"iterations": 0}, "output": {"stacking": "cutouts", "gap_filler": True}})
    assert report["cutouts"]["gap_filler"] > 0
    assert svg.index('fill="none"') < svg.index('fill="#')


def test_bad_combinations_are_usage_errors(tmp_path):
    poster_png(tmp_path / "in.png")
    result = run("trace", tmp_path / "in.png", "-o", tmp_path / "a.svg", "--gap-filler", "-q")
    assert result.exit_code == 2 and "cut-outs" in result.output
    result = run("trace", tmp_path / "in.png", "-o", tmp_path / "b.svg", "--stacking", "cutouts",
                 "--style", "strokes", "-q")
    assert result.exit_code == 2 and "--style fills" in result.output
    assert not (tmp_path / "a.svg").exists() and not (tmp_path / "b.svg").exists()


def test_refine_refuses_a_stroked_file_before_the_work(tmp_path):
    poster_png(tmp_path / "in.png")
    (tmp_path / "in.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="72" height="56">'
                                     '<path d="M5 5 L60 40" stroke="#000" fill="none"/></svg>')
    result = run("refine", tmp_path / "in.png", tmp_path / "in.svg", "-o", tmp_path / "out.svg",
                 "--stacking", "cutouts", "-q")
    assert result.exit_code != 0 and "strokes" in result.output and "in.svg" in result.output
    assert "Traceback" not in result.output and not (tmp_path / "out.svg").exists()


@pytest.mark.slow
def test_batch_passes_the_stacking_on(tmp_path):
    (tmp_path / "in").mkdir()
    poster_png(tmp_path / "in" / "a.png")
    result = run("batch", tmp_path / "in", "-o", tmp_path / "out", "--mode", "trace", "--effort", "quick",
                 "--stacking", "cutouts", "-q")
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "out" / "a.report.json").read_text())
    assert report["config"]["output"]["stacking"] == "cutouts" and "cutouts" in report
