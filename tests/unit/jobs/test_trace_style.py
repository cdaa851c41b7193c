"""`vecfit trace --style`: strokes refined through the renderer (points, widths, colours) and
written without fills; fills as before; the style in the report, batch and Python."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest
from PIL import Image

import vecfit
from helpers import run
from vecfit.batch import EXIT_USAGE

FAST = {"optimize": {"iterations": 12, "threads": 1}}


def line_art(path):
    """An anti-aliased line drawing: an L and a ring, 6 px lines, over white."""
    svg = ('<svg xmlns="http://www.w3.org/2000/svg" width="96" height="96"><g fill="none" stroke="#151515" '
           'stroke-width="6" stroke-linecap="round" stroke-linejoin="round"><path d="M14 14V80H50"/>'
           '<circle cx="66" cy="36" r="18"/></g></svg>')
    (path.parent / "art.svg").write_text(svg)
    scene = vecfit.load_svg(path.parent / "art.svg")
    rgba = vecfit.render(scene, 96, 96, samples=4, background=(1, 1, 1, 1)).numpy()
    Image.fromarray((np.clip(rgba[..., :3], 0, 1) * 255 + 0.5).astype(np.uint8)).save(path)
    return path


def elements(svg: str) -> list[str]:
    return [m.group(0) for m in re.finditer(r"<(path|circle|ellipse|rect|polygon)\b[^>]*>", svg)
            if 'id="vecfit-background"' not in m.group(0)]


@pytest.mark.slow
def test_strokes_are_refined_and_written_without_fills(tmp_path):
    png = line_art(tmp_path / "art.png")
    svg, report = vecfit.trace(png, style="strokes", settings=FAST)
    drawn = elements(svg)
    assert len(drawn) == 2
    assert all('fill="none"' in e and 'stroke="#' in e and "stroke-width" in e for e in drawn), drawn
    assert report["style"] == "strokes" and report["trace"]["strokes"] == 2 and report["trace"]["warnings"] == []
    assert report["parameters"]["stroke_widths"] == 2  # widths are optimised
    assert report["optimized"]["psnr"] >= report["initial"]["psnr"] - 1e-9  # (the loop keeps its best)
    assert report["optimized"]["psnr"] > 32


def test_the_command_takes_style_and_fills_stays_as_it_was(tmp_path):
    png = line_art(tmp_path / "art.png")
    run("trace", png, "-o", tmp_path / "default.svg", "--no-refine", "-q")
    run("trace", png, "-o", tmp_path / "fills.svg", "--no-refine", "--style", "fills", "-q")
    assert (tmp_path / "default.svg").read_bytes() == (tmp_path / "fills.svg").read_bytes()
    assert json.loads((tmp_path / "fills.report.json").read_text())["style"] == "fills"
    result = run("trace", png, "-o", tmp_path / "strokes.svg", "--no-refine", "--style", "strokes", "-q")
    assert result.exit_code == 0
    assert all('fill="none"' in e for e in elements((tmp_path / "strokes.svg").read_text()))
    bad = run("trace", png, "-o", tmp_path / "x.svg", "--style", "pencil", "-q")
    assert bad.exit_code == 2 and "Traceback" not in bad.output


@pytest.mark.slow
def test_batch_takes_style_for_trace_only(tmp_path):
    folder = tmp_path / "in"
    folder.mkdir()
    line_art(folder / "art.png")
    result = run("batch", folder, "-o", tmp_path / "out", "--mode", "trace", "--style", "strokes", "--effort", "quick",
                 "--threads", "1", "-q")
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "out" / "art.report.json").read_text())
    assert report["style"] == "strokes"
    refused = run("batch", folder, "-o", tmp_path / "out2", "--mode", "paint", "--style", "strokes", "-q")
    assert refused.exit_code == EXIT_USAGE and "--style" in refused.output


def test_a_blurred_drawing_reports_the_figures_the_fit_reached(tmp_path):
    # fitted through a 1.5-px blur, the sharp lines written score low against the blurred
    # image; "as_fitted" scores them blurred alike, which is what the fit compared
    import cv2

    png = line_art(tmp_path / "art.png")
    blurred = cv2.GaussianBlur(np.asarray(Image.open(png), np.float32), (0, 0), 1.5)
    Image.fromarray(np.clip(blurred + 0.5, 0, 255).astype(np.uint8)).save(png)
    settings = {"optimize": {**FAST["optimize"], "target_blur": 1.5}}
    _, report = vecfit.trace(png, style="strokes", settings=settings)
    fitted = report["as_fitted"]
    assert fitted["target_blur"] == 1.5
    assert fitted["psnr"] > report["optimized"]["psnr"] + 5 and fitted["ssim"] > report["optimized"]["ssim"]
    _, sharp = vecfit.trace(line_art(tmp_path / "sharp.png"), style="strokes",
                            settings={"optimize": {**FAST["optimize"], "target_blur": 0}})
    assert "as_fitted" not in sharp  # no blur: the figures are the fit's own
