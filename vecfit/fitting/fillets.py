"""Rounded corners for strokes, where the picture's are rounder than a join draws them.

A traced centerline meets a rounded corner of the picture (a rect's rx; Tabler draws its
frames with corners of radius 1 at a stroke 2 wide) as a sharp vertex. A round join draws
the outside of a sharp vertex at the stroke's half width, where the picture's corner is
as round as the fillet's radius plus that: the difference is pixels wide, and the fit
cannot close it, having no node there to move.

Each corner of a stroke (two segments meeting at a turn) is tried filleted at a few radii,
all corners at once per radius, and each radius is judged at each corner by the squared
error of the render in a window about it. A corner takes the radius that is clearly
better there than the sharp vertex; the fillets taken are kept where the whole picture's
error falls."""
from __future__ import annotations

import dataclasses

import numpy as np

from vecfit.scene.arrays import to_numpy
from vecfit.scene.model import Path
from vecfit.scene.placement import shape_matrices
from vecfit.scene.segments import path_segments, points_at, split_at, with_segments

from .windows import choose_in_windows

# The fillets' radii tried, as multiples of the stroke's half width.
RADII = (0.5, 1.0, 1.5, 2.0)
TURN_MIN = 30.0   # degrees: a vertex turning less than this is no corner
TURN_MAX = 150.0  # degrees: nor is a hairpin (the trim grows as tan(turn / 2))
# A radius is taken at a corner where its window's squared error is this share of the
# sharp vertex's or less (the windows hold other strokes' edges and sampling noise).
CLEARLY_BETTER = 0.7
# Before the fit, the trace's corners are rough and a fillet often beats a rough sharp
# corner where the picture's is sharp: only a corner far better filleted is rounded then
# (at 0.7, a sharp-cornered Tabler icon lost 6 dB: the fit cannot take a fillet back).
TRACED_CLEARLY_BETTER = 0.35
# The tracer's join other than round (centerline.JOIN_CLEARLY_BETTER chose it) comes back
# after the passes tried with round joins where its render has this share of theirs or less.
TRACER_JOIN_KEPT = 0.8
WINDOW = 2.0      # the window's half side: this many half widths past the trim, and 2 px
CURVE_TURN_MIN = 60.0  # degrees: one curve turning less than this is no corner
NEIGHBOUR_STRAIGHT = 0.25  # ... and its neighbours within this many half widths of their chords
CURVED_MAX = 3    # a corner drawn as curves: at most this many segments between its lines
CURVED_REACH = 5.0  # ... all within this many half widths of where the lines meet


@dataclasses.dataclass
class Corner:
    shape: int
    subpath: int
    vertex: int      # between segment vertex - 1 and segment vertex (0: a closed subpath's start)
    turn: float      # radians
    half_width: float  # shape units
    at: np.ndarray   # the vertex, shape units
    # A corner the trace drew as curves: the lines on either side, segments vertex - 1 and
    # `last`, meet at `at` where extended, and the curves between them go (else -1).
    last: int = -1
    # A corner the trace drew as one curve (between anything): the curve's end tangents,
    # extended, meet at `at`; `last` is `vertex`, the curve.
    one_curve: bool = False


def stroked(shape) -> bool:
    """Whether a shape is a path drawn by its stroke alone (a line of line art)."""
    return isinstance(shape.geometry, Path) and shape.stroke is not None and shape.fill is None


def half_width(shape) -> float:
    """A stroke's half width, shape units."""
    return 0.5 * float(np.asarray(to_numpy(shape.stroke_width)).reshape(-1)[0])


def _unit(v: np.ndarray) -> np.ndarray:
    n = float(np.hypot(*v))
    return v / n if n > 0 else v * 0


def _end_tangent(c: np.ndarray, at_end: bool) -> np.ndarray:
    """A segment's unit tangent at its start or end (past coincident control points)."""
    pts = c[::-1] if at_end else c
    for q in pts[1:]:
        d = (pts[0] - q) if at_end else (q - pts[0])
        if np.hypot(*d) > 1e-9:
            return _unit(d)
    return np.zeros(2)


def _length_table(c: np.ndarray, n: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """Parameters t [n + 1] along the segment and the arc length to each."""
    t = np.linspace(0.0, 1.0, n + 1)
    pts = points_at(c, t)
    return t, np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])


def _trimmed(c: np.ndarray, d: float, at_end: bool) -> np.ndarray | None:
    """The segment less its first (or last) ``d`` of arc length; None where it is not
    longer than that by a fifth."""
    t, s = _length_table(c)
    total = s[-1]
    if total <= 1.2 * d:
        return None
    u = float(np.interp(total - d if at_end else d, s, t))
    left, right = split_at(c, u)
    return left if at_end else right


def _arc(a: np.ndarray, ta: np.ndarray, b: np.ndarray, tb: np.ndarray) -> np.ndarray:
    """A cubic from a (leaving along ta) to b (arriving along tb) as a circular arc would
    go: handles of 4/3 tan(phi / 4) times the radius the chord and the turn phi give."""
    phi = float(np.arccos(np.clip(ta @ tb, -1.0, 1.0)))
    chord = float(np.hypot(*(b - a)))
    if phi < 1e-6:
        k = chord / 3
    else:
        k = 4 / 3 * np.tan(phi / 4) * chord / (2 * np.sin(phi / 2))
    return np.stack([a, a + k * ta, b - k * tb, b])


def filleted(segs: list[np.ndarray], closed: bool, vertex: int, radius: float,
             corner: Corner | None = None) -> list[np.ndarray] | None:
    """The subpath's segments with the corner at ``vertex`` (see Corner) rounded by an arc
    of ``radius``; None where a segment beside it is too short for the trim. A corner drawn
    as curves (``corner.last`` >= 0) is made of its two lines, extended to meet, first
    (radius 0: a sharp corner there)."""
    if corner is not None and corner.one_curve:
        c = segs[vertex]
        lines = [np.stack([c[0], corner.at]), np.stack([corner.at, c[-1]])]
        if min(np.hypot(*(q[1] - q[0])) for q in lines) <= 1e-6:
            return None
        segs = segs[:vertex] + lines + segs[vertex + 1:]
        if radius <= 0:
            return segs
        vertex += 1
    elif corner is not None and corner.last >= 0:
        n = len(segs)
        a, b = segs[vertex - 1], segs[corner.last % n]
        lines = [np.stack([a[0], corner.at]), np.stack([corner.at, b[-1]])]
        if min(np.hypot(*(q[1] - q[0])) for q in lines) <= 1e-6:
            return None
        if corner.last == n:  # across a closed subpath's start (segment 0 is the second line)
            segs = [lines[1]] + segs[1:vertex - 1] + [lines[0]]
            vertex = 0
        else:
            segs = segs[:vertex - 1] + lines + segs[corner.last + 1:]
        if radius <= 0:
            return segs
    before = vertex - 1 if vertex > 0 else len(segs) - 1
    c_in, c_out = segs[before], segs[vertex]
    t_in, t_out = _end_tangent(c_in, True), _end_tangent(c_out, False)
    turn = float(np.arccos(np.clip(t_in @ t_out, -1.0, 1.0)))
    trim = radius * np.tan(turn / 2)
    a_seg, b_seg = _trimmed(c_in, trim, True), _trimmed(c_out, trim, False)
    if a_seg is None or b_seg is None:
        return None
    arc = _arc(a_seg[-1], _end_tangent(a_seg, True), b_seg[0], _end_tangent(b_seg, False))
    out = list(segs)
    out[before], out[vertex] = a_seg, b_seg
    if vertex == 0:  # a closed subpath's start: the arc goes last, and the start moves
        return out + [arc]
    return out[:vertex] + [arc] + out[vertex:]


def corners(scene, shapes: dict[int, list]) -> list[Corner]:
    """Every corner (a vertex turning TURN_MIN to TURN_MAX degrees) of the stroked paths
    of ``shapes`` (shape index -> scene.segments.subpath_segments)."""
    out = []
    lo, hi = np.radians(TURN_MIN), np.radians(TURN_MAX)
    for s, subs in shapes.items():
        sh = scene.shapes[s]
        if not stroked(sh) or sh.linejoin != "round":
            continue
        hw = half_width(sh)
        for j, (segs, closed) in enumerate(subs):
            curved = _curved_corners(s, j, segs, closed, hw)
            taken = {v % len(segs) for c in curved for v in range(c.vertex, c.last + 1)}  # (their vertices are theirs)
            out += curved
            for k in range(0 if closed else 1, len(segs) - 1):  # (a closed subpath's last curve: no)
                if k in taken or (k + 1) % len(segs) in taken or _is_line(segs[k]):
                    continue
                one = _one_curve_corner(s, j, k, segs, hw)
                if one is not None:
                    out.append(one)
                    taken |= {k, (k + 1) % len(segs)}
            for v in range(0 if closed else 1, len(segs)):
                if (v == 0 and len(segs) < 2) or v in taken:
                    continue
                c_in, c_out = segs[v - 1], segs[v]
                turn = float(np.arccos(np.clip(_end_tangent(c_in, True) @ _end_tangent(c_out, False), -1, 1)))
                if lo <= turn <= hi:
                    out.append(Corner(s, j, v, turn, hw, np.array(c_out[0])))
    return out


def _straightness(c: np.ndarray) -> float:
    """How far a segment's control points stray from its chord (px, shape units)."""
    d = c[-1] - c[0]
    length = float(np.hypot(*d))
    if length <= 1e-9:
        return np.inf
    return float(np.abs((c - c[0]) @ np.array([-d[1], d[0]])).max() / length)


def _one_curve_corner(shape: int, subpath: int, k: int, segs: list[np.ndarray], hw: float) -> Corner | None:
    """A curve that is a corner (a square's corner the trace drew as one cubic): between
    two all but straight segments (within NEIGHBOUR_STRAIGHT half widths of their chords)
    whose chords turn CURVE_TURN_MIN to TURN_MAX degrees and, drawn on from the curve's
    ends, meet within CURVED_REACH half widths of both; else None. (The curve's own end
    tangents point off: the fit bent the neighbours' last pixels into it.)"""
    n = len(segs)
    before, after = segs[k - 1], segs[(k + 1) % n]
    if max(_straightness(before), _straightness(after)) > NEIGHBOUR_STRAIGHT * hw:
        return None
    c = segs[k]
    a, b = c[0], c[-1]
    u, v = _unit(before[-1] - before[0]), _unit(after[-1] - after[0])
    turn = float(np.arccos(np.clip(u @ v, -1.0, 1.0)))
    if not np.radians(CURVE_TURN_MIN) <= turn <= np.radians(TURN_MAX):
        return None
    m = np.array([u, v]).T  # a + s u = b - t v
    if abs(np.linalg.det(m)) < 1e-9:
        return None
    s_, t_ = np.linalg.solve(m, b - a)
    if not (0 < s_ <= CURVED_REACH * hw and 0 < t_ <= CURVED_REACH * hw):
        return None
    return Corner(shape, subpath, k, turn, hw, a + s_ * u, last=k, one_curve=True)


def _is_line(c: np.ndarray) -> bool:
    return len(c) == 2


def _curved_corners(shape: int, subpath: int, segs: list[np.ndarray], closed: bool, hw: float) -> list[Corner]:
    """Corners the trace drew as curves: one to CURVED_MAX curved segments between two
    lines that turn TURN_MIN to TURN_MAX degrees from one to the other and, extended, meet
    within CURVED_REACH half widths of every point of the curves. Across a closed
    subpath's start only where its first segment is a line (round_corners turns it so):
    that corner's ``last`` is the number of segments."""
    out = []
    lo, hi = np.radians(TURN_MIN), np.radians(TURN_MAX)
    n = len(segs)
    lines = [i for i, c in enumerate(segs) if _is_line(c)]
    pairs = list(zip(lines, lines[1:]))
    if closed and lines and lines[0] == 0:
        pairs.append((lines[-1], n))
    for a, b in pairs:
        if not 1 <= b - a - 1 <= CURVED_MAX:
            continue
        p0, p1, q0, q1 = segs[a][0], segs[a][1], segs[b % n][0], segs[b % n][1]
        u, v = _unit(p1 - p0), _unit(q1 - q0)
        turn = float(np.arccos(np.clip(u @ v, -1.0, 1.0)))
        if not lo <= turn <= hi:
            continue
        # p1 + s u = q0 + t v
        m = np.array([u, -v]).T
        if abs(np.linalg.det(m)) < 1e-9:
            continue
        s_, t_ = np.linalg.solve(m, q0 - p1)
        at = p1 + s_ * u
        if s_ < -CURVED_REACH * hw or t_ > CURVED_REACH * hw:  # (the corner is ahead of the first line, behind the second)
            continue
        curve = np.concatenate([segs[k % n] for k in range(a + 1, b)])
        if np.hypot(*(curve - at).T).max() > CURVED_REACH * hw:
            continue
        out.append(Corner(shape, subpath, a + 1, turn, hw, at, last=b))
    return out


def traced_corners(scene, render_rgb, target_rgb: np.ndarray, size: tuple[int, int]) -> dict:
    """A trace's strokes before the fit, in place: small rings made polygons
    (polygons.py), then corners rounded where far better (round_corners at
    TRACED_CLEARLY_BETTER). Both need round joins. Where the tracer chose another join for
    its strokes (centerline._choose_caps: a bevel draws a rounded corner's outside nearer
    than a round join on the sharp corner thinning leaves), the strokes are tried with
    round joins and both passes, the fillets at CLEARLY_BETTER (the corners are likely
    round there), and kept so unless the tracer's join, on the trace as it was, is still
    clearly better (TRACER_JOIN_KEPT). Returns counts."""
    from .polygons import sharpen_loops

    others = [sh for sh in scene.shapes if stroked(sh) and sh.linejoin != "round"]
    saved = [(sh.geometry, sh.linejoin) for sh in scene.shapes]
    image = render_rgb(scene)
    before = float(((image - target_rgb) ** 2).mean())
    if others:
        for sh in others:
            sh.linejoin = "round"
        image = render_rgb(scene)
    loops, image = sharpen_loops(scene, render_rgb, target_rgb, size, image)
    rounded, image = round_corners(scene, render_rgb, target_rgb, size, image,
                                   clearly_better=CLEARLY_BETTER if others else TRACED_CLEARLY_BETTER)
    stats = {"corners": rounded["corners"], "rounded": rounded["rounded"], "polygons": loops["sharpened"]}
    if others:
        stats["joins_made_round"] = float(((image - target_rgb) ** 2).mean()) * TRACER_JOIN_KEPT <= before
        if not stats["joins_made_round"]:
            for sh, (geometry, join) in zip(scene.shapes, saved):
                sh.geometry, sh.linejoin = geometry, join
            stats.update(rounded=0, polygons=0)
    return stats


def round_corners(scene, render_rgb, target_rgb: np.ndarray, size: tuple[int, int], image=None,
                  clearly_better: float = CLEARLY_BETTER) -> tuple[dict, np.ndarray]:
    """Fillets at the corners of ``scene``'s strokes, in place, where the render says (see
    the module's text). ``image``: ``render_rgb(scene)`` where the caller has it. Returns
    counts, and the render of the scene as it is left."""
    shapes = path_segments(scene)
    for s, subs in shapes.items():  # closed subpaths start at a line, where they have one (_curved_corners)
        for j, (segs, closed) in enumerate(subs):
            first = next((k for k, c in enumerate(segs) if _is_line(c)), 0)
            if closed and first:
                subs[j] = (segs[first:] + segs[:first], closed)
    found = corners(scene, shapes)
    stats = {"corners": len(found), "rounded": 0}
    if image is None:
        image = render_rgb(scene)
    if not found:
        return stats, image
    originals = {c.shape: scene.shapes[c.shape].geometry for c in found}
    mats = np.asarray(to_numpy(shape_matrices(scene, size[0], size[1])), np.float64)
    h, w = image.shape[:2]

    def window(c: Corner) -> tuple[slice, slice]:
        """About the corner, wide enough for the largest fillet's trim."""
        m = mats[c.shape]
        scale = float(np.sqrt(abs(np.linalg.det(m[:2, :2]))))
        p = m[:2, :2] @ c.at + m[:2, 2]
        half = scale * c.half_width * (max(RADII) * np.tan(c.turn / 2) + WINDOW) + 2
        x0, x1 = int(max(0, np.floor(p[0] - half))), int(min(w, np.ceil(p[0] + half)))
        y0, y1 = int(max(0, np.floor(p[1] - half))), int(min(h, np.ceil(p[1] + half)))
        return slice(y0, y1), slice(x0, x1)

    def apply(choice: dict[int, float]) -> None:
        """choice: corner index -> radius factor (the corners of a subpath latest first, so
        that the vertex indices hold)."""
        subs_of: dict[int, list] = {}
        for i in sorted(choice, key=lambda i: -found[i].vertex):
            c = found[i]
            subs = subs_of.setdefault(c.shape, [(list(segs), closed) for segs, closed in shapes[c.shape]])
            segs, closed = subs[c.subpath]
            made = filleted(segs, closed, c.vertex, choice[i] * c.half_width, c)
            if made is not None:
                subs[c.subpath] = (made, closed)
        for s, g in originals.items():
            scene.shapes[s].geometry = with_segments(g, subs_of[s]) if s in subs_of else g

    def restore() -> None:
        for s, g in originals.items():
            scene.shapes[s].geometry = g

    choice, image = choose_in_windows(
        scene, render_rgb, target_rgb, image, {i: window(c) for i, c in enumerate(found)}, (0.0,) + RADII,
        lambda i, factor: factor > 0 or found[i].last >= 0,  # (0: sharp, where the lines meet)
        apply, restore, clearly_better)
    stats["rounded"] = len(choice)
    return stats, image
