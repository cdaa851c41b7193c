"""The user's colours (issue 39): --palette (a list, a file, a GIMP palette, auto:N) in
trace, refine and paint; --remove-background; --group-by colour; what the reports say."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest
from PIL import Image, ImageDraw

import vecfit
from helpers import rounded_diamond, run, two_shapes_png
from vecfit.errors import VecfitError
from vecfit.fitting.metrics import compare, to_rgb
from vecfit.jobs.palette import auto_palette, from_lab, parse_palette, to_lab, written_colours
from vecfit.svg.layers import group_by_colour

FAST = {"optimize": {"iterations": 30, "threads": 1}}
PAINT_ATTR = re.compile(r'(?:fill|stroke|stop-color)="(#[0-9a-f]{6})"')


def paints(svg: str) -> set[str]:
    """Every #rrggbb the SVG paints with, by the reader (attributes and styles alike)."""
    return set(written_colours(svg.encode()))


def drawn(svg, w: int, h: int) -> np.ndarray:
    """The SVG text's render, straight RGBA [h, w, 4] without background."""
    from vecfit.svg.document import SvgDocument
    from vecfit.svg.read import scene_of
    text = svg.decode() if isinstance(svg, bytes) else svg
    image = vecfit.render(scene_of(SvgDocument.parse(text), for_writing=False), w, h, samples=4)
    return image.numpy() if hasattr(image, "numpy") else np.asarray(image)


def psnr_over(svg: str, target: np.ndarray, background=(1.0, 1.0, 1.0, 1.0)) -> float:
    image = drawn(svg, target.shape[1], target.shape[0])
    return compare(to_rgb(image, background), to_rgb(target, background))["psnr"]


def poster_png(path, size=(64, 48), background=(240, 240, 235)):
    """Three flat colours on a flat page."""
    image = Image.new("RGB", size, background)
    draw = ImageDraw.Draw(image)
    draw.ellipse((6, 5, 34, 33), fill=(200, 60, 40))
    draw.rectangle((30, 14, 58, 40), fill=(40, 90, 180))
    draw.rectangle((10, 36, 24, 44), fill=(250, 200, 30))
    image.save(path)
    return np.asarray(image, np.float32) / 255


# ------------------------------------------------------------------------ parsing

def test_a_list_a_file_and_a_gimp_palette_parse_to_the_same_colours(tmp_path):
    listed = parse_palette("#e63946, #F1FAEE,#1d3557,#e63946")
    assert listed.hex() == ["#e63946", "#f1faee", "#1d3557"]  # order kept, duplicates dropped
    (tmp_path / "p.txt").write_text("#e63946 red\n\nf1faee\n// a comment\n29 53 87\n")
    assert parse_palette(str(tmp_path / "p.txt")).hex() == listed.hex()
    (tmp_path / "p.gpl").write_text("GIMP Palette\nName: flag\nColumns: 3\n# comment\n"
                                    "230  57  70\tRed\n241 250 238\tWhite\n 29  53 135\n")
    assert parse_palette(str(tmp_path / "p.gpl")).hex() == ["#e63946", "#f1faee", "#1d3587"]
    assert parse_palette("auto:8").auto == 8 and parse_palette("AUTO: 3").auto == 3
    assert parse_palette("") is None and parse_palette(None) is None
    assert parse_palette("red").hex() == ["#ff0000"]


@pytest.mark.parametrize("value, words", [
    ("missing.gpl", "cannot be read"),
    ("#e63946,#zzzzzz", "'#zzzzzz' is not a colour"),
    ("auto:0", "at least 1"),
    ("auto:x", "at least 1"),
    (",", "empty"),
])
def test_bad_palettes_are_refused_with_the_value_named(value, words):
    with pytest.raises(VecfitError, match=re.escape(words)):
        parse_palette(value)


def test_an_empty_palette_file_is_refused(tmp_path):
    (tmp_path / "empty.txt").write_text("\n// nothing\n")
    with pytest.raises(VecfitError, match="empty.txt.*the palette is empty"):
        parse_palette(str(tmp_path / "empty.txt"))


def test_a_palette_file_is_refused_naming_the_line_that_does_not_parse(tmp_path):
    (tmp_path / "typo.txt").write_text("#ff0000\n\n#00fg00 green\n")
    with pytest.raises(VecfitError, match=r"typo.txt', line 3: '#00fg00' is not a colour"):
        parse_palette(str(tmp_path / "typo.txt"))
    (tmp_path / "high.gpl").write_text("GIMP Palette\n255 0 0 red\n256 0 0 brighter\n")
    with pytest.raises(VecfitError, match=r"high.gpl', line 3: .* has a value above 255"):
        parse_palette(str(tmp_path / "high.gpl"))
    (tmp_path / "binary.txt").write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe")
    with pytest.raises(VecfitError, match=r"binary.txt': cannot be read"):
        parse_palette(str(tmp_path / "binary.txt"))


@pytest.mark.parametrize("command", ["trace", "refine", "paint"])
def test_the_cli_refuses_each_bad_palette_with_exit_2_before_writing(tmp_path, command):
    two_shapes_png(tmp_path / "in.png")
    (tmp_path / "init.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="48" height="36">'
                                       '<circle cx="20" cy="18" r="10" fill="#884444"/></svg>')
    (tmp_path / "empty.gpl").write_text("GIMP Palette\nName: none\n")
    (tmp_path / "typo.txt").write_text("#ff0000\n#00ff00\n#00fg00 green\n")  # line 3 does not parse
    (tmp_path / "binary.txt").write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe")  # not text: unreadable
    args = [tmp_path / "in.png"] + ([tmp_path / "init.svg"] if command == "refine" else [])
    for value in (str(tmp_path / "nowhere.gpl"), str(tmp_path / "binary.txt"), str(tmp_path / "empty.gpl"),
                  ",", "#ff0000,#notacolour", str(tmp_path / "typo.txt"), "#ff000080", "auto:0"):
        out = tmp_path / "out.svg"
        result = run(command, *args, "-o", out, "--iterations", 2, "--palette", value, "-q")
        assert result.exit_code == 2, (value, result.output)
        lines = [line for line in result.output.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: ") and "palette" in lines[0], result.output
        assert not out.exists() and not (tmp_path / "out.report.json").exists()


# ----------------------------------------------------------------- the palette

def test_a_traced_palette_writes_only_its_colours_exactly(tmp_path):
    target = poster_png(tmp_path / "in.png")
    # near the image's colours, not equal: the trace must map to them in CIELAB
    palette = "#c83c28,#285ab4,#fac81e,#f0f0eb,#000000"
    free, _ = vecfit.trace(tmp_path / "in.png", settings=FAST)
    svg, report = vecfit.trace(tmp_path / "in.png", settings={**FAST, "optimize": {**FAST["optimize"],
                                                                                   "palette": palette}})
    used = paints(svg)
    assert used <= set(palette.split(",")) and len(used) == 4, used
    assert set(PAINT_ATTR.findall(svg)) == used  # written as plain #rrggbb, none translucent
    assert "opacity" not in svg
    assert report["colours"]["palette"] == palette and report["colours"]["distinct"] == 4
    assert psnr_over(svg, target) >= psnr_over(free, target) - 0.5 and psnr_over(svg, target) > 30


@pytest.mark.slow
def test_auto_palette_caps_the_distinct_colours(tmp_path):
    target = poster_png(tmp_path / "in.png")
    for n in (2, 3):
        svg, report = vecfit.trace(tmp_path / "in.png",
                                   settings={**FAST, "optimize": {**FAST["optimize"], "palette": f"auto:{n}"}})
        assert len(paints(svg)) <= n and report["colours"]["distinct"] <= n and report["file"]["colours"] <= n
    # four colours in, four allowed: every colour kept, so the picture stays close
    svg, _ = vecfit.trace(tmp_path / "in.png", settings={**FAST, "optimize": {**FAST["optimize"], "palette": "auto:4"}})
    assert len(paints(svg)) == 4 and psnr_over(svg, target) > 30


@pytest.mark.slow
def test_refine_and_paint_snap_free_colours_to_the_palette(tmp_path):
    two_shapes_png(tmp_path / "in.png")
    init = ('<svg xmlns="http://www.w3.org/2000/svg" width="48" height="36">'
            '<rect width="48" height="36" fill="#777777"/>'
            '<circle cx="20" cy="18" r="10" fill="#884444"/><rect x="24" y="12" width="20" height="20" '
            'style="fill:#3355aa;fill-opacity:0.8"/></svg>')
    palette = "#f0f0eb,#c83c28,#285ab4"
    svg, report = vecfit.refine(tmp_path / "in.png", init,
                                settings={"optimize": {"iterations": 24, "threads": 1, "palette": palette}})
    assert paints(svg) == set(palette.split(","))
    # colours the only thing fitted: the geometry-only polish has nothing to move
    frozen = {"points": 0.0, "radii": 0.0, "stroke_widths": 0.0}
    svg, _ = vecfit.refine(tmp_path / "in.png", init, settings={"optimize": {
        "iterations": 12, "threads": 1, "palette": palette, "lr": frozen}})
    assert paints(svg) == set(palette.split(","))
    svg, _ = vecfit.paint(tmp_path / "in.png", settings={"optimize": {"iterations": 12, "threads": 1,
                                                                      "palette": "auto:3"},
                                                         "paint": {"paths": 6}})
    assert 1 <= len(paints(svg)) <= 3


def test_auto_palette_kmeans_weights_by_coverage():
    rgb = np.array([[1, 0, 0], [0.98, 0.02, 0], [0, 0, 1], [0, 0.02, 0.98], [0, 1, 0]], float)
    chosen = auto_palette(rgb, np.array([100, 1, 100, 1, 0.1]), 2)
    assert len(chosen) == 2
    assert {tuple(c) for c in chosen} == {(255, 0, 0), (0, 0, 255)} or len(chosen) == 2
    back = from_lab(to_lab(rgb))
    assert np.abs(back - rgb).max() < 1e-3


# ----------------------------------------------------------- background removal

@pytest.mark.slow
def test_remove_background_leaves_the_page_transparent_and_scores_as_before(tmp_path):
    target = poster_png(tmp_path / "in.png")
    kept, _ = vecfit.trace(tmp_path / "in.png", settings=FAST)
    svg, report = vecfit.trace(tmp_path / "in.png", settings={**FAST, "trace": {"remove_background": True}})
    assert report["removed_background"] == "#f0f0eb"
    assert report["config"]["optimize"]["background"] == "auto"  # the settings as given: batch resumes on them
    assert "#f0f0eb" not in paints(svg) and "vecfit-background" not in svg
    bare = drawn(svg, 64, 48)
    assert bare[:3, :, 3].max() < 0.01 and bare[:, -3:, 3].max() < 0.01  # the page's edges: nothing drawn
    page = (240 / 255, 240 / 255, 235 / 255, 1.0)
    assert psnr_over(svg, target, page) >= psnr_over(kept, target, page) - 0.5


@pytest.mark.slow
def test_remove_background_with_a_palette_scores_over_the_colour_removed(tmp_path):
    target = poster_png(tmp_path / "in.png")
    page = (240 / 255, 240 / 255, 235 / 255, 1.0)
    for palette in ("auto:3", "#c83c28,#285ab4,#fac81e"):
        svg, report = vecfit.trace(tmp_path / "in.png", settings={
            **FAST, "optimize": {**FAST["optimize"], "palette": palette}, "trace": {"remove_background": True}})
        assert report["background"] == "#f0f0eb" and "#f0f0eb" not in paints(svg)
        assert report["optimized"]["psnr"] > 25 and psnr_over(svg, target, page) > 25


def test_remove_background_takes_the_colour_given(tmp_path):
    """The colour given is removed wherever it is (a blue band on the left edge and the
    blue square inside), not the page's dominant colour, which stays."""
    target = poster_png(tmp_path / "in.png")
    image = Image.fromarray(np.rint(target * 255).astype(np.uint8))
    ImageDraw.Draw(image).rectangle((0, 0, 4, 47), fill=(40, 90, 180))
    image.save(tmp_path / "in.png")
    svg, report = vecfit.trace(tmp_path / "in.png", settings={
        **FAST, "optimize": {**FAST["optimize"], "iterations": 0, "background": "#285ab4"},
        "trace": {"remove_background": True}})
    assert report["removed_background"] == "#285ab4" and "#f0f0eb" in paints(svg)
    bare = drawn(svg, 64, 48)
    assert bare[:, :4, 3].max() < 0.01 and bare[20:30, 40:50, 3].max() < 0.01
    assert bare[2:5, 20:30, 3].min() > 0.99  # the off-white page is drawn


def disc_at_the_edge_png(path, line=None):
    """A blue disc whose left side runs 0.3 px past the canvas's edge, anti-aliased (drawn
    8x and averaged), on a teal page; ``line``: a colour drawn over the disc's middle
    seven pixels of the canvas's left column."""
    big = Image.new("RGB", (64 * 8, 48 * 8), (42, 157, 143))
    ImageDraw.Draw(big).ellipse((19.7 * 8 - 160, 24 * 8 - 160, 19.7 * 8 + 160, 24 * 8 + 160), fill=(41, 98, 255))
    image = big.reduce(8)
    if line is not None:
        ImageDraw.Draw(image).line((0, 21, 0, 27), fill=line)
    image.save(path)
    return np.asarray(image, np.float32) / 255


def test_background_is_the_corners_colour_where_a_logo_covers_most_of_the_border():
    """A rounded card that bleeds to every edge (tunein's logo) covers most of the
    border, so the border's dominant colour is the card's; its four rounded corners show
    the page, which is the background. Where the corners do not agree (two and two), the
    border's dominant colour decides."""
    from vecfit.initial.tracer.background import border_colour, corners_rival
    page, card = (42, 157, 143), (20, 216, 204)
    image = Image.new("RGB", (96, 64), page)
    ImageDraw.Draw(image).rounded_rectangle((0, 0, 95, 63), radius=8, fill=card)
    rgb = np.asarray(image, np.float64) / 255
    assert np.rint(border_colour(rgb) * 255).astype(int).tolist() == list(page)
    ImageDraw.Draw(image).rectangle((0, 0, 95, 31), fill=card)  # top corners square: two and two
    rgb = np.asarray(image, np.float64) / 255
    assert np.rint(border_colour(rgb) * 255).astype(int).tolist() == list(card)
    # ... and the bottom corners' colour is named, for the job's warning
    assert np.rint(corners_rival(rgb, border_colour(rgb)) * 255).astype(int).tolist() == list(page)
    assert corners_rival(rgb, np.array(page) / 255) is not None  # (the card, two corners: the other guess)
    solid = np.full((8, 8, 3), 0.5)
    assert corners_rival(solid, border_colour(solid)) is None


def test_remove_background_warns_where_the_corners_disagree_with_the_border(tmp_path):
    """Two corners of the page's colour, the border mostly the frame's: the frame's colour
    is removed, and the warning names the page's colour and the option that picks it."""
    image = Image.new("RGB", (64, 48), (42, 157, 143))
    ImageDraw.Draw(image).rectangle((0, 0, 40, 47), fill=(64, 209, 245))  # the left corners and most of the border
    image.save(tmp_path / "in.png")
    with pytest.warns(UserWarning, match="corners are #2a9d8f.*--background #2a9d8f"):
        _, report = vecfit.trace(tmp_path / "in.png", settings={
            **FAST, "optimize": {**FAST["optimize"], "iterations": 0}, "trace": {"remove_background": True}})
    assert report["removed_background"] == "#40d1f5"


def test_remove_background_unmixes_a_shape_tangent_to_the_canvas_edge(tmp_path):
    """The disc's blends along the canvas's left column have no page pixel beside them
    (beyond the canvas counts as page): they are unmixed like any rim, so every pixel
    left drawn is the disc's blue (they kept their blends, then traced as pixel-sized
    pieces of other colours)."""
    from vecfit.initial.tracer.background import without_background
    target = disc_at_the_edge_png(tmp_path / "in.png")
    page = np.array([42, 157, 143]) / 255
    edge = target[:, 0, :3]
    assert ((np.abs(edge - page).max(1) > 0.02) & (np.abs(edge - [41 / 255, 98 / 255, 1]).max(1) > 0.02)).sum() >= 4
    out = without_background(np.concatenate([target, np.ones_like(target[..., :1])], 2), page)
    shown = out[..., 3] > 0
    assert np.abs(out[shown][:, :3] - np.array([41, 98, 255]) / 255).max() < 1.5 / 255
    column = out[:, 0, 3]
    assert ((column > 0.02) & (column < 0.98)).sum() >= 4  # the blends: partly covered, the page unmixed out
    svg, report = vecfit.trace(tmp_path / "in.png", settings={
        **FAST, "optimize": {**FAST["optimize"], "iterations": 0}, "trace": {"remove_background": True}})
    assert paints(svg) == {"#2962ff"} and report["trace"]["paths"] == 1


def test_remove_background_keeps_a_line_along_the_canvas_edge(tmp_path):
    """A pixel on the canvas's edge that is no blend of the page and its inner neighbour
    (a red line in the left column, over the disc) keeps its colour and stays opaque."""
    from vecfit.initial.tracer.background import without_background
    target = disc_at_the_edge_png(tmp_path / "in.png", line=(230, 20, 20))
    out = without_background(np.concatenate([target, np.ones_like(target[..., :1])], 2),
                             np.array([42, 157, 143]) / 255)
    assert np.abs(out[21:28, 0, :3] - np.array([230, 20, 20]) / 255).max() < 1e-6
    assert out[21:28, 0, 3].min() == 1.0


def test_remove_background_fits_a_shape_tangent_to_the_canvas_edge_closer(tmp_path, monkeypatch):
    """A rounded diamond touching the canvas's four sides (logos-005's shape): with the page
    removed its outline is one loop without corners that touches the edge, fitted within
    half the tolerance (bezier.EDGE_TOLERANCE); at the full tolerance, as before, its two
    halves took fewer cubics and the unrefined trace scored 3 dB lower over the page."""
    from vecfit.initial.tracer import bezier
    off = (np.arange(8) + 0.5) / 8
    ys = (np.arange(64)[:, None] + off).ravel()
    cover = (rounded_diamond(ys[None, :], ys[:, None], 64, 20.0, 12.0) <= 0).reshape(64, 8, 64, 8).mean((1, 3))
    page, blue = np.array([42, 157, 143]) / 255, np.array([41, 98, 255]) / 255
    image = np.rint((cover[..., None] * blue + (1 - cover[..., None]) * page) * 255).astype(np.uint8)
    Image.fromarray(image).save(tmp_path / "in.png")
    target = np.concatenate([image / 255, np.ones((64, 64, 1))], 2)
    settings = {**FAST, "optimize": {**FAST["optimize"], "iterations": 0}, "trace": {"remove_background": True}}
    scores = {}
    for closer in (1.0, 0.5):
        monkeypatch.setattr(bezier, "EDGE_TOLERANCE", closer)
        svg, report = vecfit.trace(tmp_path / "in.png", settings=settings)
        assert paints(svg) == {"#2962ff"} and drawn(svg, 64, 64)[:4, :4, 3].max() < 0.01
        scores[closer] = (psnr_over(svg, target, (*page, 1.0)), report["trace"]["segments"])
    assert scores[0.5][1] > scores[1.0][1]
    assert scores[0.5][0] > scores[1.0][0] + 2


# ------------------------------------------------------------------ colour layers

def svg_of(*shapes):
    body = "".join(f'<rect x="{x}" y="{y}" width="{w}" height="{h}" fill="{c}"/>' for x, y, w, h, c in shapes)
    return f'<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">{body}</svg>'.encode()


def layer_colours(svg: bytes) -> list[tuple[str, int]]:
    text = svg.decode()
    return [(label, len(re.findall(r"<rect", body))) for label, body in
            re.findall(r'inkscape:label="([^"]+)">(.*?)</g>', text, re.S)]


def test_group_by_colour_keeps_the_stacking_order():
    red, blue = "#ff0000", "#0000ff"
    # red A, blue B over A, red C apart from B (joins A's layer), red D over B (a layer of its own)
    svg = svg_of((0, 0, 30, 30, red), (20, 20, 30, 30, blue), (60, 0, 10, 10, red), (40, 40, 20, 20, red))
    out, report = group_by_colour(svg)
    assert layer_colours(out) == [(red, 2), (blue, 1), (f"{red} (2)", 1)]
    assert report["split"] == [red] and report["warnings"] and 'inkscape:groupmode="layer"' in out.decode()
    # the picture is unchanged
    assert np.abs(drawn(svg, 100, 100) - drawn(out, 100, 100)).max() < 1e-6
    # nothing overlapping: one layer a colour, no warning
    out, report = group_by_colour(svg_of((0, 0, 10, 10, red), (20, 0, 10, 10, blue), (40, 0, 10, 10, red)))
    assert layer_colours(out) == [(red, 2), (blue, 1)] and not report["warnings"]


def test_trace_group_by_colour_reports_its_layers(tmp_path):
    poster_png(tmp_path / "in.png")
    out = tmp_path / "out.svg"
    result = run("trace", tmp_path / "in.png", "-o", out, "--iterations", 0, "--group-by", "colour",
                 "--palette", "auto:4", "-q")
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    layers = report["colours"]["layers"]["layers"]
    text = out.read_text()
    assert len(layers) == text.count('inkscape:groupmode="layer"') >= 3
    assert {layer["colour"] for layer in layers} <= set(report["colours"]["used"])


# ---------------------------------------------------------------------- defaults

def test_without_the_options_the_report_has_no_colour_entry(tmp_path):
    two_shapes_png(tmp_path / "in.png")
    svg, report = vecfit.trace(tmp_path / "in.png", settings={"optimize": {"iterations": 0}})
    same, _ = vecfit.trace(tmp_path / "in.png", settings={"optimize": {"iterations": 0, "palette": ""},
                                                          "output": {"group_by": "none"}})
    assert "colours" not in report and svg == same and "inkscape" not in svg


@pytest.mark.slow
def test_batch_takes_the_colour_options_and_summarises_them(tmp_path):
    import csv
    (tmp_path / "in").mkdir()
    poster_png(tmp_path / "in" / "a.png")
    result = run("batch", tmp_path / "in", "-o", tmp_path / "out", "--mode", "trace", "--effort", "quick",
                 "--palette", "auto:3", "--group-by", "colour", "--remove-background", "-q")
    assert result.exit_code == 0, result.output
    row = next(csv.DictReader(open(tmp_path / "out" / "summary.csv")))
    assert row["palette"] == "auto:3" and int(row["file_colours"]) <= 3 and int(row["layers"]) >= 1
    assert "#f0f0eb" not in paints((tmp_path / "out" / "a.svg").read_text())
    for bad in (["--palette", "auto:0"], ["--palette", str(tmp_path / "none.gpl")]):
        result = run("batch", tmp_path / "in", "-o", tmp_path / "bad", "--mode", "trace", *bad, "-q")
        assert result.exit_code == 2 and not (tmp_path / "bad").exists(), result.output
    result = run("batch", tmp_path / "in", "-o", tmp_path / "bad", "--mode", "paint", "--remove-background", "-q")
    assert result.exit_code == 2 and "trace" in result.output
