"""Traced outlines as a designer would draw them: straight runs as lines, and outlines that
are a rectangle, a circle or an ellipse as that element.

The Bézier fit writes every stretch between corners as cubics, so a flag's stripe comes
back as four cubics whose control points lie on its edges, and a disc as four or more
cubics. A cubic whose control points lie within ``tolerance`` of its chord (and between
its ends) is a line; neighbouring lines that continue each other are one line. A shape
whose one outline is four axis-aligned lines is a ``<rect>``; one whose outline stays
within ``tolerance`` of an axis-aligned ellipse is an ``<ellipse>``, or a ``<circle>``
when its radii agree. Refinement then moves a line as a line (its two ends) and a disc
by its centre and radius.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# An outline of fewer points is too small to tell an ellipse from a polygon.
MIN_ELLIPSE_POINTS = 12
# The traced edge steps along pixel boundaries (half a pixel either side of the true
# curve); it is smoothed by a Gaussian of this many pixels before the comparison.
EDGE_SMOOTHING = 1.0


@dataclass
class Outline:
    """A closed outline in the Scene's layout: ``points`` (its start, then each segment's
    control points and end; the last segment's end is the start, not stored again) and
    ``degrees`` (1 line, 3 cubic)."""
    points: np.ndarray
    degrees: list[int]


@dataclass
class Primitive:
    """An element other than a path: ``tag`` rect, circle or ellipse; ``attributes`` its
    geometry (numbers, in pixels)."""
    tag: str
    attributes: dict


def cubic_outline(segs: np.ndarray) -> Outline:
    """A closed outline of cubics [S, 4, 2] as they are, closed by a ``Z`` line of zero
    length (as the reader closes it)."""
    points = np.concatenate([np.asarray(segs[:1, 0], float), np.asarray(segs[:, 1:], float).reshape(-1, 2)])
    return Outline(points, [3] * len(segs) + [1])


def line_like(segs: np.ndarray, tolerance: float, within_chord: bool = True) -> np.ndarray:
    """[S] bool: cubics [S, 4, 2] whose control points lie within ``tolerance`` of the chord's
    line and, with ``within_chord``, project inside the chord (so the curve neither bulges
    nor doubles back). Without it a flat cubic that runs past its end and back is line-like
    too (cutouts.py: such a spike is what it straightens)."""
    p0, p1, p2, p3 = segs[:, 0], segs[:, 1], segs[:, 2], segs[:, 3]
    chord = p3 - p0
    length = np.hypot(chord[:, 0], chord[:, 1])
    safe = np.maximum(length, 1e-12)[:, None]
    unit = chord / safe
    ok = length > 1e-9
    for c in (p1, p2):
        rel = c - p0
        across = np.abs(rel[:, 0] * unit[:, 1] - rel[:, 1] * unit[:, 0])
        ok &= across <= tolerance
        if within_chord:
            along = (rel * unit).sum(1) / np.maximum(length, 1e-12)
            ok &= (along >= -1e-6) & (along <= 1 + 1e-6)
    return ok


def _runs(segs: np.ndarray, tolerance: float) -> list[list]:
    """Cubics [S, 4, 2] as runs [degree, start, the points after the start]: cubics within
    ``tolerance`` of their chord become lines, and lines that continue each other one."""
    straight = line_like(segs, tolerance) if tolerance > 0 else np.zeros(len(segs), bool)
    runs: list[list] = []
    for k in range(len(segs)):
        if not straight[k]:
            runs.append([3, segs[k, 0], segs[k, 1:]])
        elif runs and runs[-1][0] == 1 and _continues(runs[-1][1], segs[k, 0], segs[k, 3], tolerance):
            runs[-1][2] = segs[k, 3][None]  # the line goes on
        else:
            runs.append([1, segs[k, 0], segs[k, 3][None]])
    return runs


def straightened(segs: np.ndarray, tolerance: float) -> Outline:
    """A closed outline of cubics [S, 4, 2] with its straight runs as lines (see the module
    docstring), closed as the tracer closes it: a ``Z`` line of zero length at the end."""
    runs = _runs(segs, tolerance)
    # a line that ends the outline may go on into the one that starts it
    if (len(runs) > 2 and runs[0][0] == 1 and runs[-1][0] == 1
            and _continues(runs[-1][1], runs[0][1], runs[0][2][-1], tolerance)):
        runs[0][1] = runs.pop()[1]
    points = [runs[0][1][None]] + [r[2] for r in runs]
    return Outline(np.concatenate(points), [r[0] for r in runs] + [1])


def open_outline(segs: np.ndarray, tolerance: float) -> tuple[np.ndarray, list[int]]:
    """An open run of cubics [S, 4, 2] with its straight stretches as lines: (points,
    degrees) in the Scene's layout (its start, then each segment's points after its start)."""
    runs = _runs(segs, tolerance)
    return np.concatenate([runs[0][1][None]] + [r[2] for r in runs]), [r[0] for r in runs]


def _continues(a: np.ndarray, b: np.ndarray, c: np.ndarray, tolerance: float) -> bool:
    """Whether the lines a-b and b-c are one line: b within ``tolerance`` of a-c, between."""
    ac = c - a
    n = float(np.hypot(*ac))
    if n < 1e-9:
        return False
    ab = b - a
    across = abs(ab[0] * ac[1] - ab[1] * ac[0]) / n
    along = float(ab @ ac) / (n * n)
    return across <= tolerance and 0 < along < 1


def _rect(outline: Outline, tolerance: float) -> Primitive | None:
    """The axis-aligned rectangle that four lines draw, if they do."""
    if outline.degrees != [1, 1, 1, 1, 1] or len(outline.points) != 5:
        return None
    q = outline.points[:4]
    e = np.roll(q, -1, axis=0) - q
    axis = np.minimum(np.abs(e[:, 0]), np.abs(e[:, 1])) <= tolerance
    alternate = (np.abs(e[0, 0]) > np.abs(e[0, 1])) != (np.abs(e[1, 0]) > np.abs(e[1, 1]))
    if not (axis.all() and alternate):
        return None
    x0, y0 = q.min(0)
    x1, y1 = q.max(0)
    if x1 - x0 <= tolerance or y1 - y0 <= tolerance:
        return None
    return Primitive("rect", {"x": x0, "y": y0, "width": x1 - x0, "height": y1 - y0})


def _ellipse(pts: np.ndarray, tolerance: float) -> Primitive | None:
    """The axis-aligned ellipse (or circle) that a closed outline (points [N, 2], in order)
    follows within ``tolerance``, if it does."""
    if len(pts) < MIN_ELLIPSE_POINTS:
        return None
    pts = _smoothed_loop(pts)
    centre = pts.mean(0)
    x, y = (pts - centre).T
    # x^2/a^2 + y^2/b^2 + D x + E y = 1 about the mean (a least-squares conic, axis-aligned)
    design = np.stack([x * x, y * y, x, y], 1)
    try:
        (pa, pb, d, e), *_ = np.linalg.lstsq(design, np.ones_like(x), rcond=None)
    except np.linalg.LinAlgError:
        return None
    if pa <= 0 or pb <= 0:
        return None
    cx, cy = -d / (2 * pa), -e / (2 * pb)
    k = 1 + pa * cx * cx + pb * cy * cy
    rx, ry = np.sqrt(k / pa), np.sqrt(k / pb)
    if not (np.isfinite(rx) and np.isfinite(ry)) or min(rx, ry) <= 2 * tolerance:
        return None
    cx, cy = cx + centre[0], cy + centre[1]
    # the outline must go round once: its angles about the centre cover the circle in order
    angles = np.unwrap(np.arctan2((pts[:, 1] - cy) / ry, (pts[:, 0] - cx) / rx))
    if abs(abs(angles[-1] - angles[0]) - 2 * np.pi * (1 - 1 / len(pts))) > 0.5:
        return None
    # distance to the ellipse, to first order: the implicit function's value over its gradient
    gx, gy = (pts[:, 0] - cx) / rx, (pts[:, 1] - cy) / ry
    f = gx * gx + gy * gy - 1
    grad = 2 * np.hypot(gx / rx, gy / ry)
    if float(np.max(np.abs(f) / np.maximum(grad, 1e-12))) > tolerance:
        return None
    # undo the smoothing's pull towards the centre (about sigma^2 / 2r)
    grow = np.exp(EDGE_SMOOTHING ** 2 / (2 * rx * ry))
    rx, ry = rx * grow, ry * grow
    if abs(rx - ry) <= tolerance:
        r = 0.5 * (rx + ry)
        return Primitive("circle", {"cx": cx, "cy": cy, "r": r})
    return Primitive("ellipse", {"cx": cx, "cy": cy, "rx": rx, "ry": ry})


def _smoothed_loop(pts: np.ndarray) -> np.ndarray:
    """A closed pixel outline with its staircase ironed out: a Gaussian of EDGE_SMOOTHING
    pixels along the loop (it pulls a circle of radius r in by about sigma^2 / 2r)."""
    steps = np.hypot(*np.diff(pts, axis=0, append=pts[:1]).T)
    spacing = float(np.median(steps)) or 1.0
    sigma = EDGE_SMOOTHING / spacing
    reach = min(int(np.ceil(3 * sigma)), (len(pts) - 1) // 2)
    k = np.exp(-0.5 * (np.arange(-reach, reach + 1) / sigma) ** 2)
    k /= k.sum()
    wrapped = np.concatenate([pts[-reach:], pts, pts[:reach]]) if reach else pts
    return np.stack([np.convolve(wrapped[:, i], k, mode="valid") for i in range(2)], 1)


# The control points' distance along the tangent that makes four cubics a circle (within
# 0.03% of the radius).
KAPPA = 0.5522847498


def ellipse_outline(ellipse: Primitive, like: Outline) -> Outline:
    """An ellipse or circle as four cubics, from its rightmost point, turning the way
    ``like`` (the outline it replaces) turns: the exact curve of a compound path's
    elliptical subpath (a ring's rims, a letter's round counter), which cannot be an
    element of its own."""
    a = ellipse.attributes
    cx, cy = a["cx"], a["cy"]
    rx, ry = (a["r"], a["r"]) if ellipse.tag == "circle" else (a["rx"], a["ry"])
    x, y = like.points[:, 0], like.points[:, 1]
    turn = 1.0 if float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) >= 0 else -1.0
    points = [(cx + rx, cy)]
    for q in range(4):
        t0, t1 = q * np.pi / 2, (q + 1) * np.pi / 2
        c0, s0, c1, s1 = np.cos(t0), np.sin(t0), np.cos(t1), np.sin(t1)
        points += [(cx + rx * (c0 - KAPPA * s0), cy + turn * ry * (s0 + KAPPA * c0)),
                   (cx + rx * (c1 + KAPPA * s1), cy + turn * ry * (s1 - KAPPA * c1)),
                   (cx + rx * c1, cy + turn * ry * s1)]
    return Outline(np.array(points), [3, 3, 3, 3, 1])  # closed as the tracer closes: a Z of zero length


def distance_rms(points: np.ndarray, outline: Outline, steps: int = 24) -> float:
    """The root mean square distance of ``points`` [N, 2] from a closed ``outline`` of
    lines and cubics (each drawn as ``steps`` chords)."""
    t = np.linspace(0.0, 1.0, steps + 1)[:, None]
    polyline, at = [], 0
    for degree in outline.degrees:
        if degree == 3:
            p0, p1, p2, p3 = outline.points[at:at + 4]
            polyline.append((1 - t) ** 3 * p0 + 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t * t * p2 + t ** 3 * p3)
        else:
            polyline.append(outline.points[[at, (at + 1) % len(outline.points)]])
        at += degree
    line = np.concatenate(polyline)
    a, b = line[:-1], line[1:]
    d = b - a
    u = np.clip(((points[:, None] - a[None]) * d[None]).sum(-1) / np.maximum((d * d).sum(-1), 1e-12)[None], 0.0, 1.0)
    nearest = a[None] + u[..., None] * d[None]
    return float(np.sqrt(np.mean(np.min(((points[:, None] - nearest) ** 2).sum(-1), axis=1))))


def as_primitive(edge: np.ndarray, outline: Outline, line_tolerance: float,
                 curve_tolerance: float) -> Primitive | None:
    """A shape of one closed outline as a rect (its fitted ``outline``'s sides within
    ``line_tolerance`` of the axes), a circle or an ellipse (its traced ``edge``, points
    [N, 2] in order before the curve fit, within ``curve_tolerance`` of one), if it is
    one; else None. The ellipse is judged on the edge, not on the fitted cubics: a fit
    within a pixel cannot tell a rounded rectangle from an ellipse."""
    if 1 in outline.degrees[:-1]:
        return _rect(outline, line_tolerance)
    return _ellipse(np.asarray(edge, float), curve_tolerance)
