"""SVG path data (the ``d`` attribute): read into subpaths of line, quadratic and cubic
segments, and written from them (``format_relative_path_data``, as the SVG writer and the
tracer write it; ``format_path_data``, absolute, for pydiffvg and the painter).

Written here rather than taken from svgelements because the Scene needs choices that
svgelements does not make for us: arcs as cubics of at most 90 degrees, ``Z`` as an
explicit closing line, zero-length subpaths kept, and SVG's error rule (draw the path up
to the first error instead of rejecting it).
"""
from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, field

import numpy as np

from .numbers import fmt, fmt_many
from .units import NUMBER

_TOKEN = re.compile(rf"[MmZzLlHhVvCcSsQqTtAa]|{NUMBER}|[^\s,]")
_COMMANDS = frozenset("MmZzLlHhVvCcSsQqTtAa")
_ARG_COUNT = {"m": 2, "l": 2, "h": 1, "v": 1, "c": 6, "s": 4, "q": 4, "t": 2, "a": 7}
_ARG_COUNT.update({c.upper(): n for c, n in _ARG_COUNT.items()})


@dataclass
class Subpath:
    """Points: the start, then per segment its control points and end (the closing line's
    end, equal to the start, is not stored)."""
    points: list = field(default_factory=list)   # [(x, y)]
    degrees: list = field(default_factory=list)  # [1 | 2 | 3]
    closed: bool = False


class PathDataError(ValueError):
    """Path data with an error; ``subpaths`` holds what was read before it. ``too_long``:
    the path has more segments than the limit it was read with."""

    def __init__(self, subpaths, too_long: bool = False):
        super().__init__("invalid path data")
        self.subpaths = subpaths
        self.too_long = too_long


class _Builder:
    """Collects segments while tracking the current point and the previous control point
    (for S and T, which reflect it)."""

    def __init__(self):
        self.subpaths: list[Subpath] = []
        self.current: Subpath | None = None
        self.start = (0.0, 0.0)
        self.point = (0.0, 0.0)
        self.last_cubic_ctrl = None  # second control point of the previous C/S
        self.last_quad_ctrl = None   # control point of the previous Q/T
        self.segments = 0

    def move(self, p):
        self.current = Subpath(points=[p])
        self.subpaths.append(self.current)
        self.start = self.point = p
        self._forget()

    def _open(self):
        # A drawing command right after Z starts a new subpath at the closed one's start.
        if self.current is None or self.current.closed:
            self.move(self.start)

    def _forget(self):
        self.last_cubic_ctrl = self.last_quad_ctrl = None

    # (line, cubic and quad are the parser's inner loop: each does the work of _open and
    # _forget itself rather than call them)
    def line(self, p):
        self.segments += 1
        current = self.current
        if current is None or current.closed:
            self.move(self.start)
            current = self.current
        current.points.append(p)
        current.degrees.append(1)
        self.point = p
        self.last_cubic_ctrl = self.last_quad_ctrl = None

    def cubic(self, c1, c2, p):
        self.segments += 1
        current = self.current
        if current is None or current.closed:
            self.move(self.start)
            current = self.current
        current.points += (c1, c2, p)
        current.degrees.append(3)
        self.point = p
        self.last_quad_ctrl = None
        self.last_cubic_ctrl = c2

    def quad(self, c, p):
        self.segments += 1
        current = self.current
        if current is None or current.closed:
            self.move(self.start)
            current = self.current
        current.points += (c, p)
        current.degrees.append(2)
        self.point = p
        self.last_cubic_ctrl = None
        self.last_quad_ctrl = c

    def close(self):
        if self.current is None or self.current.closed:
            # Z after Z (or before anything) closes an empty subpath at the start point.
            self.move(self.start)
        last = self.current.points[-1]
        if last != self.start and all(abs(a - b) <= 1e-12 * max(1.0, abs(b)) for a, b in zip(last, self.start)):
            # relative offsets that add up to the start but for float rounding (88.998 and
            # -5.6e-16 for 88.998, 0): the start, as the writer meant; else the Z's line of
            # next to no length makes the outline seem to cross itself there
            self.current.points[-1] = self.start
        self.current.degrees.append(1)  # explicit line back to the start, not stored twice
        self.current.closed = True
        self.point = self.start
        self._forget()

    def reflected(self, ctrl):
        if ctrl is None:
            return self.point
        return (2 * self.point[0] - ctrl[0], 2 * self.point[1] - ctrl[1])


def parse_path_data(d: str, max_segments: int | None = None) -> list[Subpath]:
    """Subpaths of ``d`` (empty ones, a moveto alone, are dropped). Raises PathDataError,
    carrying the subpaths read so far, at the first error; with too_long set when ``d``
    has more than ``max_segments`` segments."""
    b = _Builder()
    tokens = _TOKEN.findall(d or "")
    i, n = 0, len(tokens)
    # Cheap bounds first: a path with more than 8 tokens (numbers and commands) per
    # allowed segment is refused before it is built (movetos count, as they cost as much).
    if max_segments is not None and n > 8 * (max_segments + 1):
        raise PathDataError([], too_long=True)
    budget = max_segments if max_segments is not None else math.inf
    cmd = None
    try:
        while i < n:
            tok = tokens[i]
            if tok in _COMMANDS:
                cmd = tok
                i += 1
                if cmd in "Zz":
                    b.close()
                    continue
                if cmd not in "Mm" and b.current is None:
                    raise ValueError("path data must start with a moveto")
            elif cmd is None or cmd in "Zz":
                raise ValueError("number without a command")
            if cmd in "Aa":
                args, i = _arc_args(tokens, i)
                _APPLY[cmd](b, args)
                if len(b.subpaths) + b.segments > budget:
                    raise PathDataError([], too_long=True)
                continue
            # The command's groups of arguments, up to the next command letter (tiger's
            # paths are a C and dozens of curves each).
            count, apply = _ARG_COUNT[cmd], _APPLY[cmd]
            while True:
                if i + count > n:
                    raise ValueError("missing arguments")
                apply(b, list(map(float, tokens[i:i + count])))
                i += count
                if len(b.subpaths) + b.segments > budget:
                    raise PathDataError([], too_long=True)
                if cmd in "Mm":  # after a moveto, further coordinate pairs are implicit linetos
                    cmd = "L" if cmd == "M" else "l"
                    apply = _APPLY[cmd]
                if i >= n or tokens[i] in _COMMANDS:
                    break
    except PathDataError:
        raise
    except (ValueError, IndexError, OverflowError):
        raise PathDataError(_drop_empty(b.subpaths)) from None
    return _drop_empty(b.subpaths)


def _drop_empty(subpaths):
    return [s for s in subpaths if s.degrees]


def _arc_args(tokens, i):
    """rx ry angle large-arc sweep x y; the flags are single characters that may be written
    without separators ("0110 20" is 0, 1, 10, 20)."""
    args = [float(tokens[i]), float(tokens[i + 1]), float(tokens[i + 2])]
    i += 3
    for _ in range(2):
        tok = tokens[i]
        if not tok or tok[0] not in "01":
            raise ValueError("arc flag must be 0 or 1")
        args.append(float(tok[0]))
        if len(tok) > 1:
            tokens[i] = tok[1:]  # the rest of the token is the next argument
        else:
            i += 1
    args += [float(tokens[i]), float(tokens[i + 1])]
    return args, i + 2


# One function per command: ``a`` its arguments, absolute coordinates added to 0.0 as
# relative ones to the current point (so -0.0 reads as 0.0 either way).
def _m_abs(b, a):
    b.move((0.0 + a[0], 0.0 + a[1]))


def _m_rel(b, a):
    ox, oy = b.point
    b.move((ox + a[0], oy + a[1]))


def _l_abs(b, a):
    b.line((0.0 + a[0], 0.0 + a[1]))


def _l_rel(b, a):
    ox, oy = b.point
    b.line((ox + a[0], oy + a[1]))


def _c_abs(b, a):
    b.cubic((0.0 + a[0], 0.0 + a[1]), (0.0 + a[2], 0.0 + a[3]), (0.0 + a[4], 0.0 + a[5]))


def _c_rel(b, a):
    ox, oy = b.point
    b.cubic((ox + a[0], oy + a[1]), (ox + a[2], oy + a[3]), (ox + a[4], oy + a[5]))


_APPLY = {"M": _m_abs, "m": _m_rel, "L": _l_abs, "l": _l_rel, "C": _c_abs, "c": _c_rel,
          **{cmd: (lambda b, a, cmd=cmd: _apply(b, cmd, a)) for cmd in "HhVvSsQqTtAa"}}


def _apply(b: _Builder, cmd: str, a: list[float]) -> None:
    rel = cmd.islower()
    ox, oy = b.point if rel else (0.0, 0.0)
    c = cmd.lower()
    if c == "m":
        b.move((ox + a[0], oy + a[1]))
    elif c == "l":
        b.line((ox + a[0], oy + a[1]))
    elif c == "h":
        b.line((ox + a[0] if rel else a[0], b.point[1]))
    elif c == "v":
        b.line((b.point[0], oy + a[0] if rel else a[0]))
    elif c == "c":
        b.cubic((ox + a[0], oy + a[1]), (ox + a[2], oy + a[3]), (ox + a[4], oy + a[5]))
    elif c == "s":
        b.cubic(b.reflected(b.last_cubic_ctrl), (ox + a[0], oy + a[1]), (ox + a[2], oy + a[3]))
    elif c == "q":
        b.quad((ox + a[0], oy + a[1]), (ox + a[2], oy + a[3]))
    elif c == "t":
        b.quad(b.reflected(b.last_quad_ctrl), (ox + a[0], oy + a[1]))
    elif c == "a":
        end = (ox + a[5], oy + a[6])
        _arc(b, a[0], a[1], a[2], a[3] != 0, a[4] != 0, end)


def _arc(b: _Builder, rx, ry, angle, large, sweep, end) -> None:
    """An elliptical arc as cubics (SVG implementation notes F.6.5 and F.6.6)."""
    x1, y1 = b.point
    x2, y2 = end
    if (x1, y1) == (x2, y2):
        b._open()  # SVG: an arc to the current point is omitted
        b._forget()
        return
    rx, ry = abs(rx), abs(ry)
    if rx == 0 or ry == 0:
        b.line(end)
        return
    phi = math.radians(angle % 360)
    cos_p, sin_p = math.cos(phi), math.sin(phi)
    # Step 1: the midpoint in the ellipse's axis-aligned frame.
    dx, dy = (x1 - x2) / 2, (y1 - y2) / 2
    x1p = cos_p * dx + sin_p * dy
    y1p = -sin_p * dx + cos_p * dy
    # Radii too small to reach the end point are scaled up (F.6.6).
    lam = (x1p / rx) * (x1p / rx) + (y1p / ry) * (y1p / ry)  # (** raises on overflow)
    if lam > 1:
        s = math.sqrt(lam)
        rx, ry = rx * s, ry * s
    # Step 2: the centre in that frame.
    num = rx * rx * ry * ry - rx * rx * y1p * y1p - ry * ry * x1p * x1p
    den = rx * rx * y1p * y1p + ry * ry * x1p * x1p
    coef = math.sqrt(max(0.0, num / den)) if den > 0 else 0.0
    if large == sweep:
        coef = -coef
    cxp, cyp = coef * rx * y1p / ry, -coef * ry * x1p / rx
    # Step 3: the centre in user space and the angle range.
    cx = cos_p * cxp - sin_p * cyp + (x1 + x2) / 2
    cy = sin_p * cxp + cos_p * cyp + (y1 + y2) / 2
    theta1 = math.atan2((y1p - cyp) / ry, (x1p - cxp) / rx)
    theta2 = math.atan2((-y1p - cyp) / ry, (-x1p - cxp) / rx)
    delta = theta2 - theta1
    if sweep and delta < 0:
        delta += 2 * math.pi
    elif not sweep and delta > 0:
        delta -= 2 * math.pi
    if not math.isfinite(delta):
        b.line(end)
        return
    # Cubics of at most 90 degrees each (error below 3e-4 of the radius).
    pieces = max(1, math.ceil(abs(delta) / (math.pi / 2) - 1e-9))
    step = delta / pieces
    k = 4 / 3 * math.tan(step / 4)

    def at(t):  # point and derivative direction on the ellipse at angle t
        ct, st = math.cos(t), math.sin(t)
        px, py = rx * ct, ry * st
        tx, ty = -rx * st, ry * ct
        return ((cx + cos_p * px - sin_p * py, cy + sin_p * px + cos_p * py),
                (cos_p * tx - sin_p * ty, sin_p * tx + cos_p * ty))

    p0, d0 = at(theta1)
    p0 = (x1, y1)
    for j in range(1, pieces + 1):
        p1, d1 = at(theta1 + j * step)
        if j == pieces:
            p1 = end  # exactly the arc's end point, not a rounded one
        c1 = (p0[0] + k * d0[0], p0[1] + k * d0[1])
        c2 = (p1[0] - k * d1[0], p1[1] - k * d1[1])
        b.cubic(c1, c2, p1)
        p0, d0 = p1, d1
    b._forget()  # a following S or T does not reflect an arc's control point


def to_arrays(subpaths: list[Subpath]):
    """(points [P, 2] float64, degrees [G] int, subpath table) in the Scene's layout."""
    points, degrees, table = [], [], []
    for s in subpaths:
        table.append((len(degrees), len(s.degrees), s.closed))
        points += s.points
        degrees += s.degrees
    # (from a flat iterator: NumPy reads a list of pairs several times slower)
    pts = np.fromiter(itertools.chain.from_iterable(points), np.float64, 2 * len(points)).reshape(-1, 2)
    return pts, np.asarray(degrees, dtype=np.int64), table


_LETTERS = {1: "L", 2: "Q", 3: "C"}


def _segment_ends(degrees, subpaths):
    """Walk subpaths stored as a Scene's ``Path`` stores them: for each, (the index of its
    start point, [(degree, indices of the points each segment writes after its start)],
    closed). A closed subpath's last end is its start (not stored again), and its last
    segment, when it is a line, is left to the ``Z``."""
    degrees = np.asarray(degrees).tolist()
    p = 0
    for first, count, closed in subpaths:
        start, segments = p, []
        p += 1
        for k in range(first, first + count):
            d = int(degrees[k])
            last = closed and k == first + count - 1
            if last and d == 1:
                break
            stored = d - 1 if last else d
            segments.append((d, list(range(p, p + stored)) + ([start] if last else [])))
            p += stored
        yield start, segments, closed


def format_path_data(points, degrees, subpaths, decimals: int = 4, compact: bool = False) -> str:
    """Absolute M/L/Q/C/Z path data of subpaths stored as a Scene's ``Path`` stores them:
    ``points`` [P, 2] (finite numbers), per subpath its start, then each segment's
    control points and end, a closed subpath's last end (its start) not stored again;
    ``degrees`` per segment; ``subpaths`` (first segment, segment count, closed).

    A closed subpath's last segment is written as ``Z`` when it is a line, else in full
    and followed by ``Z``. Numbers have at most ``decimals`` decimals; ``compact`` leaves
    out the spaces before command letters. (pydiffvg's save_svg and the painter's random
    strokes; the SVG writer and the tracer write format_relative_path_data.)
    """
    # every point formatted once, as "x y" (a trace writes 50,000 numbers)
    numbers = fmt_many(points, decimals)
    text = [f"{x} {y}" for x, y in zip(numbers[0::2], numbers[1::2])]
    out = []
    for start, segments, closed in _segment_ends(degrees, subpaths):
        out.append("M" + text[start])
        out += [_LETTERS[d] + " ".join(text[i] for i in ends) for d, ends in segments]
        if closed:
            out.append("Z")
    return ("" if compact else " ").join(out)


def format_relative_path_data(points, degrees, subpaths, decimals: int = 2) -> str:
    """Relative m/l/h/v/q/c/z path data, as designers' tools and optimisers write it (Scene
    layout and Z rule as ``format_path_data``): the first subpath starts with an absolute
    ``M``, each later one with an ``m`` from where the previous one closed or ended, each
    segment is written as offsets from its start, axis-aligned lines as ``h``/``v``, and the
    text is the shortest the SVG grammar reads back the same: no leading zero (``.5``,
    ``-.5``), no separator where a minus sign or a second decimal point starts the next
    number (``1.5.5`` is 1.5 then .5), and a command letter left out where the previous
    segment had the same one. Offsets are short (5.11 where the point is at 340.38): a
    refined photograph's path data is a quarter smaller than absolute. The points are
    rounded to ``decimals`` first and every offset is the difference of two rounded
    points, so the path lands exactly where the absolute one would, with no drift along
    it."""
    a = np.asarray(points, np.float64)
    if not np.isfinite(a).all():
        fmt_many(a, decimals)  # raises, naming the value
    unit = 10 ** int(decimals)
    q = np.rint(a * unit).astype(np.int64).tolist()
    texts: dict[int, str] = {}

    def number(v: int) -> str:
        # (a table of every fraction's text was 10^decimals strings made per path: at 6
        # decimals a 1,096-path file took minutes)
        text = texts.get(v)
        if text is None:
            whole, frac = divmod(abs(v), unit)
            text = f"{whole}.{frac:0{decimals}d}".rstrip("0") if frac else str(whole)
            if text.startswith("0."):
                text = text[1:]
            text = texts[v] = "-" + text if v < 0 and text != "0" else text
        return text

    out: list[str] = []
    # what the text written so far ends with: a command letter (True), or a number with
    # (".") or without ("") a decimal point
    state = {"letter": True, "dot": False, "command": ""}

    def put(command: str, values) -> None:
        repeat = command == state["command"] and command not in "Mm"
        if not repeat:
            out.append(command)
            state["letter"], state["command"] = True, command
        for v in values:
            t = number(v)
            if not state["letter"] and not (t[0] == "-" or (t[0] == "." and state["dot"])):
                out.append(" ")
            out.append(t)
            state["letter"], state["dot"] = False, "." in t

    def close() -> None:
        out.append("z")
        state["letter"], state["command"] = True, "z"

    here = None  # the current point after the previous subpath (its start, when closed)
    for start, segments, closed in _segment_ends(degrees, subpaths):
        sx, sy = q[start]
        if here is None:
            put("M", (sx, sy))
        else:
            put("m", (sx - here[0], sy - here[1]))
        state["command"] = "m"  # a number after m's pair would be a line: never left implicit
        cx, cy = sx, sy
        for d, ends in segments:
            offsets = [(q[i][0] - cx, q[i][1] - cy) for i in ends]
            cx, cy = q[ends[-1]]
            if d == 1 and offsets[0][1] == 0:
                put("h", (offsets[0][0],))
            elif d == 1 and offsets[0][0] == 0:
                put("v", (offsets[0][1],))
            else:
                put(_LETTERS[d].lower(), [v for pair in offsets for v in pair])
        if closed:
            close()
            here = (sx, sy)
        else:
            here = (cx, cy)
    return "".join(out)
