"""The SVG reader: SVG files -> Scene (vecfit.svg.read.load_svg) and summarize()."""
from __future__ import annotations

import csv
import math
import time
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import torch

from helpers import need
from vecfit.scene.summary import summarize
from vecfit.errors import SvgError
from vecfit.scene import (Circle, Ellipse, LinearGradient, Path as PathGeometry,
                                   RadialGradient, Rect, Scene, Solid)
from vecfit.svg import VecfitWarning, load_svg
from vecfit.svg.color import parse_color
from vecfit.svg.pathdata import PathDataError, parse_path_data

from shared_data import SHARED
CORPUS = SHARED / "conformance"
DATA = SHARED / "data"
SVG_HEAD = ('<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
            '{attrs}>')


def write(tmp_path, body: str, attrs: str = 'viewBox="0 0 200 200"', name="t.svg") -> Path:
    p = tmp_path / name
    p.write_text(SVG_HEAD.format(attrs=attrs) + body + "</svg>")
    return p


def load(tmp_path, body: str, attrs: str = 'viewBox="0 0 200 200"') -> Scene:
    with warnings.catch_warnings():
        warnings.simplefilter("error", VecfitWarning)  # these snippets are fully supported
        return load_svg(write(tmp_path, body, attrs))


def quiet_load(path) -> Scene:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", VecfitWarning)
        return load_svg(path)


def by_source(scene: Scene, source: str):
    matches = [s for s in scene.shapes if s.source == source]
    assert matches, f"no shape from #{source}"
    return matches[0]


def rgba(paint) -> list[float]:
    assert isinstance(paint, Solid), paint
    return [round(v, 4) for v in paint.color.tolist()]


def hex_rgba(text: str) -> list[float]:
    text = text.lstrip("#")
    return [round(int(text[i:i + 2], 16) / 255, 4) for i in (0, 2, 4)] + [1.0]


def to_canvas(scene: Scene, shape) -> torch.Tensor:
    """Matrix from the shape's own space to root user space (groups applied)."""
    m = shape.transform
    g = shape.group
    while g >= 0:
        m = scene.groups[g].transform @ m
        g = scene.groups[g].parent
    return m


def apply(m: torch.Tensor, xy) -> list[float]:
    p = m @ torch.tensor([xy[0], xy[1], 1.0])
    return [round(float(p[0]), 4), round(float(p[1]), 4)]


def all_tensors(scene: Scene):
    yield scene.view
    for g in scene.groups:
        yield g.transform
        yield g.opacity
    for s in scene.shapes:
        yield from (v for v in vars(s.geometry).values() if isinstance(v, torch.Tensor))
        for paint in (s.fill, s.stroke):
            if paint is not None:
                yield from (v for v in vars(paint).values() if isinstance(v, torch.Tensor))
        yield from (s.stroke_width, s.opacity, s.fill_opacity, s.stroke_opacity, s.transform)


def segment_count(scene: Scene) -> int:
    """Segments of all paths, not counting a Z's closing line when it has zero length
    (the path already ended at its start). This is how the counts in
    shared/data/README.md are defined (diffvg adds a closing segment only when needed):
    tiger 2,532, mcseem2 10,224, boston 27,945. The Scene itself keeps every Z as a
    segment: tiger has 2,534 segments including two zero-length closing lines."""
    total = 0
    for shape in scene.shapes:
        g = shape.geometry
        if not isinstance(g, PathGeometry):
            continue
        total += len(g.degrees)
        for (first, count, closed), (p0, n) in zip(g.subpaths, g.subpath_point_ranges()):
            if closed:
                last_degree = int(g.degrees[first + count - 1])
                end = g.points[p0 + n - 1]  # the closing line starts at the last stored point
                if last_degree == 1 and torch.equal(end, g.points[p0]) and n > 1:
                    total -= 1
    return total


# ============================================================ conformance corpus

def _cases():
    manifest = CORPUS / "manifest.tsv"
    if not manifest.exists():
        return []
    with open(manifest, newline="") as f:
        return list(csv.DictReader(f, delimiter="\t"))


CASES = _cases()
# Cases whose path data has an error on purpose (drawn up to the error, with a warning).
INVALID_DATA = {"shapes__path__A", "shapes__path__no-commawsp-before-arc-flags"}


@pytest.mark.parametrize("case", CASES, ids=[c["name"] for c in CASES])
def test_conformance_case_loads(case):
    path = CORPUS / case["svg"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = load_svg(path)
    # The corpus holds only supported features: nothing may be skipped.
    messages = [str(w.message) for w in caught if issubclass(w.category, VecfitWarning)]
    if case["name"] in INVALID_DATA:
        assert list(scene.skipped) == ["invalid path data"]
    else:
        assert messages == [] and scene.skipped == {}
    for t in all_tensors(scene):
        assert torch.isfinite(t).all()
    # Every case is rendered 300 px wide from its root size.
    assert scene.width > 0 and scene.height > 0
    assert math.isclose(scene.height / scene.width, int(case["height"]) / int(case["width"]),
                        rel_tol=0.01)
    if 'id="frame"' in path.read_text():
        frame = by_source(scene, "frame")
        assert isinstance(frame.geometry, Rect) and frame.fill is None
        assert rgba(frame.stroke) == [0, 0, 0, 1] and float(frame.stroke_width) == 1
        assert frame.geometry.p_min.tolist() == [1, 1]


def _corpus_scene(name: str) -> Scene:
    return quiet_load(need(CORPUS / "cases" / f"{name}.svg"))


@pytest.mark.parametrize("name, count", [
    ("structure__defs__ignore-shapes-inside-defs", 1),  # only the frame
    ("shapes__rect__zero-width-attribute-processing", 1),
    ("shapes__rect__negative-height-attribute-processing", 1),
    ("shapes__circle__missing-r-attribute", 2),
    ("shapes__ellipse__missing-rx-and-ry-attributes", 1),
    ("shapes__polyline__missing-points-attribute", 1),
    ("shapes__path__M", 1),  # a lone moveto draws nothing
    ("shapes__path__empty", 1),
    ("structure__transform__zeroed-matrix", 1),  # a singular transform draws nothing
    ("structure__svg__no-children", 0),
    ("structure__use__non-linear-order", 3),
])
def test_conformance_shape_counts(name, count):
    assert len(_corpus_scene(name).shapes) == count


# ======================================================================== paths

def test_path_commands_absolute_and_relative(tmp_path):
    scene = load(tmp_path, '<path id="p" d="M10 10 H 20 V 30 h 5 v -5 L 0 0 l 1 1 Z m 5 5 l 1 0"/>')
    g = by_source(scene, "p").geometry
    assert g.degrees.tolist() == [1, 1, 1, 1, 1, 1, 1, 1]
    assert g.subpaths == [(0, 7, True), (7, 1, False)]
    # The closed subpath stores its start once: 7 segments of degree 1 -> 7 points.
    assert g.points.tolist() == [[10, 10], [20, 10], [20, 30], [25, 30], [25, 25], [0, 0],
                                 [1, 1], [15, 15], [16, 15]]


def test_z_is_an_explicit_closing_line_even_at_zero_length(tmp_path):
    scene = load(tmp_path, '<path id="p" d="M0 0 L10 0 L 10 10 L 0 0 Z" stroke="black"/>')
    g = by_source(scene, "p").geometry
    assert g.degrees.tolist() == [1, 1, 1, 1]  # three lines, then Z (zero length here)
    assert g.subpaths == [(0, 4, True)]
    assert g.points.tolist() == [[0, 0], [10, 0], [10, 10], [0, 0]]


def test_after_z_a_new_subpath_starts_at_the_closed_ones_start(tmp_path):
    g = load(tmp_path, '<path id="p" d="M10 10 L20 20 Z L 30 30"/>').shapes[0].geometry
    assert g.subpaths == [(0, 2, True), (2, 1, False)]
    assert g.points.tolist() == [[10, 10], [20, 20], [10, 10], [30, 30]]


@pytest.mark.parametrize("d, segments", [
    ("M 10 10 L 10 10", [(1, False)]),           # zero-length: a dot with round caps
    ("M 10 10 Z", [(1, True)]),                   # zero-length closed subpath
    ("M 10 10 L 10 10 L 10 10", [(2, False)]),
    ("M 10 10 M 20 20 L 30 30", [(1, False)]),    # the lone moveto is dropped
    ("M 10 10 L 20 20 M 5 5", [(1, False)]),
])
def test_zero_length_subpaths_are_kept_and_lone_movetos_dropped(tmp_path, d, segments):
    g = load(tmp_path, f'<path d="{d}" stroke="black" stroke-linecap="round"/>').shapes[0].geometry
    assert [(count, closed) for _, count, closed in g.subpaths] == segments


def test_zero_length_subpaths_of_the_corpus():
    scene = _corpus_scene("painting__stroke-linecap__zero-length-path-with-square")
    g = by_source(scene, "path2").geometry
    assert g.subpaths == [(0, 1, False), (1, 1, False)]
    assert g.points.tolist() == [[70, 100], [70, 100], [130, 100], [130, 100]]


def test_smooth_commands_reflect_control_points(tmp_path):
    g = load(tmp_path, '<path d="M0 0 C 0 10 10 10 10 0 S 20 -10 20 0 Q 25 10 30 0 T 40 0 '
                       'L 50 0 S 60 10 70 0 T 80 0"/>').shapes[0].geometry
    assert g.degrees.tolist() == [3, 3, 2, 2, 1, 3, 2]
    p = g.points.tolist()
    assert p[4] == [10, -10]        # S reflects C's second control point (10, 10) about (10, 0)
    assert p[7] == [25, 10] and p[9] == [35, -10]   # T reflects Q's control point
    assert p[12] == [50, 0]         # S after L: the first control point is the current point
    assert p[15] == [70, 0]         # T after S: the control point is the current point


def _arc_oracle(d: str, n: int = 2000) -> np.ndarray:
    """Points along the path's arcs, from svgelements (an independent implementation)."""
    import svgelements
    pts = []
    for seg in svgelements.Path(d):
        if isinstance(seg, svgelements.Arc):
            pts += [(p.x, p.y) for p in (seg.point(t) for t in np.linspace(0, 1, n))]
    return np.array(pts)


def _bezier(ctrl: np.ndarray, t: np.ndarray) -> np.ndarray:
    (p0, p1, p2, p3), u = ctrl, 1 - t[:, None]
    t = t[:, None]
    return u ** 3 * p0 + 3 * u * u * t * p1 + 3 * u * t * t * p2 + t ** 3 * p3


@pytest.mark.parametrize("d", [
    "M 20 100 A 40 30 0 0 1 180 100",          # radii scaled up to reach the end point
    "M 20 100 A 80 50 30 1 0 120 60",           # rotated, large arc
    "M 100 20 a 50 50 0 1 1 -0.5 0",            # almost a full circle
    "M 10 10 A 25 100 -45 0 1 60 30",
])
def test_arcs_become_cubics_of_at_most_90_degrees_on_the_arc(tmp_path, d):
    g = load(tmp_path, f'<path d="{d}"/>').shapes[0].geometry
    assert set(g.degrees.tolist()) == {3}
    pts = g.points.double().numpy()
    start = [float(v) for v in d.split()[1:3]]
    assert pts[0].tolist() == start
    oracle = _arc_oracle(d)
    # The last cubic ends exactly at the arc's end point.
    assert np.allclose(pts[-1], oracle[-1], atol=1e-4)
    # Every cubic stays on the arc (within the approximation error of <= 90 degree pieces),
    # and the pieces are at most 90 degrees: 4 cubics at most for one arc.
    assert len(g.degrees) <= 4
    radius = np.ptp(oracle, axis=0).max()
    for i in range(len(g.degrees)):
        curve = _bezier(pts[3 * i:3 * i + 4], np.linspace(0, 1, 50))
        dist = np.min(np.linalg.norm(curve[:, None] - oracle[None], axis=2), axis=1)
        assert dist.max() < 2e-3 * radius


def test_arc_corner_cases(tmp_path):
    scene = load(tmp_path, '<path id="a" d="M 10 10 A 0 10 0 0 1 50 50"/>'   # zero radius: a line
                           '<path id="b" d="M 10 10 A 5 5 0 0 1 10 10 L 20 20"/>'  # no-op arc
                           '<path id="c" d="M10 10 A 10 10 0 0110 30"/>')  # packed flags
    assert by_source(scene, "a").geometry.degrees.tolist() == [1]
    assert by_source(scene, "b").geometry.degrees.tolist() == [1]
    c = by_source(scene, "c").geometry
    assert c.degrees.tolist() == [3, 3] and c.points[-1].tolist() == [10, 30]


def test_path_data_errors_keep_what_came_before():
    with pytest.raises(PathDataError) as e:
        parse_path_data("M 10 10 L 20 20 L 30 # 40 40")
    assert [s.points for s in e.value.subpaths] == [[(10, 10), (20, 20)]]
    with pytest.raises(PathDataError):
        parse_path_data("L 10 10")  # must start with a moveto


def test_basic_shapes(tmp_path):
    scene = load(tmp_path, """
        <line id="l" x1="1" y1="2" x2="3" y2="4" stroke="black"/>
        <polyline id="pl" points="0,0 10,0 10,10 5"/>
        <polygon id="pg" points="0 0 10 0 10 10"/>
        <circle id="c" cx="5" cy="6" r="7"/>
        <ellipse id="e" cx="5" cy="6" rx="7" ry="8"/>
        <ellipse id="e2" cx="5" cy="6" ry="8"/>""")
    line = by_source(scene, "l").geometry
    assert line.points.tolist() == [[1, 2], [3, 4]] and line.subpaths == [(0, 1, False)]
    assert by_source(scene, "pl").geometry.subpaths == [(0, 2, False)]  # odd coordinate dropped
    pg = by_source(scene, "pg").geometry
    assert pg.subpaths == [(0, 3, True)] and len(pg.points) == 3
    c = by_source(scene, "c").geometry
    assert isinstance(c, Circle) and c.center.tolist() == [5, 6] and float(c.radius) == 7
    e = by_source(scene, "e").geometry
    assert isinstance(e, Ellipse) and e.radii.tolist() == [7, 8]
    assert by_source(scene, "e2").geometry.radii.tolist() == [8, 8]  # SVG 2: rx auto = ry


@pytest.mark.parametrize("attrs, radii", [
    ('rx="10"', [10, 10]),
    ('ry="10"', [10, 10]),
    ('rx="-5" ry="10"', [10, 10]),      # negative: as not given
    ('rx="200"', [80, 40]),             # resolved, then clamped to half the size
    ('rx="20" ry="0"', [0, 0]),         # either zero: square corners
    ("", [0, 0]),
])
def test_rect_corner_radii(tmp_path, attrs, radii):
    g = load(tmp_path, f'<rect x="20" y="20" width="160" height="80" {attrs}/>').shapes[0].geometry
    assert isinstance(g, Rect) and g.corner_radii.tolist() == radii
    assert g.p_min.tolist() == [20, 20] and g.p_max.tolist() == [180, 100]


# ================================================================ root and view

@pytest.mark.parametrize("attrs, size, view", [
    ('width="200" height="100" viewBox="0 0 400 200"', (200, 100), [[.5, 0, 0], [0, .5, 0]]),
    ('viewBox="10 20 300 150"', (300, 150), [[1, 0, -10], [0, 1, -20]]),
    ('width="50" height="40"', (50, 40), [[1, 0, 0], [0, 1, 0]]),
    ('width="2in" height="96"', (192, 96), [[1, 0, 0], [0, 1, 0]]),
    # preserveAspectRatio, default xMidYMid meet: centred horizontally.
    ('width="200" height="100" viewBox="0 0 100 100"', (200, 100), [[1, 0, 50], [0, 1, 0]]),
    ('width="200" height="100" viewBox="0 0 100 100" preserveAspectRatio="xMinYMin"',
     (200, 100), [[1, 0, 0], [0, 1, 0]]),
    ('width="200" height="100" viewBox="0 0 100 100" preserveAspectRatio="xMaxYMax slice"',
     (200, 100), [[2, 0, 0], [0, 2, -100]]),
    ('width="200" height="100" viewBox="0 0 100 100" preserveAspectRatio="none"',
     (200, 100), [[2, 0, 0], [0, 1, 0]]),
    ('width="100" viewBox="0 0 50 25"', (100, 50), [[2, 0, 0], [0, 2, 0]]),
])
def test_root_size_and_view(tmp_path, attrs, size, view):
    scene = load(tmp_path, "", attrs)
    assert (scene.width, scene.height) == size
    assert torch.allclose(scene.view, torch.tensor(view + [[0, 0, 1]], dtype=torch.float32))


def test_root_opacity_and_transform_make_a_group():
    scene = _corpus_scene("painting__opacity__on-the-root-svg")
    assert len(scene.groups) == 1 and float(scene.groups[0].opacity) == 0.5
    assert all(s.group == 0 for s in scene.shapes)


# ======================================================================== groups

def test_nested_group_opacity_makes_nested_groups(tmp_path):
    scene = load(tmp_path, '<g id="a" opacity="0.8"><g id="b" opacity="50%" transform="translate(5 6)">'
                           '<rect id="r" width="10" height="10" opacity="0.25"/></g></g>'
                           '<g id="c"><rect id="r2" width="1" height="1"/></g>')
    assert [g.source for g in scene.groups] == ["a", "b", "c"]
    assert [g.parent for g in scene.groups] == [-1, 0, -1]
    assert [round(float(g.opacity), 4) for g in scene.groups] == [0.8, 0.5, 1.0]
    assert scene.groups[1].transform[:2, 2].tolist() == [5, 6]
    r = by_source(scene, "r")
    assert r.group == 1 and float(r.opacity) == 0.25  # not multiplied into the group's
    assert by_source(scene, "r2").group == 2


def test_deeply_nested_groups_of_the_corpus():
    scene = _corpus_scene("structure__g__deeply-nested-groups")
    rect = by_source(scene, "rect1")
    depth, g = 0, rect.group
    while g >= 0:
        depth, g = depth + 1, scene.groups[g].parent
    assert depth == len(scene.groups) == 8


def test_opacity_values_percentages_and_clamping(tmp_path):
    scene = load(tmp_path, '<rect id="a" width="1" height="1" opacity="150%" fill-opacity="-2" '
                           'stroke-opacity="25%"/><rect id="b" width="1" height="1" opacity="abc"/>')
    a = by_source(scene, "a")
    assert (float(a.opacity), float(a.fill_opacity), float(a.stroke_opacity)) == (1, 0, 0.25)
    assert float(by_source(scene, "b").opacity) == 1


def test_display_visibility_and_switch(tmp_path):
    scene = load(tmp_path, """
        <g display="none"><rect id="hidden1" width="1" height="1"/></g>
        <rect id="hidden2" width="1" height="1" style="display:none"/>
        <g visibility="hidden"><rect id="hidden3" width="1" height="1"/>
          <rect id="shown1" width="1" height="1" visibility="visible"/></g>
        <switch><foreignObject/><rect id="no" systemLanguage="fr" width="1" height="1"/>
          <rect id="shown2" width="1" height="1"/><rect id="no2" width="1" height="1"/></switch>""")
    assert [s.source for s in scene.shapes] == ["shown1", "shown2"]


# ==================================================================== use

def test_use_places_its_target(tmp_path):
    scene = load(tmp_path, """
        <defs><g id="grp" transform="translate(1 2)"><rect id="inner" x="5" y="5" width="10" height="10"/></g></defs>
        <use id="u1" href="#grp" xlink:href="#nothing" x="10" y="20" transform="scale(2)" fill="red"/>
        <use id="u2" xlink:href="#u1" x="100"/>""")
    instances = [s for s in scene.shapes if s.source == "inner"]
    assert len(instances) == 2
    # u1: scale(2) . translate(10, 20) . translate(1, 2) applied to (5, 5) -> (32, 54).
    assert apply(to_canvas(scene, instances[0]), (5, 5)) == [32, 54]
    assert apply(to_canvas(scene, instances[1]), (5, 5)) == [132, 54]
    assert rgba(instances[0].fill) == [1, 0, 0, 1]  # style inherited from the use
    assert [g.source for g in scene.groups] == ["u1", "grp", "u2", "u1", "grp"]


@pytest.mark.parametrize("name, corner", [
    ("structure__use__transform-attribute-2", (20, 20)),   # the target's parent g is not used
    ("structure__use__position-inheritance", (20, 20)),
    ("structure__use__transform-inheritance", None),
])
def test_use_cases_of_the_corpus(name, corner):
    scene = _corpus_scene(name)
    rect = by_source(scene, "rect1")
    if corner is not None:
        assert apply(to_canvas(scene, rect), rect.geometry.p_min.tolist()) == list(corner)
    assert rect.group >= 0 and scene.groups[rect.group].source == "use1"


def test_use_style_inheritance_comes_from_the_use_not_the_original_parent():
    rect = by_source(_corpus_scene("structure__use__style-inheritance-2"), "rect1")
    assert rgba(rect.fill) == hex_rgba("#008000")


def test_use_of_symbol_and_nested_svg(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = load_svg(write(tmp_path, """
            <defs><symbol id="sym" viewBox="0 0 10 10"><circle id="sc" cx="5" cy="5" r="5"/></symbol></defs>
            <use id="u" href="#sym" x="50" y="50" width="20" height="20"/>
            <svg id="n" x="10" y="10" width="50" height="50" viewBox="0 0 100 100">
              <rect id="nr" width="100" height="100"/></svg>"""))
    circle = by_source(scene, "sc")
    assert apply(to_canvas(scene, circle), (5, 5)) == [60, 60]
    assert apply(to_canvas(scene, by_source(scene, "nr")), (100, 100)) == [60, 60]
    # Both viewports clip (overflow: hidden): a rect of the viewport's size, in the
    # space before the viewBox's mapping.
    nested = scene.groups[scene.shapes[-1].group]
    rect = nested.clip.content.shapes[0].geometry
    assert rect.p_max.tolist() == [50, 50]
    assert apply(nested.clip.content.view, (50, 50)) == [100, 100]


def test_recursive_and_broken_uses_are_skipped(tmp_path):
    with pytest.warns(VecfitWarning) as record:
        scene = load_svg(write(tmp_path, '<g id="loop"><use id="u3" href="#loop"/></g>'
                                         '<use id="u5" href="#gone"/>'))
    assert scene.shapes == []
    assert scene.skipped == {"use": ["u3 (recursive)", "u5 (no element #gone)"]}
    assert len(record) == 1


# ======================================================================= style

@pytest.mark.slow
def test_css_classes_of_an_adobe_trace():
    path = need(DATA / "photos" / "kitty.svg")
    scene = load_svg(path)
    root = ET.parse(path).getroot()
    style = "".join(e.text or "" for e in root.iter() if e.tag.endswith("style"))
    colors = {c: hex_rgba(v) for c, v in
              (rule.strip().lstrip(".").split("{fill:") for rule in style.split(";}") if "{" in rule)}
    classes = [e.get("class") for e in root.iter() if e.tag.rsplit("}")[-1] in ("path", "polygon")]
    assert len(scene.shapes) == len(classes) == 1019
    assert colors["st0"] == hex_rgba("#4A4137")
    assert rgba(scene.shapes[0].fill) == hex_rgba("#4A4137")  # the first path is .st0
    assert [rgba(s.fill) for s in scene.shapes] == [colors[c] for c in classes]
    # Without ids, each shape's source is its position in the document.
    for shape, cls in zip(scene.shapes, classes):
        assert element_at(root, shape.source).get("class") == cls


def element_at(root, handle: str):
    element = root
    for k in handle.strip("/").split("/"):
        element = list(element)[int(k)]
    return element


def test_sources_are_unique_ids_or_positions(tmp_path):
    scene = load(tmp_path, '<g id="g"><rect id="a" width="1" height="1"/><rect width="1" height="1"/>'
                           '<rect id="d" width="1" height="1"/><rect id="d" width="1" height="1"/></g>')
    assert [s.source for s in scene.shapes] == ["a", "/0/1", "/0/2", "/0/3"]
    assert scene.groups[0].source == "g"


def test_style_precedence_and_inheritance(tmp_path):
    scene = load(tmp_path, """
        <style>/* c */ .a, #r3 { fill: #FF0000; stroke: blue } rect.b { fill: lime }
        rect { stroke-width: 3 } .imp { fill: green !important }</style>
        <rect id="r1" class="a" width="10" height="10" fill="black"/>
        <rect id="r2" class="b a" width="10" height="10" style="fill:purple"/>
        <rect id="r3" width="10" height="10"/>
        <rect id="r4" class="imp" width="10" height="10" style="fill:red"/>
        <rect id="r5" class="b" width="10" height="10"/>
        <g fill="blue" stroke="red" stroke-width="7" stroke-linejoin="round" fill-rule="evenodd">
          <circle id="c1" r="4" fill="currentColor" color="#123"/>
          <circle id="c2" r="4" stroke="inherit" opacity="0.5"/></g>""")
    assert rgba(by_source(scene, "r1").fill) == [1, 0, 0, 1]      # CSS over presentation attribute
    assert rgba(by_source(scene, "r2").fill) == hex_rgba("#800080")  # style attribute over CSS
    assert rgba(by_source(scene, "r3").fill) == [1, 0, 0, 1]      # #id selector
    assert rgba(by_source(scene, "r4").fill) == hex_rgba("#008000")  # !important wins
    assert rgba(by_source(scene, "r5").fill) == [0, 1, 0, 1]      # tag.class compound
    assert float(by_source(scene, "r1").stroke_width) == 3
    c1, c2 = by_source(scene, "c1"), by_source(scene, "c2")
    assert rgba(c1.fill) == hex_rgba("#112233")                   # currentColor
    assert rgba(c1.stroke) == [1, 0, 0, 1] and float(c1.stroke_width) == 7  # inherited
    assert c1.linejoin == "round" and c1.fill_rule == "evenodd"
    assert rgba(c2.fill) == [0, 0, 1, 1] and float(c2.opacity) == 0.5


def test_style_attribute_with_comments():
    rect = by_source(_corpus_scene("structure__style-attribute__comments"), "rect1")
    assert rgba(rect.fill) == hex_rgba("#008000")


@pytest.mark.parametrize("attrs, expected", [
    ('stroke-linecap="round" stroke-linejoin="bevel" stroke-miterlimit="10"', ("round", "bevel", 10)),
    ('stroke-linecap="miter" stroke-linejoin="miter-clip" stroke-miterlimit="0.5"', ("butt", "miter", 4)),
    ('stroke-linecap="square" stroke-linejoin="arcs" stroke-miterlimit="1"', ("square", "miter", 1)),
    ('stroke-linejoin="nonsense"', ("butt", "miter", 4)),
])
def test_stroke_properties(tmp_path, attrs, expected):
    s = load(tmp_path, f'<path d="M0 0 L 10 10" stroke="black" {attrs}/>').shapes[0]
    assert (s.linecap, s.linejoin, s.miter_limit) == expected


@pytest.mark.parametrize("width, stroked", [("0", False), ("-2", False), ("2.5", True), ("x", True)])
def test_stroke_width(tmp_path, width, stroked):
    s = load(tmp_path, f'<path d="M0 0 L 10 10" stroke="black" stroke-width="{width}"/>').shapes[0]
    assert (s.stroke is not None) == stroked


def test_invalid_linecap_quirk_of_the_corpus():
    path = by_source(_corpus_scene("painting__stroke-miterlimit__valid-value"), "path1")
    assert path.linecap == "butt" and path.linejoin == "miter"


# ====================================================================== colours

@pytest.mark.parametrize("text, expected", [
    ("green", [0, 128 / 255, 0, 1]),
    ("GREEN", [0, 128 / 255, 0, 1]),
    ("#0f0", [0, 1, 0, 1]),
    ("#00FF00", [0, 1, 0, 1]),
    ("#0A0A", [0, 2 / 3, 0, 2 / 3]),
    ("#00ff0080", [0, 1, 0, 128 / 255]),
    ("rgb(0, 128, 0)", [0, 128 / 255, 0, 1]),
    ("RGB(0%, 50%, 0%)", [0, 0.5, 0, 1]),
    ("rgb(-10%, 50%, 120%)", [0, 0.5, 1, 1]),
    ("rgb(0.8, 127.5, 14.2)", [0.8 / 255, 0.5, 14.2 / 255, 1]),
    ("rgba(0, 127, 0, 0.5)", [0, 127 / 255, 0, 0.5]),
    ("rgba(0, 127, 0, -1)", [0, 127 / 255, 0, 0]),
    ("rgba(0, 127, 0, 2)", [0, 127 / 255, 0, 1]),
    ("rgba(0, 127, 0, 50%)", [0, 127 / 255, 0, 0.5]),
    ("rgb(0 127 0 / 0.5)", [0, 127 / 255, 0, 0.5]),
    ("hsl(120, 100%, 25%)", [0, 0.5, 0, 1]),
    ("hsl(120, 200%, 25%)", [0, 0.5, 0, 1]),
    ("hsl(360, 100%, 25%)", [0.5, 0, 0, 1]),
    ("hsla(120, 100%, 25%, 0.5)", [0, 0.5, 0, 0.5]),
    ("transparent", [0, 0, 0, 0]),
    ("qwe", None),
    ("#12", None),
    ("rgb(1, 2)", None),
])
def test_colors(text, expected):
    got = parse_color(text)
    if expected is None:
        assert got is None
    else:
        assert np.allclose(got, expected, atol=1e-6)


def test_fill_and_stroke_defaults_and_none(tmp_path):
    scene = load(tmp_path, '<rect id="a" width="1" height="1"/>'
                           '<rect id="b" width="1" height="1" fill="none" stroke="qwe"/>'
                           '<rect id="c" width="1" height="1" fill="qwe" stroke="red"/>'
                           '<rect id="d" width="1" height="1" fill="rgba(255,0,0,0.5)" fill-opacity="0.5"/>')
    a, b, c, d = (by_source(scene, k) for k in "abcd")
    assert rgba(a.fill) == [0, 0, 0, 1] and a.stroke is None
    assert b.fill is None and b.stroke is None  # kept, drawing nothing
    assert rgba(c.fill) == [0, 0, 0, 1] and rgba(c.stroke) == [1, 0, 0, 1]
    assert rgba(d.fill) == [1, 0, 0, 0.5] and float(d.fill_opacity) == 0.5  # not folded


# ===================================================================== gradients

def test_gradient_href_inherits_stops_and_attributes():
    fill = by_source(_corpus_scene("paint-servers__linearGradient__stops-via-xlink-href"), "rect1").fill
    assert isinstance(fill, LinearGradient) and fill.source == "lg2"
    assert fill.offsets.tolist() == [0, 1]
    assert fill.colors.tolist() == [[1, 1, 1, 1], [0, 0, 0, 1]]
    # lg3 -> lg1 (own stops: white, black) -> lg2 (red): the first with stops wins.
    fill = by_source(_corpus_scene("paint-servers__linearGradient__stops-via-xlink-href-complex-order-2"),
                     "rect1").fill
    assert fill.colors.tolist() == [[1, 1, 1, 1], [0, 0, 0, 1]]
    fill = by_source(_corpus_scene("paint-servers__linearGradient__attributes-via-xlink-href"), "rect1").fill
    assert np.allclose(fill.start.tolist() + fill.end.tolist(), [0.2, 0.1, 0.8, 0.7])
    # A radial gradient takes stops from a linear one.
    fill = by_source(_corpus_scene("paint-servers__radialGradient__stops-via-xlink-href-from-linearGradient"),
                     "rect1").fill
    assert isinstance(fill, RadialGradient) and fill.offsets.tolist() == [0, 1]


def test_href_precedence_over_xlink_href():
    scene = _corpus_scene("paint-servers__linearGradient__href-precedence-over-xlink")
    for rect in ("rect1", "rect2"):
        assert rgba(Solid(by_source(scene, rect).fill.colors[0])) == hex_rgba("#008000")


@pytest.mark.parametrize("name, center, focal", [
    ("paint-servers__radialGradient__fx-resolving-1", (0.6, 0.5), (0.6, 0.5)),  # fx = cx
    ("paint-servers__radialGradient__fx-resolving-2", (0.7, 0.5), (0.6, 0.5)),  # fx inherited
    ("paint-servers__radialGradient__fy-resolving-3", (0.5, 0.7), (0.5, 0.7)),  # cy inherited
    ("paint-servers__radialGradient__attributes-via-xlink-href-only-required", (0.5, 0.55), (0.6, 0.65)),
])
def test_radial_focal_defaults(name, center, focal):
    fill = by_source(_corpus_scene(name), "rect1").fill
    assert np.allclose(fill.center.tolist(), center) and np.allclose(fill.focal.tolist(), focal)
    assert fill.units == "objectBoundingBox"


def test_percentages_in_gradient_coordinates():
    # userSpaceOnUse: percentages of the viewport (viewBox 0 0 200 100); defaults 0% / 100%.
    fill = by_source(_corpus_scene("paint-servers__linearGradient__gradientUnits=userSpaceOnUse-with-percent"),
                     "rect1").fill
    assert fill.units == "userSpaceOnUse"
    assert np.allclose(fill.start.tolist() + fill.end.tolist(), [30, 0, 200, 80])
    fill = by_source(_corpus_scene("paint-servers__radialGradient__gradientUnits=userSpaceOnUse-with-percent"),
                     "rect1").fill
    assert np.allclose(fill.center.tolist() + [float(fill.radius)] + fill.focal.tolist(),
                       [120, 100, 60, 80, 90])
    # objectBoundingBox: percentages are fractions of the box.
    fill = by_source(_corpus_scene("paint-servers__radialGradient__gradientUnits=objectBoundingBox-with-percent"),
                     "rect1").fill
    assert np.allclose(fill.center.tolist() + [float(fill.radius)], [0.6, 0.5, 0.5])


def test_gradient_transform_and_stop_rules(tmp_path):
    scene = load(tmp_path, """
        <linearGradient id="g" gradientTransform="rotate(90)" gradientUnits="userSpaceOnUse" x2="50">
          <stop offset="-1" stop-color="red"/><stop offset="60%" stop-color="lime" stop-opacity="0.5"/>
          <stop offset="0.4" style="stop-color: blue; stop-opacity: 50%"/><stop offset="2"/></linearGradient>
        <rect id="r" width="10" height="10" fill="url(#g)"/>""")
    fill = by_source(scene, "r").fill
    assert np.allclose(fill.transform.tolist(), [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-6)
    assert fill.end.tolist() == [50, 0]
    assert np.allclose(fill.offsets.tolist(), [0, 0.6, 0.6, 1])  # clamped, never decreasing
    assert np.allclose(fill.colors.tolist(), [[1, 0, 0, 1], [0, 1, 0, 0.5], [0, 0, 1, 0.5], [0, 0, 0, 1]])


def test_degenerate_gradients(tmp_path):
    scene = load(tmp_path, """
        <linearGradient id="none"/>
        <linearGradient id="one"><stop stop-color="lime" stop-opacity="0.5"/></linearGradient>
        <radialGradient id="r0" r="0"><stop stop-color="red"/><stop offset="1" stop-color="blue"/></radialGradient>
        <rect id="a" width="1" height="1" fill="url(#none)" stroke="url(#one)"/>
        <rect id="b" width="1" height="1" fill="url(#r0)"/>""")
    a, b = by_source(scene, "a"), by_source(scene, "b")
    assert a.fill is None and rgba(a.stroke) == [0, 1, 0, 0.5]
    assert rgba(b.fill) == [0, 0, 1, 1]  # r = 0: the last stop's colour


def test_shared_gradient_is_one_paint_object(tmp_path):
    scene = load(tmp_path, '<linearGradient id="g"><stop stop-color="red"/><stop offset="1"/></linearGradient>'
                           '<rect width="1" height="1" fill="url(#g)"/><rect width="1" height="1" fill="url(#g)"/>')
    assert scene.shapes[0].fill is scene.shapes[1].fill  # one element, one set of parameters


def test_unsupported_paints_use_fallbacks_or_none(tmp_path):
    with pytest.warns(VecfitWarning):
        scene = load_svg(write(tmp_path, """
            <pattern id="pat"/><radialGradient id="rs" spreadMethod="reflect"><stop/><stop offset="1"/></radialGradient>
            <rect id="a" width="1" height="1" fill="url(#pat) green"/>
            <rect id="b" width="1" height="1" fill="url(#missing)"/>
            <rect id="c" width="1" height="1" fill="url(#pat)"/>
            <rect id="d" width="1" height="1" fill="url(#rs)"/>"""))
    assert rgba(by_source(scene, "a").fill) == hex_rgba("#008000")
    assert by_source(scene, "b").fill is None and by_source(scene, "c").fill is None
    assert isinstance(by_source(scene, "d").fill, RadialGradient)  # drawn as pad
    assert scene.skipped["pattern"] == ["a", "c"]
    assert scene.skipped["spreadMethod"] == ["rs (reflect)"]
    assert scene.skipped["paint reference"] == ["b (#missing)"]


# ==================================================================== skipped content

def test_skipped_content_warns_once_per_kind(tmp_path):
    path = write(tmp_path, """
        <text id="t1">a</text><text>b</text><text id="t3">c</text>
        <image id="i1"/><image id="i2"/>
        <rect id="f1" width="1" height="1" filter="url(#f)" stroke="red" stroke-dasharray="1e-9"/>
        <rect id="f2" width="1" height="1" style="filter: url(#f)" clip-path="url(#c)"/>
        <rect id="ok" width="1" height="1"/>""")
    with pytest.warns(VecfitWarning) as record:
        scene = load_svg(path)
    messages = [str(w.message) for w in record]
    assert len(messages) == len(set(messages)) == 5
    assert scene.skipped == {"text": ["t1", "text", "t3"], "image": ["i1", "i2"],
                             "filter reference": ["f1 (no <filter> #f)", "f2 (no <filter> #f)"],
                             "stroke-dasharray": ["f1"], "clip-path": ["f2 (no <clipPath> #c)"]}
    assert "more dashes than the limit" in next(m for m in messages if "stroke-dasharray" in m)
    text_warning = next(m for m in messages if "text" in m)
    assert str(path) in text_warning and "t1" in text_warning and "t3" in text_warning
    # As browsers do: a clip path that is not there clips nothing, a filter that is not
    # there draws nothing (the shapes stay in the Scene, one per element).
    assert len(scene.shapes) == 3
    assert scene.shapes[0].filter.steps == [] and scene.shapes[1].clip is None


# ======================================================================== dashes

def test_dash_array_and_offset(tmp_path):
    """Lengths with units, percentages of the diagonal / sqrt(2), comma or space separated,
    an odd count repeated, inherited; offsets likewise (not finite: 0)."""
    diagonal = math.sqrt((200 ** 2 + 100 ** 2) / 2)
    scene = load(tmp_path, """
        <path id="a" d="M0 0 H 50" stroke="red" stroke-dasharray="10%, 5mm 2" stroke-dashoffset="-5%"/>
        <g stroke-dasharray="3 1" stroke-dashoffset="2"><path id="b" d="M0 0 H 50" stroke="red"/></g>
        <rect id="c" width="5" height="5" stroke="red" stroke-dasharray="1,2" stroke-dashoffset="nan"/>
        <circle id="d" r="5" stroke="red" style="stroke-dasharray: 1 2; stroke-dashoffset: 1e400"/>
        <path id="e" d="M0 0 H 50" stroke="red" stroke-dasharray="4 4" stroke-dashoffset="12"/>""",
                 attrs='width="200" height="100"')
    a = by_source(scene, "a")
    assert np.allclose(a.dash_array, [0.1 * diagonal, 5 * 96 / 25.4, 2] * 2) and len(a.dash_array) == 6
    assert math.isclose(a.dash_offset, -0.05 * diagonal)
    assert by_source(scene, "b").dash_array == (3.0, 1.0) and by_source(scene, "b").dash_offset == 2.0
    assert by_source(scene, "c").dash_array == (1.0, 2.0) and by_source(scene, "c").dash_offset == 0.0
    assert by_source(scene, "d").dash_array == (1.0, 2.0) and by_source(scene, "d").dash_offset == 0.0
    assert by_source(scene, "e").dash_offset == 12.0
    assert not scene.skipped


@pytest.mark.parametrize("value", ["none", "", "1 x", "-1 2", "0 0", "0", "nan 2", "inf", "1e400 1", "1 -0",
                                   "1,,", "url(#a)"])
def test_dash_arrays_that_draw_solid(tmp_path, value):
    scene = load(tmp_path, f'<path id="p" d="M0 0 H 50" stroke="red" stroke-dasharray="{value}"/>')
    assert by_source(scene, "p").dash_array is None and not scene.skipped


def test_dashes_only_on_strokes(tmp_path):
    scene = load(tmp_path, '<path id="p" d="M0 0 H 50" fill="red" stroke-dasharray="1 2"/>'
                           '<path id="q" d="M0 0 H 50" stroke="red" stroke-width="0" stroke-dasharray="1 2"/>')
    assert by_source(scene, "p").dash_array is None and by_source(scene, "q").dash_array is None


def test_too_many_dashes_warn_and_draw_solid(tmp_path):
    start = time.perf_counter()
    with pytest.warns(VecfitWarning, match="stroke-dasharray.*long"):
        scene = load_svg(write(tmp_path, '<path id="long" d="M0 0 H 1e6 V 1e6" stroke="red" stroke-dasharray="1e-9"/>'
                                         '<path id="ok" d="M0 0 H 1e6" stroke="red" stroke-dasharray="100"/>'))
    assert by_source(scene, "long").dash_array is None and by_source(scene, "ok").dash_array == (100.0, 100.0)
    assert scene.skipped == {"stroke-dasharray": ["long"]}
    assert time.perf_counter() - start < 5


def test_huge_numbers_are_clamped_not_infinite(tmp_path):
    with pytest.warns(VecfitWarning, match="out-of-range"):
        scene = load_svg(write(tmp_path, '<path id="p" d="M0 0 L 1e39 5 L 5 -1e300 Z" stroke="black" '
                                         'stroke-width="1e39"/><circle id="c" r="1e39"/>'))
    for t in all_tensors(scene):
        assert torch.isfinite(t).all()
    assert by_source(scene, "p").geometry.points[1, 0] == 1e7
    assert scene.skipped["out-of-range numbers"] == ["p", "c"]


# ============================================================================ errors

@pytest.mark.parametrize("content, reason", [
    (None, "no such file"),
    (b"", "empty"),
    (b"   \n", "empty"),
    (b"<html><body/></html>", "root element"),
    (b"\x00\xff\xfe garbage \x01", "XML"),
    (b'<svg xmlns="http://www.w3.org/2000/svg"><rect', "XML"),
    (b'<svg xmlns="http://www.w3.org/2000/svg" width="0" height="10"/>', "width"),
    (b'<svg xmlns="http://www.w3.org/2000/svg" width="10" height="-3"/>', "height"),
    (b'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 0 10"/>', "viewBox"),
    (b'<x:svg xmlns:x="http://example.com/not-svg"/>', "root element"),
])
def test_bad_input_raises_svg_error_naming_the_file(tmp_path, content, reason):
    path = tmp_path / "bad.svg"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(SvgError) as e:
        load_svg(path)
    assert str(path) in str(e.value) and reason in str(e.value)


def test_deep_nesting_and_use_bombs_are_errors(tmp_path, monkeypatch):
    deep = tmp_path / "deep.svg"
    deep.write_text('<svg xmlns="http://www.w3.org/2000/svg">' + "<g>" * 5000 + "</g>" * 5000 + "</svg>")
    with pytest.raises(SvgError, match="nested too deeply"):
        load_svg(deep)
    import vecfit.svg.read as read
    monkeypatch.setattr(read, "MAX_ELEMENTS", 1000)
    body = '<defs><rect id="a0" width="1" height="1"/>' + "".join(
        f'<g id="a{i}">' + f'<use href="#a{i - 1}"/>' * 10 + "</g>" for i in range(1, 5)) + "</defs>"
    with pytest.raises(SvgError, match="expands to more than 1000"):
        load_svg(write(tmp_path, body + '<use href="#a4"/>'))


def test_svg_without_namespace(tmp_path):
    path = tmp_path / "plain.svg"
    path.write_text('<svg width="10" height="10"><rect width="1" height="1" fill="red"/>'
                    '<x:meta xmlns:x="http://example.com/editor"><rect width="1" height="1"/></x:meta></svg>')
    scene = load_svg(path)
    assert len(scene.shapes) == 1 and rgba(scene.shapes[0].fill) == [1, 0, 0, 1]


def test_directory_raises_svg_error(tmp_path):
    with pytest.raises(SvgError, match="directory"):
        load_svg(tmp_path)


def test_no_drawable_shapes_is_an_empty_scene(tmp_path):
    scene = load(tmp_path, "<defs><rect width='1' height='1'/></defs><title>x</title>")
    assert scene.shapes == [] and scene.groups == [] and (scene.width, scene.height) == (200, 200)


def test_svgz_is_read(tmp_path):
    import gzip
    path = tmp_path / "a.svgz"
    path.write_bytes(gzip.compress(b'<svg xmlns="http://www.w3.org/2000/svg" width="5" height="5">'
                                   b'<rect width="1" height="1"/></svg>'))
    assert len(load_svg(path).shapes) == 1


# ======================================================================= real scenes

@pytest.mark.slow
@pytest.mark.parametrize("name, segments", [("tiger", 2532), ("mcseem2", 10224), ("boston", 27945)])
def test_segment_counts_of_the_benchmark_scenes(name, segments):
    scene = quiet_load(need(DATA / "scenes" / f"{name}.svg"))
    assert segment_count(scene) == segments
    for t in all_tensors(scene):
        assert torch.isfinite(t).all()


def test_benchmark_scene_structure():
    tiger = quiet_load(need(DATA / "scenes" / "tiger.svg"))
    assert (tiger.width, tiger.height) == (495, 510) and len(tiger.shapes) == 303
    assert sum(len(s.geometry.degrees) for s in tiger.shapes) == 2534  # Z lines included
    # The tiger is drawn flipped: scale(1,-1) translate(0,-510) on its only group.
    assert len(tiger.groups) == 1
    assert apply(tiger.groups[0].transform, (0, 0)) == [0, 510]


@pytest.mark.slow
def test_boston_loads_quickly():
    path = need(DATA / "scenes" / "boston.svg")
    quiet_load(path)  # warm caches (imports, regexes)
    start = time.perf_counter()
    quiet_load(path)
    assert time.perf_counter() - start < 2.0


@pytest.mark.slow
def test_every_shared_scene_loads():
    for path in sorted(need(DATA).glob("*/*.svg")):
        scene = quiet_load(path)
        assert scene.shapes, path
        for t in all_tensors(scene):
            assert torch.isfinite(t).all(), path


# ========================================================================== describe

def test_describe_counts(tmp_path):
    with pytest.warns(VecfitWarning):
        scene = load_svg(write(tmp_path, """
            <linearGradient id="g"><stop/><stop offset="1"/></linearGradient>
            <g opacity="0.5"><path d="M0 0 L 1 1 Q 2 2 3 3 C 4 4 5 5 6 6 Z"/><rect width="1" height="1"
            fill="url(#g)" stroke="red"/></g><circle r="2" opacity="0.5"/><text id="t">x</text>""",
            'width="300" height="150" viewBox="0 0 200 100"'))
    text = summarize(scene)
    assert "canvas: 300 x 150 px" in text
    assert "viewBox: 0 0 200 100" in text
    assert "shapes: 3 (1 path, 1 rect, 1 circle, 0 ellipse)" in text
    assert "segments: 4 (2 lines, 1 quadratics, 1 cubics) in 1 subpaths (1 closed" in text
    assert "fills: 3 (2 solid, 1 linear, 0 radial)" in text
    assert "strokes: 1 (1 solid, 0 linear, 0 radial)" in text
    assert "groups: 1 (1 with opacity < 1); shapes with opacity < 1: 1" in text
    assert "text: 1 (t)" in text


def test_describe_tiger():
    text = summarize(quiet_load(need(DATA / "scenes" / "tiger.svg")))
    assert "shapes: 303 (303 path" in text and "segments: 2534" in text
    assert "skipped: nothing" in text
