"""An iteration hook for stroked centerlines (``trace --style strokes``): cubics kept from
folding back on themselves.

Refinement moves control points freely. On a straight stretch a cubic's control point may
drift past its end (or behind its start): the curve then runs past its end and back, a
cusp. diffvg's strokes (the distance to the curve) draw it as the straight line it looks
like, but SVG renderers that stroke by offsetting the outline (resvg, browsers) leave gaps
and notches where the offsets turn inside out. After every iteration each cubic of a
stroke-only path has its control points held between its ends along its chord (their
distance from the chord is kept).
"""
from __future__ import annotations

import torch

from vecfit.scene.model import Path

MIN_CHORD = 1.0  # (the path's own units) shorter cubics are left alone


def _tame(points: torch.Tensor, degrees, subpaths, ranges) -> bool:
    """Clamp the control points of the cubics of one path in place; whether any moved."""
    moved = False
    for (first, count, closed), (start, length) in zip(subpaths, ranges):
        at = start
        for k in range(first, first + count):
            d = degrees[k]
            if d == 3:
                end = at + 3 if at + 3 < start + length else start  # a closed subpath's last ends at its start
                p0, p3 = points[at], points[end]
                chord = p3 - p0
                n2 = float(chord @ chord)
                if n2 > MIN_CHORD ** 2:
                    c = points[at + 1:at + 3]
                    along = (c - p0) @ chord / n2
                    fixed = along.clamp(0.0, 1.0)
                    if bool(fixed[0] > fixed[1]):  # the control polygon doubles back: meet halfway
                        fixed = fixed.mean().expand(2)
                    if bool((fixed != along).any()):
                        c += (fixed - along)[:, None] * chord
                        moved = True
            at += d
    return moved


def tame_stroke_cubics(step) -> None:
    """The hook (vecfit.fitting.loop.Step): every stroke-only path's cubics tamed."""
    for shape in step.scene.shapes:
        g = shape.geometry
        if shape.fill is not None or shape.stroke is None or not isinstance(g, Path):
            continue
        if not isinstance(g.points, torch.Tensor):
            continue
        pts = g.points.view(-1, 2)
        if _tame(pts, list(g.degrees), list(g.subpaths), list(g.subpath_point_ranges())):
            step.reset(g.points)
