"""A human-readable summary of a Scene, for ``vecfit info``."""
from __future__ import annotations

from collections import Counter

import numpy as np

from .arrays import to_numpy
from .model import (CUBIC, LINE, QUADRATIC, Circle, ClipPath, Ellipse, LinearGradient, Mask, Path,
                    RadialGradient, Rect, Scene, Solid)

_GEOMETRY = ((Path, "path"), (Rect, "rect"), (Circle, "circle"), (Ellipse, "ellipse"))
_PAINTS = ((Solid, "solid"), (LinearGradient, "linear"), (RadialGradient, "radial"))
_SHOWN = 6  # names listed per skipped kind


def _kind(obj, table) -> str:
    return next((name for cls, name in table if isinstance(obj, cls)), type(obj).__name__)


def _num(x: float) -> str:
    return f"{x:.6g}"


def _counts(counter: Counter, order) -> str:
    return ", ".join(f"{counter.get(k, 0)} {k}" for k in order)


def _canvas(scene: Scene) -> list[str]:
    """Size, and the user-space region the canvas shows (the viewBox when the aspect
    ratios agree), from the inverse of the view matrix."""
    lines = [f"canvas: {_num(scene.width)} x {_num(scene.height)} px"]
    view = np.asarray(to_numpy(scene.view), np.float64)
    try:
        inv = np.linalg.inv(view)
    except np.linalg.LinAlgError:
        return lines + ["view: not invertible"]
    corners = inv @ np.array([[0.0, scene.width], [0.0, scene.height], [1.0, 1.0]])
    (x0, x1), (y0, y1) = corners[0].tolist(), corners[1].tolist()
    lines.append(f"viewBox: {_num(x0)} {_num(y0)} {_num(x1 - x0)} {_num(y1 - y0)}"
                 f" (the user-space region shown)")
    return lines


def _segments(scene: Scene) -> str:
    degrees = Counter()
    subpaths = closed = 0
    for shape in scene.shapes:
        g = shape.geometry
        if isinstance(g, Path):
            values, counts = np.unique(np.asarray(g.degrees), return_counts=True)
            degrees.update(dict(zip(values.tolist(), counts.tolist())))
            subpaths += len(g.subpaths)
            closed += sum(1 for _, _, c in g.subpaths if c)
    total = sum(degrees.values())
    return (f"segments: {total} ({degrees.get(LINE, 0)} lines, {degrees.get(QUADRATIC, 0)} "
            f"quadratics, {degrees.get(CUBIC, 0)} cubics) in {subpaths} subpaths "
            f"({closed} closed; each Z counts as a line)")


def _paints(scene: Scene) -> list[str]:
    out = []
    for role in ("fill", "stroke"):
        paints = [getattr(s, role) for s in scene.shapes if getattr(s, role) is not None]
        kinds = Counter(_kind(p, _PAINTS) for p in paints)
        out.append(f"{role}s: {len(paints)} ({_counts(kinds, ('solid', 'linear', 'radial'))})")
    return out


def _opacity(scene: Scene) -> str:
    groups = sum(1 for g in scene.groups if float(g.opacity) < 1)
    shapes = sum(1 for s in scene.shapes if float(s.opacity) < 1)
    return (f"groups: {len(scene.groups)} ({groups} with opacity < 1); "
            f"shapes with opacity < 1: {shapes}")


def _effects(scene: Scene) -> list[str]:
    """Clip paths, masks and filters: how many of each, what uses them, and what they hold."""
    owners = [*scene.shapes, *scene.groups]
    lines = []
    for attr, label in (("clip", "clip paths"), ("mask", "masks"), ("filter", "filters")):
        used = [getattr(o, attr) for o in owners if getattr(o, attr) is not None]
        distinct = {id(e): e for e in used}.values()
        if not distinct:
            continue
        names = ", ".join(str(e.source) for e in list(distinct)[:_SHOWN] if e.source is not None)
        if attr == "filter":
            steps = Counter(step.kind for e in distinct for step in e.steps)
            detail = ", ".join(f"{n} {k}" for k, n in sorted(steps.items())) or "no steps"
        else:
            detail = f"{sum(len(e.content.shapes) for e in distinct)} shapes drawn in them"
        lines.append(f"{label}: {len(distinct)} on {len(used)} shapes and groups ({detail})"
                     + (f": {names}" if names else ""))
    return lines


def _skipped(scene: Scene) -> list[str]:
    if not scene.skipped:
        return ["skipped: nothing"]
    lines = ["skipped or approximated:"]
    for kind, names in scene.skipped.items():
        shown = ", ".join(names[:_SHOWN]) + (f" and {len(names) - _SHOWN} more"
                                             if len(names) > _SHOWN else "")
        lines.append(f"  {kind}: {len(names)} ({shown})")
    return lines


def summarize(scene: Scene) -> str:
    """Counts of shapes by geometry, segments by degree, paints by kind, groups and
    opacity layers, clip paths, masks and filters, the canvas and view, and what the
    reader skipped."""
    kinds = Counter(_kind(s.geometry, _GEOMETRY) for s in scene.shapes)
    unpainted = sum(1 for s in scene.shapes if s.fill is None and s.stroke is None)
    lines = _canvas(scene)
    lines.append(f"shapes: {len(scene.shapes)} ({_counts(kinds, ('path', 'rect', 'circle', 'ellipse'))})"
                 + (f"; {unpainted} without fill or stroke" if unpainted else ""))
    lines.append(_segments(scene))
    lines += _paints(scene)
    lines.append(_opacity(scene))
    lines += _effects(scene)
    lines += _skipped(scene)
    return "\n".join(lines)
