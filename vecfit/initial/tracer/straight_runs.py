"""Straight runs of a fitted centerline written as one line each (``--style strokes``).

Where lines cross, a skeleton bends towards the other line, so a straight line through a
crossing is fitted as several segments that wobble there by a pixel or more (the slash of
an "-off" icon: 9 segments for the designer's 1), and the refinement keeps every one of
them: only a line stays a line. A run of consecutive segments is one line where, clear of
the crossings it passes (skeleton.Chain.crossings: a disk of JUNCTION_REACH times the
line's half width there), it lies within NEAR pixels of the line fitted to it, and nearer
the crossings it runs through within the stroke's half width (the wobble stays inside the
ink; at its ends no slack: the run may turn into another line past a crossing). The run's
ends go onto that line (where two runs meet, to where their lines cross), and the
neighbouring segments follow their ends. (Only crossings: at a T the bar may bend for
real, a book's cover dipping to its spine.)
"""
from __future__ import annotations

import numpy as np

from .bezier import _basis
from .primitives import line_like

# px: how far the run's points clear of crossings may lie from its line
NEAR = 1.0
# The skeleton bends towards the other line within this many half widths of a crossing's
# centre (its half width: the distance to the outline there, more than the line's own).
JUNCTION_REACH = 2.0
# At least this share of a run's length lies clear of crossings (a run that is mostly
# crossing says nothing about its direction).
MIN_CLEAR = 0.5
SAMPLES = 16  # per segment


def _points(segs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Samples [S, SAMPLES, 2] of cubics [S, 4, 2] (the middles of SAMPLES even steps of
    the parameter) and the length each stands for [S, SAMPLES]."""
    u = (np.arange(SAMPLES) + 0.5) / SAMPLES
    edges = np.linspace(0.0, 1.0, SAMPLES + 1)

    def at(t):
        return np.einsum("mk,skd->smd", np.stack(_basis(t), 1), segs)
    steps = np.linalg.norm(np.diff(at(edges), axis=1), axis=-1)
    return at(u), steps


def _line(points: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(A point on, the unit direction of) the weighted least-squares line through points."""
    centre = (points * weights[:, None]).sum(0) / weights.sum()
    d = points - centre
    cov = (d * weights[:, None]).T @ d
    _, vectors = np.linalg.eigh(cov)
    return centre, vectors[:, -1]


def _distance(points: np.ndarray, line) -> np.ndarray:
    centre, direction = line
    d = points - centre
    return np.abs(d[:, 0] * direction[1] - d[:, 1] * direction[0])


def _project(p: np.ndarray, line) -> np.ndarray:
    centre, direction = line
    return centre + float((p - centre) @ direction) * direction


def _crossing(a, b) -> np.ndarray | None:
    """Where two lines cross; None where they are (nearly) parallel."""
    (pa, da), (pb, db) = a, b
    det = da[0] * -db[1] + db[0] * da[1]
    if abs(det) < 1e-6:
        return None
    t = ((pb - pa)[0] * -db[1] + db[0] * (pb - pa)[1]) / det
    return pa + t * da


def straight_runs(segs: np.ndarray, crossings: np.ndarray, width: float, closed: bool = False,
                  tolerance: float = NEAR) -> np.ndarray:
    """The cubics [S, 4, 2] of one centerline (in order, each starting where the last
    ends; ``closed``: the last ends where the first starts) with each straight run (see the
    module docstring) as one straight cubic (control points at thirds of its chord).
    ``crossings`` [J, 3]: the centre and half width of each crossing the centerline
    passes; ``width``: the stroke's. Each segment of a run is a line on its own (within
    ``tolerance`` of its chord: primitives.line_like, the fit's test) or passes a crossing:
    a curve that runs into a corner clear of crossings (a rounded corner drawn tight) stays
    a curve."""
    count = len(segs)
    if count == 0:
        return segs
    points, lengths = _points(segs)
    clear = np.ones(points.shape[:2], bool)
    for x, y, half in np.asarray(crossings, np.float64).reshape(-1, 3):
        clear &= np.hypot(points[..., 0] - x, points[..., 1] - y) > JUNCTION_REACH * half
    may_join = line_like(segs, tolerance) | ~clear.all(1)

    def line_of(a: int, b: int):
        """The line of segments a..b, or None where they are not one."""
        p, w, ok = points[a:b + 1].reshape(-1, 2), lengths[a:b + 1].reshape(-1), clear[a:b + 1].reshape(-1)
        if w[ok].sum() < MIN_CLEAR * w.sum() or w[ok].sum() <= 0:
            return None
        # only a crossing the run passes through is let off: at its ends the run may turn
        # into another line (a tail past the crossing)
        inside = np.flatnonzero(ok)
        ok = ok.copy()
        ok[:inside[0]] = True
        ok[inside[-1] + 1:] = True
        line = _line(p[ok], w[ok])
        d = _distance(p, line)
        if d[ok].max() > NEAR or (~ok).any() and d[~ok].max() > width / 2:
            return None
        return line

    runs = []  # (first segment, last segment, line)
    a = 0
    while a < count:
        longest = count - 1 if not closed else min(count - 1, a + count - 2)  # (never the whole loop)
        longest = a + int(np.argmin(np.append(may_join[a:longest + 1], False))) - 1  # (-1: a may not)
        for b in range(longest, a, -1):  # (one segment is a line where the fit's own test says so)
            line = line_of(a, b)
            if line is not None:
                runs.append((a, b, line))
                a = b + 1
                break
        else:
            a += 1
    if not runs:
        return segs

    # the nodes (segment ends) the runs move: onto their line, or where two runs' lines cross
    nodes = np.concatenate([segs[:1, 0], segs[:, 3]])
    lines_at: dict[int, list] = {}
    node_key = (lambda n: n % count) if closed else (lambda n: n)  # a loop's last node is its first
    for a, b, line in runs:
        lines_at.setdefault(node_key(a), []).append(line)
        lines_at.setdefault(node_key(b + 1), []).append(line)
    moved = nodes.copy()
    for n, lines in lines_at.items():
        old = nodes[n]
        if len(lines) == 2:
            meet = _crossing(*lines)
            moved[n] = meet if meet is not None and np.hypot(*(meet - old)) <= width else \
                0.5 * (_project(old, lines[0]) + _project(old, lines[1]))
        else:
            moved[n] = _project(old, lines[0])
    if closed:
        moved[count] = moved[0]
    shift = moved - nodes

    out = []
    in_run = {k: (a, b) for a, b, _ in runs for k in range(a, b + 1)}
    for k in range(count):
        if k in in_run:
            a, b = in_run[k]
            if k == a:
                p, q = moved[a], moved[b + 1]
                out.append(np.stack([p, p + (q - p) / 3, p + 2 * (q - p) / 3, q]))
            continue
        seg = segs[k].copy()
        seg[:2] += shift[k]
        seg[2:] += shift[k + 1]
        out.append(seg)
    return np.stack(out)
