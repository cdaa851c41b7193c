"""A designer's stacking in flat-art traces: pieces tucked under the colour that surrounds
them (vecfit/initial/tracer/tucked.py), concave corners kept sharp (outlines.crack_outlines),
and no shape in the backdrop's colour laid straight over the backdrop."""
from __future__ import annotations

import re

import numpy as np

from vecfit.initial.tracer import TraceSettings, trace_image
from vecfit.initial.tracer.outlines import crack_outlines
from vecfit.initial.tracer.tucked import tucked_hosts

from test_trace import coverage, paint, psnr, render

W, H = 200, 150
BLUE, WHITE, RED = (0.0, 0.32, 0.61), (1.0, 1.0, 1.0), (0.86, 0.12, 0.21)


def cross(x0, width, y0, height):
    return lambda x, y: ((x > x0) & (x < x0 + width)) | ((y > y0) & (y < y0 + height))


def flag(offset=0.36):
    """Iceland's flag: a red cross on a white cross on blue, edges off the pixel grid."""
    layers = [(coverage(cross(55 + offset, 30, 60 + offset, 30), W, H), WHITE),
              (coverage(cross(62.5 + offset, 15, 67.5 + offset, 15), W, H), RED)]
    return paint(layers, W, H, background=BLUE)


def test_a_concave_corner_is_traced_through_the_pixel_corner():
    mask = np.zeros((100, 120), bool)
    mask[:, 40:60] = True
    mask[30:50, :] = True
    outline = crack_outlines(mask)[0]
    steps = np.abs(np.diff(np.vstack([outline, outline[:1]]), axis=0))
    assert (steps.min(axis=1) == 0).all()  # every step along a pixel edge: no diagonal
    for corner in ([40, 30], [60, 30], [40, 50], [60, 50]):  # the four concave corners
        assert (np.abs(outline - corner).sum(axis=1) == 0).any()


def test_a_piece_mostly_against_one_colour_is_tucked_under_it():
    labels = np.zeros((40, 60), np.int64)  # region 0 all round
    labels[10:20, 10:20] = 1               # an island of 1: enclosed by 0
    labels[30:40, 25:35] = 2               # 2 at the bottom edge: 10 of its 40 edges on the canvas's
    labels[0:5, 50:60] = 3                 # 3 in a corner: half of its edges on the canvas's
    host = tucked_hosts(labels, 4)
    assert (host[labels == 1] == 0).all() and (host[labels == 2] == 0).all()
    assert (host[labels == 3] == -1).all() and (host[labels == 0] == -1).all()


def test_a_flag_is_traced_as_a_designer_stacks_it(tmp_path):
    image = flag()
    result = trace_image(image, TraceSettings.defaults(paths=3))
    paths = re.findall(r'<path d="([^"]*)" fill="(#[0-9a-f]{6})"', result.svg)
    # the white cross whole, under the red one: one outline of 12 lines each, and nothing
    # in the backdrop's blue over the backdrop
    assert len(paths) == 2 and paths[0][1] == "#ffffff" and int(paths[1][1][1:3], 16) > 200
    for d, _ in paths:
        assert d.count("m") + d.count("M") == 1 and not re.search(r"[cCsSqQ]", d)
        assert len(re.findall(r"[hvlHVL]", d)) == 12
    out = render(result, W, H, tmp_path)
    assert psnr(image[..., :3], out[..., :3]) >= 33  # (not refined)


def test_the_page_cut_in_two_stays_page(tmp_path):
    # logos-052: a ring reaching the canvas's edges cuts the white page into pieces; at a
    # budget of one path they were merged with the ring into one grey shape (10.7 dB).
    # Here a bar from top to bottom: the page's right-hand piece is page too.
    bar = coverage(lambda x, y: (x > 120.3) & (x < 140.3) & (y > -1), W, H)
    image = paint([(bar, (0.0, 0.0, 0.0))], W, H, background=(1.0, 1.0, 1.0))
    result = trace_image(image, TraceSettings.defaults(paths=1))
    backdrop = next(line for line in result.svg.split("\n") if 'id="vecfit-background"' in line)
    assert 'fill="#ffffff"' in backdrop
    assert re.findall(r'<(?:path|rect) (?!id)[^>]*fill="(#[0-9a-f]{6})"', result.svg) == ["#000000"]
    out = render(result, W, H, tmp_path)
    assert psnr(image[..., :3], out[..., :3]) >= 30


def test_a_stripe_runs_on_under_the_emblem_over_it(tmp_path):
    # Myanmar's flag (flags-000): stripes with a star over them; each stripe is a
    # rectangle under the star, not a rectangle with the star's notch cut in it
    # (tucked.hull_filled). Here a disc over a green and a red stripe.
    layers = [(coverage(lambda x, y: (x > -1) & (y > 50.3) & (y < 100.3), W, H), (0.2, 0.7, 0.2)),
              (coverage(lambda x, y: (x > -1) & (y > 100.3), W, H), (0.9, 0.15, 0.2)),
              (coverage(lambda x, y: np.hypot(x - 100, y - 80) < 35, W, H), (1.0, 1.0, 1.0))]
    image = paint(layers, W, H, background=(1.0, 0.8, 0.0))
    result = trace_image(image, TraceSettings.defaults(paths=3))
    written = [line for line in result.svg.split("\n")
               if line.startswith(("<path", "<rect", "<circle", "<ellipse")) and "vecfit-background" not in line]
    assert written[0].startswith("<rect")  # the red stripe, whole under the disc
    # the green one runs on under the disc in one piece (its hidden edge not quite
    # straight: the sub-pixel placement reads no blend under the disc)
    green = re.search(r' d="([^"]*)"', written[1]).group(1)
    assert green.lower().count("m") == 1 and len(re.findall(r"[a-zA-Z]", green)) <= 9
    assert written[2].startswith("<circle") or written[2].startswith("<ellipse")  # the disc, on top
    out = render(result, W, H, tmp_path)
    assert psnr(image[..., :3], out[..., :3]) >= 30
