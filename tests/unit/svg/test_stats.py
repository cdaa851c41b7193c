"""vecfit.svg.stats.design_stats: the counts a designer sees, on small SVGs whose answers
are known, and on vecfit's own traces (whose tracer counts them too)."""
from __future__ import annotations

import gzip

import numpy as np
import pytest

from vecfit.svg.stats import design_stats, path_data_segments


def svg(body: str, size: int = 100) -> str:
    return f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" viewBox="0 0 {size} {size}">' \
           f'{body}</svg>'


# ------------------------------------------------------------------- path data

@pytest.mark.parametrize("d, lines, curves", [
    ("M0 0 L10 0 L10 10 Z", 3, 0),                      # Z draws the third side
    ("M0 0 L10 0 L10 10 L0 0 Z", 3, 0),                 # already back: Z draws nothing
    ("m0 0 10 0 v10 h-10 z", 4, 0),                     # implicit lineto, relative H and V
    ("M0 0 C1 1 2 2 3 3 S5 5 6 6 Q7 7 8 8 T9 9 A5 5 0 0 1 20 20 Z", 1, 5),
    ("M0 0 A5 5 0 0 1 0 0 L1 1", 1, 0),                 # an arc to the current point draws nothing
    ("M0 0 a5 5 0 0110 0", 0, 1),                       # flags run into the end point
    ("M0 0 a5,5 0 1,1 10,0 a5 5 0 0 1 -10 0z", 0, 2),   # two half circles: back at the start
    ("M0 0 L10 0 L5", 1, 0),                            # read up to the first error
    ("L10 0 M0 0 L5 5", 0, 0),                          # no moveto first: nothing is drawn
    ("M0 0 L10 0 Z L5 5 Z M20 20 L30 30", 5, 0),        # after Z, a lineto starts at the start
])
def test_path_data_segments(d, lines, curves):
    assert path_data_segments(d) == (lines, curves)


# ----------------------------------------------------------------- elements

def test_each_kind_of_element_counts_its_segments_as_written():
    stats = design_stats(svg(
        '<path d="M0 0 C10 0 10 10 0 10 Z"/>'                 # 1 curve, 1 line (Z)
        '<rect x="1" y="1" width="10" height="10"/>'          # 4 lines
        '<rect x="1" y="1" width="10" height="10" rx="2"/>'   # 4 lines, 4 arcs
        '<rect x="1" y="1" width="20" height="10" rx="10"/>'  # a pill: arcs only (ry = rx, clamped)
        '<circle cx="5" cy="5" r="3"/>'                       # 4 arcs
        '<ellipse cx="5" cy="5" rx="3" ry="2"/>'              # 4 arcs
        '<line x1="0" y1="0" x2="5" y2="5" stroke="black"/>'  # 1 line
        '<polyline points="0 0 5 0 5 5" stroke="black" fill="none"/>'  # 2 lines
        '<polygon points="0 0 5 0 5 5 0 5"/>'                 # 4 lines
        '<polygon points="0 0 5 0 5 5 0 0"/>'))               # 3: the closing side has no length
    assert stats["paths"] == 10
    assert stats["primitives"] == 5
    assert stats["lines"] == 1 + 4 + 4 + 0 + 0 + 0 + 1 + 2 + 4 + 3
    assert stats["curves"] == 1 + 0 + 4 + 4 + 4 + 4
    assert stats["segments"] == stats["lines"] + stats["curves"]


def test_only_what_is_drawn_counts():
    stats = design_stats(svg(
        '<defs><path id="leaf" d="M0 0 L10 0 L5 5 Z" fill="green"/>'
        '<clipPath id="c"><rect width="50" height="50"/></clipPath></defs>'
        '<use href="#leaf"/><use href="#leaf" x="20"/>'       # two instances: 2 paths, 6 lines
        '<g clip-path="url(#c)"><circle cx="5" cy="5" r="3" fill="red"/></g>'  # the clip's rect is not drawn
        '<rect width="5" height="5" fill="none"/>'            # neither fill nor stroke
        '<rect width="5" height="5" display="none"/>'
        '<rect width="5" height="5" visibility="hidden"/>'
        '<rect width="5" height="5" opacity="0"/>'))
    assert stats["paths"] == 3
    assert (stats["lines"], stats["curves"], stats["primitives"]) == (6, 4, 1)


def test_vecfits_background_rect_is_reported_apart():
    stats = design_stats(svg('<rect id="vecfit-background" x="0" y="0" width="100" height="100" fill="#fafafa"/>'
                             '<path d="M0 0 L10 0 L5 5 Z" fill="#101010"/>'))
    assert stats["background"] is True
    assert (stats["paths"], stats["segments"], stats["primitives"]) == (1, 3, 0)
    assert stats["colours"] == 2
    assert design_stats(svg('<path d="M0 0 L10 0 L5 5 Z"/>'))["background"] is False


# ------------------------------------------------------------------- paints

def test_colours_are_distinct_paints_of_fills_strokes_and_stops():
    stats = design_stats(svg(
        '<defs><linearGradient id="g"><stop offset="0" stop-color="#00ff00"/>'
        '<stop offset="1" stop-color="#0000ff"/></linearGradient></defs>'
        '<rect width="5" height="5" fill="#ff0000" stroke="red"/>'   # one colour, twice
        '<rect width="5" height="5" fill="url(#g)"/>'
        '<rect width="5" height="5" fill="currentColor" color="#123456"/>'
        '<rect width="5" height="5" fill="#00FF00"/>'))              # the stop's colour again
    assert stats["colours"] == 4


def test_translucent_paints_count_elements_drawn_with_alpha_below_one():
    stats = design_stats(svg(
        '<defs><linearGradient id="g"><stop offset="0" stop-color="red"/>'
        '<stop offset="1" stop-color="blue" stop-opacity="0.5"/></linearGradient></defs>'
        '<rect width="5" height="5" fill="red" fill-opacity="0.5"/>'              # 1
        '<rect width="5" height="5" fill="red" opacity="0.5"/>'                   # 2
        '<rect width="5" height="5" fill="#ff000080"/>'                           # 3: the colour's alpha
        '<rect width="5" height="5" fill="none" stroke="red" stroke-opacity="0.3"/>'  # 4
        '<rect width="5" height="5" fill="url(#g)"/>'                             # 5: a stop's opacity
        '<rect width="5" height="5" fill="red" stroke="blue" fill-opacity="0.9" stroke-opacity="0.2"/>'  # 6, once
        '<rect width="5" height="5" fill="none" fill-opacity="0.5" stroke="red"/>'  # its fill is not drawn
        '<g opacity="0.5"><rect width="5" height="5" fill="red"/></g>'            # a group's opacity
        '<rect width="5" height="5" fill="red"/>'))
    assert stats["paths"] == 9
    assert stats["translucent_paints"] == 6


# --------------------------------------------------- crossings, bytes, inputs

def test_crossed_outlines_counts_filled_outlines_crossing_themselves():
    stats = design_stats(svg('<path d="M0 0 L20 20 L20 0 L0 20 Z"/>'                     # a bow tie
                             '<path d="M30 0 L50 20 L50 0 L30 20 Z" fill="none" stroke="black"/>'  # stroked only
                             '<path d="M60 0 L80 0 L80 20 L60 20 Z"/>'                  # a square
                             '<polygon points="50,60 62,95 31,73 69,73 38,95"/>'))      # a star, drawn crossed
    assert stats["crossed_outlines"] == 2


def test_bytes_and_inputs(tmp_path):
    text = svg('<path d="M0 0 L10 0 L5 5 Z" fill="red"/>' + "<!-- padding -->" * 50)
    data = text.encode("utf-8")
    file = tmp_path / "a.svg"
    file.write_bytes(data)
    stats = design_stats(data)
    assert stats["bytes"] == len(data)
    assert stats["gzip_bytes"] == len(gzip.compress(data, compresslevel=9, mtime=0)) < len(data)
    assert design_stats(text) == design_stats(file) == design_stats(str(file)) == stats
    (tmp_path / "a.svgz").write_bytes(gzip.compress(data))
    assert design_stats(tmp_path / "a.svgz") == stats


def test_a_trace_is_counted_as_its_tracer_counts_it():
    """The tracer counts its own paths, segments (a rect's 4 sides, each cubic) and fill
    colours: the file must say the same."""
    skimage_data = pytest.importorskip("skimage.data")
    from PIL import Image

    from vecfit.initial.tracer import TraceSettings, trace_image

    image = np.asarray(Image.fromarray(skimage_data.chelsea()).resize((128, 96)), np.float32) / 255
    for paths in (16, 64):
        traced = trace_image(image, TraceSettings.defaults(paths=paths))
        stats = design_stats(traced.svg)
        assert (stats["paths"], stats["segments"], stats["colours"]) == (traced.paths, traced.segments, traced.colors)
        assert stats["translucent_paints"] == 0 and stats["curves"] > stats["lines"]
