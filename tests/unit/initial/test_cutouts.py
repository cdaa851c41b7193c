"""Cut-outs (vecfit/initial/tracer/cutouts.py): a stacked drawing rewritten as pieces that
do not overlap, meet edge to edge, keep the drawing's own curves and look the same."""
import warnings

import numpy as np
import pytest

from vecfit.errors import VecfitError
from vecfit.export import scene_of_svg
from vecfit.initial.tracer.cutouts import cut_out
from vecfit.renderer.forward import render_numpy
from vecfit.scene.outline import f64, flattened, subpaths, transformed
from vecfit.scene.partition import winding_samples
from vecfit.scene.placement import shape_matrices
from vecfit.svg.stats import design_stats

W, H = 96, 80
STACKED = f"""<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}">
<rect x="-4" y="-4" width="{W + 8}" height="{H + 8}" fill="#f1faee"/>
<rect x="10.3" y="12.6" width="50" height="40" fill="#1d3557"/>
<circle cx="55.2" cy="47.7" r="22.4" fill="#e63946"/>
<path d="M20 70 C 30 50 60 60 88 8 L 90 30 Z" fill="#2a9d8f"/>
</svg>"""


def scene(svg):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return scene_of_svg(svg)[0]


def coverage(svg, scale=8):
    """[shapes, H*scale, W*scale] bool: which samples each filled shape covers."""
    s = scene(svg)
    out = []
    for shape, m in zip(s.shapes, np.asarray(shape_matrices(s, W, H), np.float64)):
        if shape.fill is None:
            continue
        polygons = [flattened(sp, 0.01) for sp in transformed(subpaths(shape.geometry), m)]
        out.append(winding_samples(polygons, shape.fill_rule == "evenodd", (0, H * scale, 0, W * scale), scale))
    return np.array(out)


def rgb(svg, mode="mc"):
    """Over white. Monte Carlo samples each point of a pixel once for all shapes (no
    seams); analytic coverage composites each shape's share on its own, as resvg does."""
    image = render_numpy(scene(svg), W, H, samples=4 if mode == "mc" else 1, seed=0, mode=mode)
    a = image[..., 3:]
    return image[..., :3] * a + (1 - a)  # over white


@pytest.fixture(scope="module")
def cut():
    return cut_out(STACKED.encode(), (W, H))


def test_pieces_do_not_overlap_and_cover_what_the_drawing_covers(cut):
    svg, report = cut
    covered = coverage(svg)
    overlap = (covered.sum(0) > 1).sum() / 64  # px²
    assert overlap < 1.0
    stacked = coverage(STACKED.encode()).any(0)
    assert (covered.any(0) != stacked).sum() / 64 < 1.0
    assert report.pieces == len(covered) == 4


def test_boundaries_are_the_drawing_s_own_curves(cut):
    svg, report = cut
    assert report.followed >= report.chains - 4  # all but the canvas's edges
    # the circle's cut is its own four quarter arcs, cut where the others cross it: few
    # segments, not a refitted staircase
    assert design_stats(svg)["segments"] <= 2 * design_stats(STACKED)["segments"] + 12
    assert design_stats(svg)["crossed_outlines"] == 0


def test_the_cut_looks_like_the_stacked_drawing_away_from_seams(cut):
    svg, _ = cut
    a, b = rgb(STACKED.encode()), rgb(svg)
    differ = np.abs(a - b).max(2)
    assert np.median(differ) < 1e-3
    assert (differ > 0.02).mean() < 0.05  # edges only: each piece anti-aliased on its own


def test_the_gap_filler_closes_the_seams():
    plain, _ = cut_out(STACKED.encode(), (W, H))
    filled, report = cut_out(STACKED.encode(), (W, H), gap_filler=True)
    reference = rgb(STACKED.encode(), "analytic")
    error = lambda svg: float(((rgb(svg, "analytic") - reference) ** 2).mean())  # noqa: E731
    assert error(filled) < 0.5 * error(plain)
    assert report.gap_filler > 0
    text = filled.decode()
    assert text.index('fill="none"') < text.index('fill="#f1faee"')  # under the pieces


def test_a_translucent_shape_is_cut_into_flat_composited_pieces():
    svg = f"""<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}">
    <rect x="0" y="0" width="{W}" height="{H}" fill="#ffffff"/>
    <rect x="20" y="20" width="40" height="40" fill="#ff0000" fill-opacity="0.5"/></svg>""".encode()
    out, report = cut_out(svg, (W, H))
    assert report.pieces == 2
    assert "#ff8080" in out.decode() and "fill-opacity" not in out.decode()


def test_what_cannot_be_cut_is_refused_with_the_reason():
    stroked = STACKED.replace('fill="#e63946"', 'fill="#e63946" stroke="#000"').encode()
    with pytest.raises(VecfitError, match="strokes"):
        cut_out(stroked, (W, H), name="x.svg")
    gradient = STACKED.replace('<rect x="10.3"', '<defs><linearGradient id="g"><stop offset="0"/><stop offset="1" stop-color="#fff"/></linearGradient>'
                               '</defs><rect fill-opacity="1" x="10.3"').replace('fill="#1d3557"', 'fill="url(#g)"')
    with pytest.raises(VecfitError, match="gradient"):
        cut_out(gradient.encode(), (W, H), name="x.svg")


def test_the_file_keeps_its_size_and_view_box():
    svg = STACKED.replace(f'width="{W}" height="{H}" viewBox="0 0 {W} {H}"',
                          f'width="{W / 4}mm" height="{H / 4}mm" viewBox="0 0 {W} {H}"')
    out, _ = cut_out(svg.encode(), (W, H))
    assert f'width="{W / 4}mm"' in out.decode() and f'viewBox="0 0 {W} {H}"' in out.decode()
    assert np.isfinite(f64(scene(out).shapes[0].geometry.points)).all()


def test_a_flat_cubic_past_its_moved_end_becomes_a_line():
    # noto-emoji-040: a chain's end moved back along a straight stretch left its control
    # point 0.16 px past the end, a spike that made the piece's outline cross itself
    from vecfit.initial.tracer.cutouts import _collinear_as_lines
    points = np.array([[130.0, 53.0], [140.19, 52.97], [140.81, 52.97], [141.08, 52.97], [140.92, 52.97],
                       [144.0, 48.9], [156.8, 39.0], [165.0, 34.2]])
    out, degrees = _collinear_as_lines(points, [1, 3, 3], 0.1)
    assert degrees == [1, 1, 3]
    assert np.array_equal(out, points[[0, 1, 4, 5, 6, 7]])
    bulging = points.copy()
    bulging[2, 1] += 0.5  # a real curve stays one
    assert _collinear_as_lines(bulging, [1, 3, 3], 0.1)[1] == [1, 3, 3]


def test_a_piece_with_no_area_is_not_written():
    # a piece whose two chains were laid on the same stretch of an outline: a loop that
    # goes out and back on itself, which the crossing test finds crossed
    from vecfit.initial.tracer.cutouts import _piece_layout
    chain = (np.array([[135.76, 495.7], [136.81, 495.77], [137.86, 495.77], [138.91, 495.85]]), [3])
    layout = _piece_layout([[(0, False), (0, True)]], [chain], lambda p: p, decimals=2, tolerance=0.01,
                           stub=0.05, min_area=1.0)
    assert layout is None
    small = (np.array([[0.0, 0.0], [0.6, 0.0], [0.6, 0.6], [0.0, 0.6], [0.0, 0.0]]), [1, 1, 1, 1])
    kept = _piece_layout([[(0, False)]], [small], lambda p: p, decimals=2, tolerance=0.01, stub=0.05, min_area=1.0)
    assert kept is not None and kept[1] == [1, 1, 1, 1]  # a lone small piece is kept: its neighbours leave it a hole
