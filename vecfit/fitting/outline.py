"""A cost on outlines that grow: how much longer each curved segment's control polygon
has become than it was at the start of the fit, in pixels (Settings.outline, off by
default).

Where the image gives a control point little to go on, the Monte Carlo gradients are
mostly noise and Adam's steps make it wander; over a run the control polygons grow (the
demo's trace: 36k -> 87k px, chords 31k -> 47k px) and with them the SVG's clutter and
the backward pass's boundary samples, which are counted by control-polygon length: the
last iterations of `vecfit trace` cost 1.5x the first. The cost holds each segment to its
starting length unless the image pays for more.

Measured on the demo (benchmarks/RESULTS.md): the growth is also where part of the fit's
gain comes from. Weight 0.0003 keeps the time flat (last / first iterations 1.03x, the job
22 s against 36 s) for 36.00 dB against 36.79 dB; a cost on the polygon beyond the chord
(straightening every curve) did worse at every weight. So the default is 0 and the
setting is there for users who want the cleaner, faster fit.

The weight is per pixel of growth per pixel of the image. Computed from the points kind's
flat tensor (adam.ParameterKind), with index arrays made once.
"""
from __future__ import annotations

import numpy as np
import torch

from vecfit.scene import Path, Scene

from .rates import shape_pixel_scales


class OutlineCost:
    def __init__(self, scene: Scene, points_kind, width: int, height: int, weight: float):
        self.weight = weight / (width * height)
        at = {i: o // 2 for i, o in points_kind.offsets.items()}  # id(tensor) -> its first point
        scales = shape_pixel_scales(scene, width, height)
        edge_a, edge_b, edge_scale, edge_segment = [], [], [], []
        segments = 0
        for shape, scale in zip(scene.shapes, scales):
            g = shape.geometry
            if not isinstance(g, Path) or id(g.points) not in at:
                continue
            base = at[id(g.points)]
            for (first, count, closed), (p0, n) in zip(g.subpaths, g.subpath_point_ranges()):
                k = 0
                for degree in (int(d) for d in g.degrees[first:first + count]):
                    idx = [base + p0 + ((k + i) % n if closed else k + i) for i in range(degree + 1)]
                    k += degree
                    if degree > 1:  # (a line's polygon is the line)
                        edge_a += idx[:-1]
                        edge_b += idx[1:]
                        edge_scale += [scale] * degree
                        edge_segment += [segments] * degree
                        segments += 1
        as_index = lambda v: torch.as_tensor(np.asarray(v, dtype=np.int64))  # noqa: E731
        self._a, self._b = as_index(edge_a), as_index(edge_b)
        self._scale = torch.as_tensor(edge_scale, dtype=torch.float32)
        self._segment = as_index(edge_segment)
        self._segments = segments
        with torch.no_grad():
            self._start = self.polygons(points_kind.flat)

    def __bool__(self) -> bool:
        return self.weight > 0 and self._segments > 0

    def polygons(self, flat: torch.Tensor) -> torch.Tensor:
        """Each curved segment's control-polygon length in pixels."""
        p = flat.view(-1, 2)
        d = p[self._a] - p[self._b]
        lengths = torch.sqrt((d * d).sum(dim=1) + 1e-12) * self._scale
        return torch.zeros(self._segments).index_add(0, self._segment, lengths)

    def __call__(self, flat: torch.Tensor) -> torch.Tensor:
        return self.weight * torch.relu(self.polygons(flat) - self._start).sum()
