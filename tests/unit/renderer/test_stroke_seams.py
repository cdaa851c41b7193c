"""The analytical image is continuous where a pixel centre crosses a seam inside a stroke.

A stroke is a union of pieces (sweeps, joins, caps) meeting along internal seams; its
signed distance inside is the deepest piece's depth (scene/coverage.h). At a bevel join
the sweep's depth on its end normal, hw - s, and the bevel triangle's, (hw - s) cos(turn /
2), differed, so the image jumped when the stroke moved a pixel centre across that normal
(about 0.1 of the colour for a right-angle bevel, 0.3 px inside the edge); the seam rule
bounds the sweep by the bevel edge. Each case puts a pixel centre 0.3 px inside the outer
edge on the sweep's end normal (or a cap's back edge) and moves the whole stroke by
+-1e-6 px across it: the image may change by its slope times the step, not by a jump.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import vecfit
from vecfit.scene import Path, Scene, Shape, Solid

SIZE = 24
HW = 3.3  # the pixel centre (12.5, 9.5) lies 3 px above the vertex (12.5, 12.5): 0.3 px inside


def render(points, degrees, join, cap="butt", dx=0.0):
    pts = torch.tensor(points, dtype=torch.float32) + torch.tensor([dx, 0.0])
    path = Path(points=pts, degrees=np.array(degrees), subpaths=[(0, len(degrees), False)])
    shape = Shape(geometry=path, stroke=Solid(torch.tensor([0.0, 0.0, 0.0, 1.0])), stroke_width=torch.tensor(2 * HW),
                  linecap=cap, linejoin=join)
    img = vecfit.render(Scene(width=SIZE, height=SIZE, shapes=[shape]), SIZE, SIZE, samples=1, mode="analytic",
                        background=(1, 1, 1))
    return img[..., 0].double()


def turn(deg):
    """Along +x into the vertex (12.5, 12.5), out turned by `deg` towards +y: the outer
    side is -y, where the sweep's end normal runs up through the pixel centre (12.5, 9.5)."""
    a = math.radians(deg)
    v = (12.5, 12.5)
    return [(2.0, 12.5), v, (v[0] + 9 * math.cos(a), v[1] + 9 * math.sin(a))], [1, 1]


CASES = {
    "bevel, right angle": (*turn(90), "bevel", "butt"),
    "bevel, 45 degrees": (*turn(45), "bevel", "butt"),
    "miter past its limit (bevel fallback)": (*turn(160), "miter", "butt"),
    # the other pieces' seams, which agree with the sweep already
    "miter within its limit": (*turn(90), "miter", "butt"),
    "round join": (*turn(90), "round", "butt"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_image_continuous_across_join_seam(case):
    points, degrees, join, cap = CASES[case]
    step = 1e-6
    a, b = render(points, degrees, join, cap, -step), render(points, degrees, join, cap, step)
    jump = float((a - b).abs().max())
    # a slope of at most ~3 / px at 1 sample per pixel (kernel radius 0.5) moves a pixel
    # by ~6e-6 over the step; float32 images round at ~6e-8
    assert jump < 1e-4, f"{case}: the image jumps by {jump:.3g} where the pixel centre crosses the seam"


def test_bevel_seam_is_where_the_jump_was():
    """The case above must really put the pixel on a seam: the pixel's value changes
    smoothly with the bevel and is inside the edge's prefilter band (0 < cov < 1)."""
    points, degrees = turn(90)
    img = render(points, degrees, "bevel")
    v = 1 - float(img[9, 12])  # the black stroke's coverage of pixel (12, 9)
    assert 0.5 < v < 1, v


def test_square_cap_back_edge():
    """A square cap's depth matches the sweep's on its back edge (s = 0): moving the end
    across the pixel centre (12.5, 9.5), 0.3 px inside the edge, changes nothing abruptly."""
    points = [(2.0, 12.5), (12.5, 12.5)]
    a = render(points, [1], "miter", "square", -1e-6)
    b = render(points, [1], "miter", "square", 1e-6)
    assert float((a - b).abs().max()) < 1e-4
