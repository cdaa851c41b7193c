"""Decimals written (vecfit/svg/precision.py) and opacities to three decimals."""
from __future__ import annotations

import re

import numpy as np
import pytest
import torch

import vecfit
from vecfit.errors import VecfitError
from vecfit.svg.precision import decimals_for
from vecfit.svg.write import opacity_text, svg_bytes

from helpers import quiet_load


@pytest.mark.parametrize("pixels_per_unit,side,decimals", [
    (1.0, 512, 2), (1.0, 1024, 2), (1.0, 4096, 2), (1.0, 20000, 1),  # 0.01 px up to 1,024 px, then its share
    (512 / 24, 512, 4),  # a 24-unit icon drawn at 512 px
    (0.1, 512, 1), (1e-9, 512, 0), (1e9, 512, 6), (0.0, 512, 6)])
def test_decimals_for(pixels_per_unit, side, decimals):
    assert decimals_for(pixels_per_unit, side) == decimals


@pytest.mark.parametrize("value,text", [(1.0, None), (0.9996, None), (0.9994, ".999"), (0.5, ".5"),
                                        (0.12345, ".123"), (0.0, "0"), (-0.2, "0"), (1.7, None)])
def test_opacity_written_with_three_decimals(value, text):
    assert opacity_text(value) == text


def _moved(tmp_path, width, view, **kw) -> str:
    src = tmp_path / "in.svg"
    src.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{width}" viewBox="{view}">'
                   '<path id="p" d="M1 1 C 2 1 3 2 3 3 L 1 3 Z" fill="#102030"/></svg>')
    scene = quiet_load(src)
    with torch.no_grad():
        scene.shapes[0].geometry.points += 0.123456789
        scene.shapes[0].fill.color[3] = 0.87654
    return svg_bytes(scene, src, **kw).decode()


def _decimals(d: str) -> int:
    return max(len(n.split(".")[1]) if "." in n else 0 for n in re.findall(r"-?\d+(?:\.\d+)?", d))


def test_written_decimals_follow_the_canvas(tmp_path):
    d = re.search(r' d="([^"]*)"', _moved(tmp_path, 512, "0 0 512 512")).group(1)
    assert _decimals(d) == 2
    icon = _moved(tmp_path, 512, "0 0 24 24")  # a user unit is 21 px
    assert _decimals(re.search(r' d="([^"]*)"', icon).group(1)) == 4
    assert 'fill-opacity=".877"' in icon
    small = _moved(tmp_path, 24, "0 0 24 24", pixels=(512, 512))  # optimised at 512 px
    assert _decimals(re.search(r' d="([^"]*)"', small).group(1)) == 4
    fixed = _moved(tmp_path, 512, "0 0 512 512", precision=5)
    assert _decimals(re.search(r' d="([^"]*)"', fixed).group(1)) == 5
    with pytest.raises(VecfitError, match="precision"):
        _moved(tmp_path, 512, "0 0 512 512", precision=9)


def test_precision_option_reaches_the_file(tmp_path):
    from PIL import Image
    import numpy as np
    Image.fromarray(np.full((32, 32, 3), 200, np.uint8)).save(tmp_path / "t.png")
    (tmp_path / "i.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="32" height="32">'
                                    '<path id="p" d="M3 3 C 9 3 20 9 20 20 L 3 20 Z" fill="#102030"/></svg>')
    settings = {"optimize": {"iterations": 3}, "output": {"precision": 0}}
    svg, _ = vecfit.refine(tmp_path / "t.png", tmp_path / "i.svg", settings=settings)
    assert _decimals(re.search(r' d="([^"]*)"', svg).group(1)) == 0
    with pytest.raises(VecfitError, match="output.precision"):
        vecfit.refine(tmp_path / "t.png", tmp_path / "i.svg", settings={"output": {"precision": 7}})


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("decimals", [0, 2, 4])
def test_relative_path_data_lands_where_the_absolute_does(seed, decimals):
    """Offsets are differences of rounded points: read back, every point equals the
    point rounded, with no drift along a long path."""
    import numpy as np
    from vecfit.svg.pathdata import format_path_data, format_relative_path_data, parse_path_data, to_arrays

    rng = np.random.default_rng(seed)
    degrees = rng.choice([1, 2, 3], 300).tolist()
    subpaths = [(0, 120, True), (120, 100, False), (220, 80, True)]
    n = sum(sum(degrees[f:f + c]) + (0 if closed else 1) for f, c, closed in subpaths)
    points = np.cumsum(rng.normal(0, 7.3, (n, 2)), 0) + 300
    points[1::9, 1] = points[0::9, 1][:len(points[1::9])]  # some axis-aligned lines (h)
    relative = to_arrays(parse_path_data(format_relative_path_data(points, degrees, subpaths, decimals)))
    absolute = to_arrays(parse_path_data(format_path_data(points, degrees, subpaths, decimals)))
    assert np.array_equal(relative[1], absolute[1]) and relative[2] == absolute[2]
    assert np.abs(relative[0] - absolute[0]).max() < 1e-9  # the absolute text is the points rounded


def test_relative_path_data_text():
    import numpy as np
    from vecfit.svg.pathdata import format_relative_path_data

    pts = np.array([[10.004, 10], [50, 10], [50.25, 40.126], [30, 41], [20.5, 35], [12, -3]])
    assert format_relative_path_data(pts, [1, 1, 3, 1], [(0, 4, True)], 2) == \
        "M10 10h40l.25 30.13c-20.25.87-29.75-5.13-38.25-43.13z"


def test_relative_path_data_shortest_text():
    """Repeated command letters left out, relative m after a closed subpath (from its
    start), no separator before a minus or a second decimal point, and a space where a
    digit follows a number; the text reads back as the points rounded."""
    import numpy as np
    from vecfit.svg.pathdata import format_path_data, format_relative_path_data, parse_path_data, to_arrays

    pts = np.array([[10, 10], [11, 12], [13, 12.5], [14, 10], [15, 9.5], [16.5, 9], [20, 10],
                    [30, 30], [30.5, 30], [31, 30.5],
                    [5, 5], [6, 7]])
    degrees = [3, 3, 1, 1, 1, 1, 1]
    subpaths = [(0, 3, True), (3, 3, True), (6, 1, False)]
    text = format_relative_path_data(pts, degrees, subpaths, 2)
    assert text == "M10 10c1 2 3 2.5 4 0 1-.5 2.5-1 6 0zm20 20h.5l.5.5zm-25-25l1 2"
    back = to_arrays(parse_path_data(text))
    absolute = to_arrays(parse_path_data(format_path_data(pts, degrees, subpaths, 2)))
    assert np.abs(back[0] - absolute[0]).max() < 1e-9 and back[2] == absolute[2]


def test_relative_path_data_closes_exactly_at_its_start():
    """Offsets that add up to the start but for float rounding (88.998 then -0.586 of y
    after 0.586 and more) read back closed at the start itself, so the Z is no line of
    its own and the outline does not seem to cross itself there."""
    from vecfit.scene.crossings import subpath_crossings
    from vecfit.svg.pathdata import parse_path_data, to_arrays

    d = ("M88.998 0h-7.047l-.386 2.025c.555 1.24 1.446 2.157 2.715 3.175c.099-.094 .199-.185 .299-.273"
         "c1.744-1.534 3.539-2.151 4.254-4.341c.06-.184 .121-.378 .165-.586z")
    (subpath,) = parse_path_data(d)
    assert subpath.points[-1] == subpath.points[0]
    points, degrees = to_arrays([subpath])[:2]
    assert subpath_crossings(np.asarray(points, np.float32).astype(np.float64), list(degrees), True) == []
