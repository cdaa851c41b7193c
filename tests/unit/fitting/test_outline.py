"""The outline cost (vecfit/fitting/outline.py): its value against a direct computation,
zero at the start, and that it holds control polygons to their length in a fit."""
from __future__ import annotations

import numpy as np
import torch

from vecfit.fitting.loop import Settings, Target, optimize
from vecfit.fitting.outline import OutlineCost
from vecfit.fitting.rates import parameter_kinds
from vecfit.svg.read import load_svg

# Two curved shapes under a scale (lengths are counted in pixels), one line-only shape.
SVG = """<svg xmlns="http://www.w3.org/2000/svg" width="48" height="48" viewBox="0 0 24 24">
  <path d="M2 2 C8 0 14 6 20 4 Q22 12 18 20 L4 18 Z" fill="#c33"/>
  <path d="M6 8 C8 6 12 6 14 10 C12 14 8 14 6 8" fill="#36c" fill-opacity="0.8"/>
  <path d="M1 22 L10 12 L22 22 Z" fill="#3a3"/>
</svg>"""


def _scene(tmp_path):
    path = tmp_path / "s.svg"
    path.write_text(SVG)
    return load_svg(path)


def _polygon_length(scene, scale=2.0):
    """Control-polygon length of the curved segments in pixels, segment by segment."""
    total = 0.0
    for shape in scene.shapes:
        g = shape.geometry
        p = g.points.detach().numpy().astype(np.float64)
        for (first, count, closed), (p0, n) in zip(g.subpaths, g.subpath_point_ranges()):
            k = 0
            for d in (int(v) for v in g.degrees[first:first + count]):
                idx = [p0 + ((k + i) % n if closed else k + i) for i in range(d + 1)]
                k += d
                if d > 1:
                    total += np.linalg.norm(np.diff(p[idx], axis=0), axis=1).sum() * scale
    return total


def test_value_and_gradient(tmp_path):
    scene = _scene(tmp_path)
    kind = parameter_kinds(scene, {"points": 1.0}, 48, 48)[0]
    cost = OutlineCost(scene, kind, 48, 48, weight=48 * 48)  # weight per pixel: 1 per px of growth
    assert float(cost(kind.flat)) == 0.0
    assert abs(float(cost.polygons(kind.flat).sum()) - _polygon_length(scene)) < 1e-3
    start = _polygon_length(scene)
    with torch.no_grad():
        kind.flat.view(-1, 2)[1] += torch.tensor([0.0, -3.0])  # a handle of the first curve pulled out
    grown = _polygon_length(scene) - start
    assert grown > 0
    x = kind.flat.detach().clone().requires_grad_()
    value = cost(x)
    assert abs(float(value.detach()) - grown) < 1e-3
    value.backward()
    # only the moved handle and its neighbours in the polygon feel it; the line-only shape not
    nonzero = torch.nonzero(x.grad.view(-1, 2).abs().sum(dim=1)).reshape(-1).tolist()
    assert 1 in nonzero and set(nonzero) <= {0, 1, 2, 3}  # (the curve's polygon)


def test_fit_holds_the_outlines(tmp_path):
    target = Target(torch.rand(48, 48, 4, generator=torch.Generator().manual_seed(0)), background=(1, 1, 1))
    target.image[..., 3] = 1
    grown = {}
    for weight in (0.0, 1.0):
        scene = _scene(tmp_path)
        start = _polygon_length(scene)
        optimize(scene, target, Settings.defaults(iterations=30, threads=1, coarse=0.0, outline=weight,
                                         lr={"points": 1.0, "colors": 0.02}))
        grown[weight] = _polygon_length(scene) / start
    assert grown[0.0] > 1.05  # noise makes handles wander ...
    assert grown[1.0] < 1 + (grown[0.0] - 1) / 3  # ... and the cost holds them
