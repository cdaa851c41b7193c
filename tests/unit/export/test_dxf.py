"""DXF export read back with ezdxf: the auditor finds no errors, the geometry lies on the
SVG's outlines (as svgelements, an independent reader, places them), one layer per
colour, a stroke-only drawing has each line once, units and the y axis are right."""
from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np
import pytest

from vecfit.export import svg_to
from helpers import need, slow_unless
from shared_data import SHARED

sys.path.insert(0, str(Path(__file__).parent))
from cases import CASES, svg  # noqa: E402

ezdxf = pytest.importorskip("ezdxf")
svgelements = pytest.importorskip("svgelements")
cKDTree = pytest.importorskip("scipy.spatial").cKDTree

LINEART = SHARED / "lineart" / "cases"
MM_PER_PX = 25.4 / 96


def read(data: bytes):
    doc = ezdxf.read(io.StringIO(data.decode("utf-8")))
    assert len(doc.audit().errors) == 0
    return doc


def dxf_lines(doc, height_px: float) -> list[np.ndarray]:
    """Each entity as points in SVG pixels (y down again)."""
    out = []
    for e in doc.modelspace():
        if e.dxftype() == "LWPOLYLINE":
            pts = np.array(e.get_points("xy"), np.float64)
            if e.closed:
                pts = np.vstack([pts, pts[:1]])
        elif e.dxftype() == "POINT":
            pts = np.array([[e.dxf.location.x, e.dxf.location.y]], np.float64)
        elif e.dxftype() == "SPLINE":
            pts = np.array([(v.x, v.y) for v in e.construction_tool().flattening(1e-4)], np.float64)
        elif e.dxftype() in ("CIRCLE", "ELLIPSE"):
            pts = np.array([(v.x, v.y) for v in e.flattening(1e-4)], np.float64)
        else:
            raise AssertionError(f"unexpected entity {e.dxftype()}")
        out.append(np.column_stack([pts[:, 0] / MM_PER_PX, height_px - pts[:, 1] / MM_PER_PX]))
    return out


def svg_lines(text: str) -> tuple[list[np.ndarray], float]:
    """Each subpath of each shape, densely sampled in pixels, by svgelements."""
    doc = svgelements.SVG.parse(io.StringIO(text))
    out = []
    for element in doc.elements():
        if not isinstance(element, svgelements.Shape) or isinstance(element, svgelements.Group):
            continue
        path = svgelements.Path(element)
        for sub in path.as_subpaths():
            sub = svgelements.Path(sub)
            pts = [np.asarray(seg.npoint(np.linspace(0, 1, 400)), np.float64)
                   for seg in sub.segments() if not isinstance(seg, svgelements.Move)]
            if pts:
                out.append(np.vstack(pts))
    return out, float(doc.height)


def dense(lines: list[np.ndarray], step: float = 0.01) -> np.ndarray:
    """Points every ``step`` px along polylines."""
    out = []
    for pts in lines:
        out.append(pts)
        for a, b in zip(pts[:-1], pts[1:]):
            k = max(1, int(np.ceil(np.hypot(*(b - a)) / step)))
            out.append(a + (b - a) * np.linspace(0, 1, k + 1)[:, None])
    return np.vstack(out)


def hausdorff(a: list[np.ndarray], b: list[np.ndarray]) -> float:
    pa, pb = dense(a), dense(b)
    return max(cKDTree(pb).query(pa)[0].max(), cKDTree(pa).query(pb)[0].max())


def check_geometry(text: str, curves: str, tolerance_px: float):
    doc = read(svg_to(text, "dxf", curves=curves))
    source, height = svg_lines(text)
    assert hausdorff(dxf_lines(doc, height), source) <= tolerance_px


@pytest.mark.parametrize("name", slow_unless(sorted(set(CASES) - {"dashes"}), ["strokes"]))
@pytest.mark.parametrize("curves", ["polyline", "spline"])
def test_dxf_geometry_is_the_svgs(name, curves):
    """Polylines within 0.01 mm (0.038 px) of the curves; splines exact (what is left is
    the checks' own sampling). Clip paths are not applied, so the clipped shapes are
    compared whole."""
    # (svgelements misplaces a circle under a skew by 0.2 px: test_skewed_circle checks it)
    check_geometry(svg(name).replace("skewX(20)", ""), curves, 0.05 if curves == "polyline" else 0.02)


@pytest.mark.parametrize("curves", ["polyline", "spline"])
def test_skewed_circle(curves):
    """The circle under translate, rotate, scale and skew: every point written lies on the
    ellipse the matrix makes of it (four cubics: within 0.03% of the radius; an ELLIPSE
    entity with exact curves)."""
    def m(a, b, c, d, e, f):
        return np.array([[a, c, e], [b, d, f], [0, 0, 1]], np.float64)
    r, k = np.radians(25), np.tan(np.radians(20))
    matrix = (m(2, 0, 0, 2, 0, 0) @ m(1, 0, 0, 1, 50, 40) @ m(np.cos(r), np.sin(r), -np.sin(r), np.cos(r), 0, 0)
              @ m(1.5, 0, 0, 0.6, 0, 0) @ m(1, 0, k, 1, 0, 0))
    doc = read(svg_to(svg("transforms"), "dxf", curves=curves))
    circle = [e for e in doc.modelspace() if e.dxf.layer == "#ee8844"]
    assert len(circle) == 1 and circle[0].dxftype() == ("ELLIPSE" if curves == "spline" else "LWPOLYLINE")
    pts = dxf_lines(doc, 160)[list(doc.modelspace()).index(circle[0])]
    local = (np.column_stack([pts, np.ones(len(pts))]) @ np.linalg.inv(matrix).T)[:, :2]
    # (float32 coordinates; the polyline's vertices lie on the four cubics)
    tolerance = 1e-4 if curves == "spline" else 10 * 3e-4 + 0.01
    assert np.hypot(local[:, 0], local[:, 1]) == pytest.approx(10, abs=tolerance)


def test_a_moved_outline_is_caught():
    text = svg("fills")
    doc = read(svg_to(text.replace('cx="70"', 'cx="70.2"'), "dxf"))
    source, height = svg_lines(text)
    assert hausdorff(dxf_lines(doc, height), source) > 0.3


def test_one_layer_per_colour():
    doc = read(svg_to(svg("strokes"), "dxf"))
    layers = {layer.dxf.name: layer.rgb for layer in doc.layers if layer.dxf.name.startswith("#")}
    assert set(layers) == {"#000000", "#aa0000", "#00aa00", "#0000aa", "#555555"}
    for name, rgb in layers.items():
        assert "#%02x%02x%02x" % rgb == name
    for e in doc.modelspace():
        assert e.dxf.layer in layers and e.dxf.color == 256  # BYLAYER


def test_a_fill_without_area_is_not_written():
    """An open line's fill (black by default) encloses nothing: only the stroke is written."""
    head = '<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">'
    doc = read(svg_to(head + '<path d="M10 10 H90" stroke="#00f"/></svg>', "dxf"))
    assert [e.dxf.layer for e in doc.modelspace()] == ["#0000ff"]


def test_fill_and_stroke_of_one_colour_are_one_outline():
    head = '<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">'
    doc = read(svg_to(head + '<rect x="10" y="10" width="50" height="50" fill="#f00" stroke="#f00"/></svg>', "dxf"))
    assert len(doc.modelspace()) == 1
    doc = read(svg_to(head + '<rect x="10" y="10" width="50" height="50" fill="#f00" stroke="#00f"/></svg>', "dxf"))
    assert sorted(e.dxf.layer for e in doc.modelspace()) == ["#0000ff", "#ff0000"]


def test_dashes_are_cut():
    """A dashed line becomes its dashes, each of the pattern's length."""
    head = '<svg xmlns="http://www.w3.org/2000/svg" width="96" height="20" viewBox="0 0 96 20">'
    doc = read(svg_to(head + '<path d="M0 10 H90" fill="none" stroke="#000" stroke-dasharray="10 5"/></svg>',
                      "dxf"))
    lines = dxf_lines(doc, 20)
    assert len(lines) == 6
    for pts in lines:
        assert np.hypot(*(pts[-1] - pts[0])) == pytest.approx(10, abs=1e-6)


@pytest.mark.parametrize("size, unit, extent", [('width="50mm" height="25mm"', 4, (50, 25)),
                                                ('width="2in" height="1in"', 1, (2, 1)),
                                                ('width="96" height="48"', 4, (25.4, 12.7))])
def test_units_and_y_axis(size, unit, extent):
    text = (f'<svg xmlns="http://www.w3.org/2000/svg" {size} viewBox="0 0 10 5">'
            '<path d="M0 0 L10 0 L10 5" fill="none" stroke="#000"/></svg>')
    doc = read(svg_to(text, "dxf"))
    assert doc.header["$INSUNITS"] == unit
    pts = np.array(next(iter(doc.modelspace())).get_points("xy"))
    # the SVG's top edge (y = 0) is at the drawing's top; its lower right corner at y = 0
    # (the Scene's floats are float32)
    assert pts == pytest.approx(np.array([[0, extent[1]], [extent[0], extent[1]], [extent[0], 0]]), abs=1e-5)


def _lineart_check(path: Path, curves: str):
    text = path.read_text()
    doc = read(svg_to(text, "dxf", curves=curves))
    source, height = svg_lines(text)
    drawn = dxf_lines(doc, height)
    # stroke-only: each line one entity, drawn once, on the one colour's layer
    assert len(drawn) == len(source), path.name
    assert {e.dxf.layer for e in doc.modelspace()} == {"#000000"}
    assert hausdorff(drawn, source) <= (0.05 if curves == "polyline" else 0.02), path.name


@pytest.mark.slow
def test_some_lineart_icons():
    for path in sorted(need(LINEART).glob("*.svg"))[::15]:
        for curves in ("polyline", "spline"):
            _lineart_check(path, curves)


@pytest.mark.slow
def test_every_lineart_icon():
    files = sorted(need(LINEART).glob("*.svg"))
    assert len(files) == 120
    for path in files:
        for curves in ("polyline", "spline"):
            _lineart_check(path, curves)
