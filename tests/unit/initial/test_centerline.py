"""--style strokes (vecfit/initial/tracer/centerline.py, skeleton.py): drawn stroke patterns,
rendered, traced back as stroked paths of the right number, width and place."""
from __future__ import annotations

import hashlib
import re
import warnings

import cv2
import numpy as np
import pytest

import vecfit
from vecfit import VecfitError
from vecfit.errors import VecfitWarning
from vecfit.initial.tracer import TraceSettings, trace_image
from vecfit.initial.tracer.skeleton import centerlines

SIZE = 128


def drawn(elements: str, size: int = SIZE) -> np.ndarray:
    """The stroked elements rendered over white by vecfit: float RGBA [H, W, 4]."""
    svg = (f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}">'
           f'<g fill="none" stroke="#202020" stroke-linecap="round" stroke-linejoin="round">{elements}</g></svg>')
    scene = vecfit.load_svg(_write(svg))
    return vecfit.render(scene, size, size, samples=4, background=(1, 1, 1, 1)).numpy()


def _write(svg: str):
    import tempfile
    from pathlib import Path
    path = Path(tempfile.mkdtemp()) / "drawn.svg"
    path.write_text(svg)
    return path


def rendered(svg: str, size: int = SIZE) -> np.ndarray:
    scene = vecfit.load_svg(_write(svg))
    rgba = vecfit.render(scene, size, size, samples=4, background=(1, 1, 1, 1)).numpy()
    return rgba[..., :3]


def psnr(a, b) -> float:
    return float(10 * np.log10(1 / max(float(((a - b) ** 2).mean()), 1e-12)))


def strokes_of(svg: str) -> list[dict]:
    """The stroked elements' attributes."""
    out = []
    for m in re.finditer(r"<(path|circle|ellipse|rect)\b([^>]*)>", svg):
        attrs = dict(re.findall(r'([\w-]+)="([^"]*)"', m.group(2)))
        if attrs.get("id") == "vecfit-background":
            continue
        out.append({"tag": m.group(1), **attrs})
    return out


def traced(elements: str, **settings):
    image = drawn(elements)
    with warnings.catch_warnings():
        warnings.simplefilter("error", VecfitWarning)  # line work: no fallback warning
        result = trace_image(image, TraceSettings.defaults(style="strokes", **settings))
    return image, result


@pytest.mark.parametrize("elements, count, width, tag", [
    ('<path d="M20 30 L108 90" stroke-width="8"/>', 1, 8, "path"),                 # a line
    ('<path d="M25 20 V100 H105" stroke-width="6"/>', 1, 6, "path"),               # an L: one path, a corner
    ('<circle cx="64" cy="64" r="38" stroke-width="7"/>', 1, 7, "circle"),         # a circle
    ('<path d="M20 30 H108 M64 30 V110" stroke-width="8"/>', 2, 8, "path"),        # a T: bar and stem
    ('<rect x="25" y="30" width="80" height="60" stroke-width="5"/>', 1, 5, "path"),  # a closed outline
])
def test_stroke_patterns_come_back_as_strokes(elements, count, width, tag):
    image, result = traced(elements)
    found = strokes_of(result.svg)
    assert len(found) == count, result.svg
    assert result.strokes == count and result.paths == count
    for f in found:
        assert f["fill"] == "none" and f["stroke"].startswith("#")
        assert abs(float(f["stroke-width"]) - width) < 0.6, f
    assert found[0]["tag"] == tag
    # the trace as it is (not refined) draws the picture closely
    assert psnr(rendered(result.svg), image[..., :3]) > 24


def test_a_stub_shorter_than_its_width_is_kept():
    """A line half its width long on a frame (Tabler's `M18 4l0 1` over a square) thins to
    nothing past the frame's own centerline; its ink, which no stroke drew, gets a dot."""
    image, result = traced('<rect x="40" y="50" width="48" height="40" stroke-width="10"/>'
                           '<path d="M64 45 V50" stroke-width="10"/>')
    starts = [tuple(float(v) for v in re.match(r"M\s*([-\d.]+)[ ,]([-\d.]+)", f["d"]).groups())
              for f in strokes_of(result.svg) if f["tag"] == "path"]
    assert any(abs(x - 64) < 2 and abs(y - 44) < 2 for x, y in starts), result.svg


def test_a_closed_outline_closes_and_an_open_line_does_not():
    _, rect = traced('<rect x="25" y="30" width="80" height="60" stroke-width="5"/>')
    _, line = traced('<path d="M20 30 L108 90" stroke-width="8"/>')
    assert strokes_of(rect.svg)[0]["d"].rstrip().lower().endswith("z")
    assert not strokes_of(line.svg)[0]["d"].rstrip().lower().endswith("z")


def test_lines_of_two_colours_are_two_inks():
    image = drawn('<path d="M20 30 H108" stroke-width="6" stroke="#c02020"/>'
                  '<path d="M20 90 H108" stroke-width="6" stroke="#2040c0"/>')
    result = trace_image(image, TraceSettings.defaults(style="strokes"))
    colours = sorted(f["stroke"] for f in strokes_of(result.svg))
    assert len(colours) == 2
    reds = [int(c[1:3], 16) for c in colours]
    assert max(reds) > 150 and min(reds) < 80


def test_centerlines_join_straight_through_a_crossing():
    mask = np.zeros((100, 100), bool)
    mask[47:54, 10:90] = True
    mask[10:90, 47:54] = True
    radius = cv2.distanceTransform(mask.astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    chains = centerlines(mask, radius)
    assert len(chains) == 2  # an X of two lines, not four arms
    for c in chains:
        span = np.ptp(c.points, axis=0)
        assert max(span) > 60 and min(span) < 4


def test_a_fat_x_with_short_arms_keeps_both_lines():
    # Tabler's "x" badge at 256 px: two crossing lines of 2 widths' length, 21 px wide.
    # Zhang-Suen thinning leaves one diagonal (the other's arms erode away); Guo-Hall's
    # skeleton keeps both, and the piece is strokes, not fills
    elements = '<path d="M100 100 L142.67 142.67 M142.67 100 L100 142.67" stroke-width="21.33"/>'
    image = drawn(elements, 256)
    mask = image[..., 0] < 0.5
    radius = cv2.distanceTransform(mask.astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    assert len(centerlines(mask, radius)) == 1  # (what made the case)
    assert len(centerlines(mask, radius, "guo-hall")) == 2
    with warnings.catch_warnings():
        warnings.simplefilter("error", VecfitWarning)  # line work: no fallback warning
        result = trace_image(image, TraceSettings.defaults(style="strokes"))
    assert len(strokes_of(result.svg)) == 2, result.svg
    assert psnr(rendered(result.svg, 256), image[..., :3]) > 24


def test_a_line_shorter_than_its_width_is_a_line_not_a_dot():
    # a 10.7 px line 21.3 px wide (Tabler's "M12 17l0 -1" at 256 px): its skeleton is a
    # pixel or two, which made it a dot, and its ink, under the strokes' 85%, fills
    image = drawn('<path d="M128 122.67 V133.33" stroke-width="21.33"/>', 256)
    with warnings.catch_warnings():
        warnings.simplefilter("error", VecfitWarning)
        result = trace_image(image, TraceSettings.defaults(style="strokes"))
    (found,) = strokes_of(result.svg)
    numbers = [float(v) for v in re.findall(r"-?\d*\.?\d+", found["d"])]
    assert "h0" not in found["d"] and "v0" not in found["d"]
    assert max(abs(v) for v in numbers[2:]) > 6, found["d"]  # a line of about its length
    assert psnr(rendered(result.svg, 256), image[..., :3]) > 28


def test_fills_is_todays_trace_byte_for_byte():
    # the SHA-256 of main's trace of this picture (before --style existed; path text in its
    # shortest form since the node pass: the same points; concave corners through the
    # pixel corner, pieces tucked under their surrounding colour and grown under what
    # covers them since session 17; without an XML declaration since session 20: with it
    # the hash is 8d36757f..., the same as before)
    img = np.ones((96, 128, 3), np.float32)
    cv2.circle(img, (40, 50), 25, (0.8, 0.2, 0.1), -1, cv2.LINE_AA)
    cv2.line(img, (10, 10), (120, 80), (0.1, 0.1, 0.6), 5, cv2.LINE_AA)
    cv2.rectangle(img, (70, 20), (110, 60), (0.2, 0.7, 0.3), 3, cv2.LINE_AA)
    for settings in (None, TraceSettings.defaults(style="fills")):
        svg = trace_image(img, settings).svg
        assert hashlib.sha256(svg.encode()).hexdigest() == \
            "32723ed708f769979226759731daeaffd06c76c509d6f30b75cf1cf281ca9a07"


def test_thick_shapes_fall_back_to_fills_with_a_warning():
    image = drawn('<circle cx="64" cy="64" r="30" fill="#202020" stroke="none"/>'
                  '<path d="M10 120 H118" stroke-width="4"/>')
    with pytest.warns(VecfitWarning, match="not line work"):
        result = trace_image(image, TraceSettings.defaults(style="strokes"))
    found = strokes_of(result.svg)
    filled = [f for f in found if f.get("fill", "#") != "none"]
    stroked = [f for f in found if f.get("fill") == "none"]
    assert len(filled) >= 1 and len(stroked) == 1
    assert psnr(rendered(result.svg), image[..., :3]) > 24


def test_no_line_work_gives_the_fills_trace_and_a_warning():
    image = np.ones((64, 64, 4), np.float32)
    image[16:48, 16:48, :3] = (0.2, 0.3, 0.8)  # a block, far thicker than max_stroke
    with pytest.warns(VecfitWarning, match="no line work"):
        result = trace_image(image, TraceSettings.defaults(style="strokes", max_stroke=0.1))
    assert result.paths >= 1 and "<rect" in result.svg or "<path" in result.svg
    assert psnr(rendered(result.svg, 64), image[..., :3]) > 30
    with pytest.warns(VecfitWarning, match="no line work"):
        blank = trace_image(np.ones((32, 32, 3), np.float32), TraceSettings.defaults(style="strokes"))
    assert "<rect" in blank.svg  # never an empty file


@pytest.mark.parametrize("changes, word", [({"style": "lines"}, "style"), ({"max_stroke": 0.0}, "max_stroke"),
                                           ({"max_stroke": 2.0}, "max_stroke"), ({"max_line": 0.0}, "max_line")])
def test_bad_style_settings_are_refused(changes, word):
    with pytest.raises(VecfitError, match=word):
        trace_image(np.ones((16, 16, 3), np.float32), TraceSettings.defaults(**changes))


def test_mixed_draws_areas_as_fills_under_their_outlines_without_a_warning():
    image = drawn('<circle cx="64" cy="64" r="40" fill="#f0c020" stroke-width="5"/>'
                  '<path d="M44 80 Q64 96 84 80" stroke-width="4"/>')
    with warnings.catch_warnings():
        warnings.simplefilter("error", VecfitWarning)
        result = trace_image(image, TraceSettings.defaults(style="mixed"))
    found = strokes_of(result.svg)
    filled = [f for f in found if f.get("fill", "#") != "none"]
    stroked = [f for f in found if f.get("fill") == "none"]
    assert len(stroked) == 2 and len(filled) >= 1
    yellow = [f for f in filled if f["fill"].lower().startswith("#f")]
    assert yellow, result.svg  # the face, run on under its outline
    assert psnr(rendered(result.svg), image[..., :3]) > 24


@pytest.mark.slow
def test_mixed_keeps_an_emojis_face_and_mouth_as_fills():
    # an emoji as OpenMoji draws them, at 256 px: a face whose skeleton runs mostly through
    # its narrow parts round the eyes and mouth (its median width under max_stroke, so it
    # was stroked 30-100 px wide), and a mouth of uneven width (a crescent, stroked at its
    # median width with gaps either side)
    size = 256
    image = drawn('<circle cx="128" cy="128" r="94" fill="#fcea2b" stroke-width="7"/>'
                  '<circle cx="92" cy="108" r="11" fill="#202020"/><circle cx="164" cy="108" r="11" fill="#202020"/>'
                  '<path d="M62 160 Q128 182 194 160 Q180 222 128 224 Q76 222 62 160 Z" fill="#ea5a47" stroke-width="7"/>',
                  size)
    result = trace_image(image, TraceSettings.defaults(style="mixed"))
    found = strokes_of(result.svg)
    stroked = [f for f in found if f.get("fill") == "none"]
    filled = {f["fill"].lower() for f in found if f.get("fill", "none") != "none"}
    assert stroked and max(float(f["stroke-width"]) for f in stroked) < 12, result.svg  # the outlines, 7 px
    assert {f["stroke"].lower() for f in stroked} == {"#202020"}, result.svg
    assert any(c.startswith("#f") for c in filled) and any(c.startswith("#e") for c in filled), result.svg
    assert psnr(rendered(result.svg, size), image[..., :3]) > 24


def test_a_round_dot_comes_back_as_a_dot_stroke():
    # a Tabler dot ("M12 8v.01", round caps): its ink is a disc whose skeleton thins to
    # nothing; it was traced as a filled circle, the icon then not strokes only
    _, result = traced('<path d="M40.3 60.6 v.01" stroke-width="12"/><path d="M60 30 H110" stroke-width="5"/>')
    found = strokes_of(result.svg)
    assert all(f.get("fill") == "none" and "stroke" in f for f in found) and len(found) == 2
    dot = max(found, key=lambda f: float(f["stroke-width"]))
    assert abs(float(dot["stroke-width"]) - 12) < 1.0
    x, y = (float(v) for v in re.match(r"M([\d.]+) ([\d.]+)", dot["d"]).groups())
    assert abs(x - 40.3) < 0.75 and abs(y - 60.6) < 0.75


def test_a_dot_twice_as_wide_as_the_widest_line_is_still_a_dot_stroke():
    # Tabler draws its dots twice as wide as its lines (a circle of radius 1 stroked 2 wide):
    # with lines near max_stroke, the dot is past it, yet a dot, not an area to fill
    widest = TraceSettings.defaults().max_stroke * SIZE
    line, dot_width = 0.8 * widest, 1.6 * widest
    _, result = traced(f'<path d="M40 60 v.01" stroke-width="{dot_width:.2f}"/>'
                       f'<path d="M75 20 V108" stroke-width="{line:.2f}"/>')
    found = strokes_of(result.svg)
    assert all(f.get("fill") == "none" and "stroke" in f for f in found) and len(found) == 2
    dot = max(found, key=lambda f: float(f["stroke-width"]))
    assert abs(float(dot["stroke-width"]) - dot_width) < 1.5


# ----------------------------------------------------------------------------- junctions

def _chains_of(elements: str, size: int = SIZE):
    image = drawn(elements, size)
    mask = image[..., 0] < 0.5
    radius = cv2.distanceTransform(mask.astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    return centerlines(mask, radius)


def _off_line(points: np.ndarray, a, b) -> np.ndarray:
    """Each point's distance from the line through a and b."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = (b - a) / np.hypot(*(b - a))
    return np.abs((points - a) @ np.array([-d[1], d[0]]))


def test_a_ts_bar_runs_straight_through_and_its_stem_ends_on_it():
    # the skeleton of a T dips towards the stem where the lines meet, and the stem's end
    # stopped at the junction pixels' mean: the junction is rebuilt from the arms' lines
    chains = _chains_of('<path d="M20 40 H108 M64 40 V110" stroke-width="12"/>')
    assert len(chains) == 2  # the bar one path, the stem another: no spur
    bar = max(chains, key=lambda c: np.ptp(c.points[:, 0]))
    stem = min(chains, key=lambda c: np.ptp(c.points[:, 0]))
    assert _off_line(bar.points, (20, 40), (108, 40)).max() < 1.0
    assert _off_line(stem.points, (64, 40), (64, 110)).max() < 1.0
    top = stem.points[np.argmin(stem.points[:, 1])]
    assert np.hypot(*(top - (64, 40))) < 1.5, top


def test_chains_carry_the_crossings_they_pass_and_not_a_ts_junction():
    # a plus: both lines pass one crossing at (64, 64); a T: its bar may bend where the
    # stem meets it (a book's spine), so its junction is no crossing
    for chain in _chains_of('<path d="M20 64 H108 M64 20 V108" stroke-width="12"/>'):
        assert chain.crossings.shape == (1, 3)
        assert np.hypot(*(chain.crossings[0, :2] - (64, 64))) < 2.0
        assert 6 <= chain.crossings[0, 2] <= 10  # the half width there (6), and more where lines cross
    for chain in _chains_of('<path d="M20 40 H108 M64 40 V110" stroke-width="12"/>'):
        assert chain.crossings.shape == (0, 3)


def test_a_crossing_at_45_degrees_that_thinning_splits_is_one_crossing():
    # thinning splits a slash over a line into two forks 28 px apart (each a T): together
    # they are the crossing, and the horizontal line (through both) carries both
    chains = _chains_of('<path d="M40 40 L216 216" stroke-width="21.33"/><path d="M30 150 H226" '
                        'stroke-width="21.33"/>', 256)
    across = max(chains, key=lambda c: np.ptp(c.points[:, 0]) - np.ptp(c.points[:, 1]))
    assert len(across.crossings) == 2
    assert np.abs(across.crossings[:, :2].mean(0) - (150, 150)).max() < 3


def test_a_slash_across_a_line_comes_back_with_fewer_segments():
    # the line's centerline wobbles where the slash crosses it: the stretch through the
    # crossing is one line (14 segments before, in 3 paths)
    image = drawn('<path d="M40 40 L216 216" stroke-width="21.33"/><path d="M30 150 H226" stroke-width="21.33"/>',
                  256)
    with warnings.catch_warnings():
        warnings.simplefilter("error", VecfitWarning)
        result = trace_image(image, TraceSettings.defaults(style="strokes"))
    assert result.segments <= 11, result.svg
    assert psnr(rendered(result.svg, 256), image[..., :3]) > 20


def test_a_plus_sign_is_two_straight_lines_crossing_where_drawn():
    chains = _chains_of('<path d="M20 64 H108 M64 20 V108" stroke-width="12"/>')
    assert len(chains) == 2
    across = max(chains, key=lambda c: np.ptp(c.points[:, 0]))
    down = max(chains, key=lambda c: np.ptp(c.points[:, 1]))
    assert _off_line(across.points, (20, 64), (108, 64)).max() < 1.0
    assert _off_line(down.points, (64, 20), (64, 108)).max() < 1.0


def test_a_traced_t_and_l_meet_where_drawn():
    # the traced strokes (not refined): the T's stem ends on the bar's centreline, the L's
    # corner is where its two lines meet
    _, result = traced('<path d="M20 40 H108 M64 40 V110" stroke-width="12"/>'
                       '<path d="M16 70 V118 H50" stroke-width="8"/>')
    found = strokes_of(result.svg)
    assert len(found) == 3, result.svg
    nodes = []
    for f in found:
        nodes += _absolute_nodes(f["d"])
    nodes = np.array(nodes)
    assert np.hypot(*(nodes - (64, 40)).T).min() < 1.5  # the stem's end on the bar
    assert np.hypot(*(nodes - (16, 118)).T).min() < 1.5  # the L's corner


def _absolute_nodes(d: str) -> list[tuple[float, float]]:
    """The on-curve points of a path of M, l, c, h, v commands (relative after the M)."""
    tokens = re.findall(r"[MmLlCcHhVvZz]|-?\d*\.?\d+(?:e-?\d+)?", d)
    out, cur, cmd, nums = [], np.zeros(2), None, []

    def flush():
        nonlocal cur
        if cmd is None:
            return
        step = {"M": 2, "m": 2, "L": 2, "l": 2, "C": 6, "c": 6, "H": 1, "h": 1, "V": 1, "v": 1}.get(cmd, 0)
        for k in range(0, len(nums), step or 1):
            if not step:
                break
            v = nums[k:k + step]
            if cmd in "Mm":
                cur = np.array(v) + (cur if cmd == "m" and out else 0)
            elif cmd in "Ll":
                cur = np.array(v) + (cur if cmd == "l" else 0)
            elif cmd in "Cc":
                cur = np.array(v[4:]) + (cur if cmd == "c" else 0)
            elif cmd in "Hh":
                cur = np.array([v[0] + (cur[0] if cmd == "h" else 0), cur[1]])
            elif cmd in "Vv":
                cur = np.array([cur[0], v[0] + (cur[1] if cmd == "v" else 0)])
            out.append(tuple(cur))
    for t in tokens:
        if t.isalpha():
            flush()
            cmd, nums = t, []
        else:
            nums.append(float(t))
    flush()
    return out


def test_a_wide_lines_acute_corners_come_back_at_their_apexes():
    # Tabler's "zzz" at 256 px (lines 21.3 px wide, corners of 37 degrees): thinning forks
    # short of an acute corner by about a half width (and pruning takes the spur), so the
    # corner was traced several pixels inside the drawn one; its sides are now judged from
    # beyond the inner corner
    s = 256 / 24
    zig = [(4 * s, 12 * s), (10 * s, 12 * s), (4 * s, 20 * s), (10 * s, 20 * s)]
    image = drawn('<path d="M{} {} H{} L{} {} H{}" stroke-width="{}"/>'.format(
        zig[0][0], zig[0][1], zig[1][0], zig[2][0], zig[2][1], zig[3][0], 2 * s), 256)
    with warnings.catch_warnings():
        warnings.simplefilter("error", VecfitWarning)
        result = trace_image(image, TraceSettings.defaults(style="strokes"))
    (found,) = strokes_of(result.svg)
    nodes = np.array(_absolute_nodes(found["d"]))
    for corner in zig[1:3]:
        assert np.hypot(*(nodes - corner).T).min() < 1.5, (corner, found["d"])
    assert psnr(rendered(result.svg, 256), image[..., :3]) > 30


def test_a_dark_grey_dot_beside_black_lines_keeps_its_own_colour():
    """Inks within SAME_INK are one ink (#1d1d1b and black: 11 CIELAB units), but the
    strokes' colours are not refined: a piece whose own colour lies off its ink's is drawn
    in its own (an emoji's eyes), while pieces of the ink's colour keep it exactly."""
    image = drawn('<path d="M10 20 H118" stroke="#000000" stroke-width="6"/>'
                  '<path d="M10 110 H118" stroke="#000000" stroke-width="6"/>'
                  '<path d="M64 64 h0.01" stroke="#1d1d1b" stroke-width="16"/>')
    colours = sorted(s["stroke"] for s in strokes_of(trace_image(image, TraceSettings.defaults(style="strokes")).svg))
    assert colours == ["#000000", "#000000", "#1d1d1b"]


def test_mixed_leaves_slivers_thinner_than_a_line_to_the_fills():
    """A 1-px sliver of an area's colour (where an outline crosses the area) is no line
    work with --style mixed: the fills draw it; the outlines are strokes."""
    image = drawn('<rect x="20" y="20" width="88" height="88" fill="#e04030" stroke="none"/>'
                  '<path d="M20 64 H108" stroke="#000000" stroke-width="4"/>'
                  '<path d="M20 12 H108" stroke="#e04030" stroke-width="1"/>')
    found = strokes_of(trace_image(image, TraceSettings.defaults(style="mixed")).svg)
    stroked = [s for s in found if s.get("fill") == "none"]
    assert stroked and all(float(s["stroke-width"]) >= 2 for s in stroked)
