"""An independent NumPy reference renderer for vecfit Scenes (a test helper).

It shares no code with ``vecfit._core`` or ``vecfit.renderer``: it reads the Scene dataclasses
(``vecfit/scene/model.py``) and point-samples them on a supersampled grid, box-filtered.

    render_reference(scene, width, height, samples=8, background=None) -> [H, W, 4] float64

returns straight RGBA in [0, 1]. The model, in short (details next to the code):

- Sampling: ``samples x samples`` points per pixel on a regular grid at ((j + 0.5) / samples)
  (or jittered inside each stratum with ``jitter=True``, seeded), averaged per pixel (box
  filter over [x, x+1) x [y, y+1); pixel centres at x + 0.5).
- Transforms: local -> pixel is diag(width / scene.width, height / scene.height, 1) @ view @
  (group transforms, root-most first) @ shape.transform. Coverage is evaluated in the shape's
  LOCAL space (sample points are mapped back with the inverse), so strokes under non-uniform
  scale or skew are exact.
- Geometry: Bezier segments are flattened into polylines with a chord error below
  ``FLATTEN_TOL_PX`` pixels (measured through the transform's largest singular value); rect,
  circle and ellipse fills are tested analytically; rounded-rect corners and ellipse strokes use
  finely sampled elliptical arcs.
- Fill: winding number w.r.t. all subpaths, each closed implicitly; nonzero or evenodd.
- Stroke: the SVG model in local space: per segment the sweep of its normals (polyline rectangles
  plus, at interior polyline vertices, the disk sectors between adjacent edges' normals), joins
  between consecutive non-degenerate segments (miter within the limit, else bevel; round; bevel),
  caps at the ends of open subpaths, dots or squares (local axes) for zero-length subpaths; a
  circle's stroke is the annulus |r - |p - c|| <= w / 2.
- Paints: solid, linear and radial (two-point, focal clamped into the circle) gradients with pad
  spread, interpolated in straight RGBA, then premultiplied; gradientTransform and both units.
- Compositing: premultiplied source-over in paint order; fill then stroke; shape opacity and
  group opacity are layers (the layer is composited and then scaled). Group layers open and close
  as the group chain of consecutive shapes changes, so a group's shapes must be contiguous.
"""
from __future__ import annotations

import math

import numpy as np

# Chord error of the flattening, in output pixels. Small enough that flattening errors are far
# below what the supersampling resolves (a 1e-4 px band along a 200 px outline is 0.02 px^2).
FLATTEN_TOL_PX = 1e-4
MAX_PIECES = 4096
# A radial gradient's focal point lying outside its circle (or on it) is moved towards the centre
# onto FOCAL_CLAMP * r from the centre (SVG 1.1 says "onto the circle", which makes the cone
# degenerate; resvg and most renderers move it slightly inside).
FOCAL_CLAMP = 0.999
# Bound on the point x primitive pairs evaluated at once (memory ~ 8 bytes x this x a few).
_CHUNK_PAIRS = 1 << 21


# ================================================================================ helpers

def _np(x) -> np.ndarray:
    """A torch tensor, numpy array or sequence as a float64 numpy array."""
    if hasattr(x, "detach"):
        x = x.detach().cpu().double().numpy()
    return np.asarray(x, dtype=np.float64)


def _apply(m: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Apply the 3x3 affine matrix ``m`` to points [..., 2]."""
    x, y = p[..., 0], p[..., 1]
    return np.stack([m[0, 0] * x + m[0, 1] * y + m[0, 2], m[1, 0] * x + m[1, 1] * y + m[1, 2]],
                    axis=-1)


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _unit(v):
    n = math.hypot(v[0], v[1])
    return None if n == 0.0 else np.array([v[0] / n, v[1] / n])


# ========================================================================= Bezier curves

def bezier_eval(ctrl: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points of the Bezier curve with control points ``ctrl`` [d+1, 2] at parameters t [m]."""
    ctrl = np.asarray(ctrl, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)[:, None]
    d = len(ctrl) - 1
    out = np.zeros((t.shape[0], 2))
    for k in range(d + 1):
        out += math.comb(d, k) * (1 - t) ** (d - k) * t ** k * ctrl[k]
    return out


def bezier_pieces(ctrl: np.ndarray, tol: float) -> int:
    """Uniform pieces in t so that the chord error is below ``tol``: the chord error of a piece of
    parameter length h is at most max|B''| h^2 / 8, and max|B''| <= d (d - 1) times the largest
    second difference of the control points."""
    d = len(ctrl) - 1
    if d <= 1:
        return 1
    sd = ctrl[2:] - 2 * ctrl[1:-1] + ctrl[:-2]
    m2 = d * (d - 1) * float(np.max(np.hypot(sd[:, 0], sd[:, 1])))
    if m2 == 0.0:
        return 1
    return int(min(MAX_PIECES, max(1, math.ceil(math.sqrt(m2 / (8.0 * tol))))))


def flatten_bezier(ctrl: np.ndarray, tol: float) -> np.ndarray:
    """A polyline [n+1, 2] through the curve, endpoints exact."""
    ctrl = np.asarray(ctrl, dtype=np.float64)
    n = bezier_pieces(ctrl, tol)
    pts = bezier_eval(ctrl, np.linspace(0.0, 1.0, n + 1))
    pts[0], pts[-1] = ctrl[0], ctrl[-1]
    return pts


def bezier_bbox(ctrl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tight bounding box of a Bezier segment (endpoints plus the extrema of each coordinate)."""
    ctrl = np.asarray(ctrl, dtype=np.float64)
    d = len(ctrl) - 1
    ts = [0.0, 1.0]
    if d >= 2:
        dc = d * (ctrl[1:] - ctrl[:-1])  # derivative control points (degree d - 1)
        for axis in range(2):
            c = dc[:, axis]
            if d == 2:  # linear derivative
                a, b = c[1] - c[0], c[0]
                if a != 0.0:
                    ts.append(-b / a)
            else:  # quadratic derivative in Bernstein form -> power form
                a = c[0] - 2 * c[1] + c[2]
                b = 2 * (c[1] - c[0])
                cc = c[0]
                if abs(a) > 1e-14 * (abs(b) + abs(cc) + 1e-300):
                    disc = b * b - 4 * a * cc
                    if disc >= 0.0:
                        s = math.sqrt(disc)
                        ts += [(-b + s) / (2 * a), (-b - s) / (2 * a)]
                elif b != 0.0:
                    ts.append(-cc / b)
    ts = np.clip(np.array([t for t in ts if -1e-12 <= t <= 1 + 1e-12]), 0.0, 1.0)
    pts = bezier_eval(ctrl, ts)
    return pts.min(axis=0), pts.max(axis=0)


# ===================================================================== outline building
#
# An outline is a list of subpaths; a subpath is (segments, closed); a segment is a _Seg: a fine
# polyline from its start point to its end point plus the exact unit tangents at both ends (None
# for a zero-length segment, whose control points all coincide).

class _Seg:
    __slots__ = ("pts", "t0", "t1")

    def __init__(self, pts, t0, t1):
        self.pts, self.t0, self.t1 = pts, t0, t1

    @property
    def degenerate(self):
        return self.t0 is None


def _bezier_seg(ctrl: np.ndarray, tol: float) -> _Seg:
    ctrl = np.asarray(ctrl, dtype=np.float64)
    t0 = t1 = None
    for k in range(1, len(ctrl)):          # first control point distinct from p0
        t0 = _unit(ctrl[k] - ctrl[0])
        if t0 is not None:
            break
    for k in range(len(ctrl) - 2, -1, -1):  # last control point distinct from p_end
        t1 = _unit(ctrl[-1] - ctrl[k])
        if t1 is not None:
            break
    if t0 is None:
        return _Seg(ctrl[:1].copy(), None, None)
    return _Seg(flatten_bezier(ctrl, tol), t0, t1)


def _arc_seg(center, rx, ry, a0, a1, tol: float) -> _Seg:
    """The elliptical arc center + (rx cos a, ry sin a), a from a0 to a1."""
    r = max(rx, ry)
    n = int(min(MAX_PIECES, max(4, math.ceil(abs(a1 - a0) / math.sqrt(8 * tol / r)))))
    a = np.linspace(a0, a1, n + 1)
    pts = np.stack([center[0] + rx * np.cos(a), center[1] + ry * np.sin(a)], axis=1)
    sgn = 1.0 if a1 > a0 else -1.0
    t0 = _unit(sgn * np.array([-rx * math.sin(a0), ry * math.cos(a0)]))
    t1 = _unit(sgn * np.array([-rx * math.sin(a1), ry * math.cos(a1)]))
    return _Seg(pts, t0, t1)


def path_segments(points, degrees, subpaths) -> list[tuple[list[np.ndarray], bool]]:
    """Control points of every segment of a scene.Path layout: [(list of [d+1, 2], closed)]."""
    points = _np(points).reshape(-1, 2)
    degrees = np.asarray(degrees).astype(int)
    out, p = [], 0
    for first, count, closed in subpaths:
        first, count, closed = int(first), int(count), bool(closed)
        degs = degrees[first:first + count]
        n = int(degs.sum()) + (0 if closed else 1)
        pts = points[p:p + n]
        p += n
        if count == 0:
            continue
        if closed:
            pts = np.concatenate([pts, pts[:1]])
        segs, i = [], 0
        for d in degs:
            segs.append(pts[i:i + d + 1])
            i += d
        out.append((segs, closed))
    return out


def _path_outline(path, tol):
    return [([_bezier_seg(c, tol) for c in segs], closed)
            for segs, closed in path_segments(path.points, path.degrees, path.subpaths)]


def _rect_outline(p_min, p_max, rx, ry, tol):
    x0, y0 = p_min
    x1, y1 = p_max
    line = lambda a, b: _bezier_seg(np.array([a, b], dtype=np.float64), tol)
    if rx <= 0 or ry <= 0:
        c = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
        return [([line(c[i], c[(i + 1) % 4]) for i in range(4)], True)]
    h = math.pi / 2
    segs = [line((x0 + rx, y0), (x1 - rx, y0)),
            _arc_seg((x1 - rx, y0 + ry), rx, ry, -h, 0.0, tol),
            line((x1, y0 + ry), (x1, y1 - ry)),
            _arc_seg((x1 - rx, y1 - ry), rx, ry, 0.0, h, tol),
            line((x1 - rx, y1), (x0 + rx, y1)),
            _arc_seg((x0 + rx, y1 - ry), rx, ry, h, 2 * h, tol),
            line((x0, y1 - ry), (x0, y0 + ry)),
            _arc_seg((x0 + rx, y0 + ry), rx, ry, 2 * h, 3 * h, tol)]
    return [(segs, True)]


def _ellipse_outline(center, rx, ry, tol):
    return [([_arc_seg(center, rx, ry, 0.0, 2 * math.pi, tol)], True)]


# ========================================================================= fill coverage

def winding_numbers(polylines, q) -> np.ndarray:
    """Winding numbers of points q [M, 2] w.r.t. polylines (each [n, 2], closed implicitly).

    Crossings of the ray from q towards +x; an edge counts for ymin <= q.y < ymax (half-open, so a
    ray through a vertex counts once). Upward edges (increasing y) count +1, so a loop that is
    counter-clockwise in a y-up frame has winding +1.
    """
    q = np.asarray(q, dtype=np.float64).reshape(-1, 2)
    M = len(q)
    order = np.argsort(q[:, 1], kind="stable")
    ys, xs = q[order, 1], q[order, 0]
    wn = np.zeros(M, dtype=np.float64)
    for poly in polylines:
        poly = np.asarray(poly, dtype=np.float64)
        if len(poly) < 2:
            continue
        a, b = poly, np.roll(poly, -1, axis=0)
        keep = a[:, 1] != b[:, 1]
        a, b = a[keep], b[keep]
        if len(a) == 0:
            continue
        lo = np.searchsorted(ys, np.minimum(a[:, 1], b[:, 1]), side="left")
        hi = np.searchsorted(ys, np.maximum(a[:, 1], b[:, 1]), side="left")
        cnt = hi - lo
        nz = np.nonzero(cnt > 0)[0]
        if len(nz) == 0:
            continue
        # process edges in chunks so that the flattened (edge, point) pairs stay bounded
        csum = np.cumsum(cnt[nz])
        start = 0
        while start < len(nz):
            base = csum[start - 1] if start > 0 else 0
            stop = int(np.searchsorted(csum, base + _CHUNK_PAIRS, side="right"))
            stop = max(stop, start + 1)
            e = nz[start:stop]
            c = cnt[e]
            eid = np.repeat(np.arange(len(e)), c)
            offs = np.arange(int(c.sum())) - np.repeat(np.cumsum(c) - c, c)
            idx = lo[e][eid] + offs
            ae, be = a[e][eid], b[e][eid]
            y = ys[idx]
            xc = ae[:, 0] + (y - ae[:, 1]) * (be[:, 0] - ae[:, 0]) / (be[:, 1] - ae[:, 1])
            sgn = np.where(be[:, 1] > ae[:, 1], 1.0, -1.0)
            contrib = np.where(xc > xs[idx], sgn, 0.0)
            wn += np.bincount(idx, weights=contrib, minlength=M)
            start = stop
    out = np.empty(M, dtype=np.int64)
    out[order] = np.rint(wn).astype(np.int64)
    return out


def _fill_mask(geom, kind, q, tol, fill_rule):
    if kind == "path":
        polys = []
        for segs, _closed in geom:
            pts = [segs[0].pts[:1]] + [s.pts[1:] for s in segs]
            polys.append(np.concatenate(pts))
        w = winding_numbers(polys, q)
        return (w % 2 == 1) if fill_rule == "evenodd" else (w != 0)
    if kind == "circle":
        c, r = geom
        return np.hypot(q[:, 0] - c[0], q[:, 1] - c[1]) <= r
    if kind == "ellipse":
        c, rx, ry = geom
        return ((q[:, 0] - c[0]) / rx) ** 2 + ((q[:, 1] - c[1]) / ry) ** 2 <= 1.0
    if kind == "rect":
        (x0, y0), (x1, y1), rx, ry = geom
        inside = (q[:, 0] >= x0) & (q[:, 0] <= x1) & (q[:, 1] >= y0) & (q[:, 1] <= y1)
        if rx > 0 and ry > 0:
            dx = np.maximum(0.0, np.maximum(x0 + rx - q[:, 0], q[:, 0] - (x1 - rx)))
            dy = np.maximum(0.0, np.maximum(y0 + ry - q[:, 1], q[:, 1] - (y1 - ry)))
            inside &= (dx / rx) ** 2 + (dy / ry) ** 2 <= 1.0
        return inside
    raise TypeError(kind)


# ======================================================================= stroke coverage

def _in_disk(q, c, r):
    return (q[:, 0] - c[0]) ** 2 + (q[:, 1] - c[1]) ** 2 <= r * r


def _in_convex(q, poly):
    """Points q inside the convex polygon ``poly`` [k, 2] (either orientation; closed boundary)."""
    poly = np.asarray(poly, dtype=np.float64)
    e = np.roll(poly, -1, axis=0) - poly
    area2 = float(np.sum(_cross(poly, np.roll(poly, -1, axis=0))))
    if abs(area2) < 1e-18:
        return np.zeros(len(q), dtype=bool)
    s = 1.0 if area2 > 0 else -1.0
    inside = np.ones(len(q), dtype=bool)
    for i in range(len(poly)):
        inside &= s * _cross(e[i], q - poly[i]) >= 0.0
    return inside


def _dedupe(pts):
    keep = np.ones(len(pts), dtype=bool)
    keep[1:] = np.any(pts[1:] != pts[:-1], axis=1)
    return pts[keep]


def _sweep(q, covered, pts, h, t0=None, t1=None):
    """Mark points of q within the sweep of a segment's normals of half-length h (updates
    ``covered`` in place), from its fine polyline ``pts`` and its exact unit end tangents:

    - for each polyline edge a-b, the points within h of the edge's line that lie between the
      line through a perpendicular to the edge and the one through b (a rectangle) -- except
      that the segment's first edge starts at the line through a perpendicular to the exact
      tangent t0, and its last edge ends at the one perpendicular to t1, so that the sweep
      begins and ends exactly on the segment's true end normals (a chord's direction differs from
      the tangent there, which would leave a sliver of a gap at a smooth join, or poke past a
      butt end);
    - at each interior polyline vertex V, the circular sector between the normals of the edges
      before and after it: the disk |q - V| <= h cut to (q - V).d_in >= 0 and (q - V).d_out <= 0
      (d the unit edge directions), which fills the wedge on the outer side of the turn.
    (Whole disks at the interior vertices would be simpler, but the disk at the vertex next to a
    segment's end protrudes up to h past a butt end, since the last polyline edge is short.)
    """
    pts = _dedupe(pts)
    n = len(pts) - 1
    if n < 1:
        return
    d_all = pts[1:] - pts[:-1]
    ll_all = np.einsum("ij,ij->i", d_all, d_all)
    u_all = d_all / np.sqrt(ll_all)[:, None]
    s_all, e_all = u_all.copy(), u_all.copy()  # directions of the start and end lines' normals
    if t0 is not None:
        s_all[0] = t0
    if t1 is not None:
        e_all[-1] = t1
    # candidates near the whole polyline, sorted by x, so that each chunk of edges finds its
    # own candidates by a binary search on x and a mask on y
    lo, hi = pts.min(axis=0) - h, pts.max(axis=0) + h
    near = np.nonzero((q[:, 0] >= lo[0]) & (q[:, 0] <= hi[0])
                      & (q[:, 1] >= lo[1]) & (q[:, 1] <= hi[1]))[0]
    near = near[np.argsort(q[near, 0], kind="stable")]
    near_x, near_y = q[near, 0], q[near, 1]
    K = 16
    for s in range(0, n, K):
        e = slice(s, min(n, s + K))                     # edges of this chunk
        v = pts[s:min(n, s + K) + 1]
        lo, hi = v.min(axis=0) - h, v.max(axis=0) + h
        i0 = np.searchsorted(near_x, lo[0], side="left")
        i1 = np.searchsorted(near_x, hi[0], side="right")
        sub = near[i0:i1]
        ys = near_y[i0:i1]
        cand = sub[(ys >= lo[1]) & (ys <= hi[1]) & ~covered[sub]]
        if len(cand) == 0:
            continue
        a, d, ll = pts[:-1][e], d_all[e], ll_all[e]
        sd, ed = s_all[e], e_all[e]
        ed_d = np.einsum("kj,kj->k", ed, d)
        # interior vertices at the end of this chunk's edges (vertex k + 1 for edge k < n - 1)
        k_iv = np.arange(e.start, min(e.stop, n - 1))
        iv, din, dout = pts[k_iv + 1], u_all[k_iv], u_all[k_iv + 1]
        step = max(1, _CHUNK_PAIRS // max(1, len(a) + len(iv)))
        for c0 in range(0, len(cand), step):
            ci = cand[c0:c0 + step]
            qq = q[ci]
            r = qq[:, None, :] - a[None, :, :]
            after_start = np.einsum("mkj,kj->mk", r, sd) >= 0.0
            before_end = np.einsum("mkj,kj->mk", r, ed) <= ed_d   # (q - b).ed <= 0
            dist = np.abs(_cross(d[None, :, :], r)) / np.sqrt(ll)
            hit = np.any(after_start & before_end & (dist <= h), axis=1)
            if len(iv):
                r = qq[:, None, :] - iv[None, :, :]
                sector = ((r ** 2).sum(-1) <= h * h) \
                    & (np.einsum("mkj,kj->mk", r, din) >= 0.0) \
                    & (np.einsum("mkj,kj->mk", r, dout) <= 0.0)
                hit |= np.any(sector, axis=1)
            covered[ci] |= hit


def _right(t):
    return np.array([t[1], -t[0]])


def _join_mask(q, v, tin, tout, h, join, miter_limit):
    cr = float(_cross(tin, tout))
    dot = float(np.dot(tin, tout))
    if abs(cr) < 1e-12 and dot > 0:
        return None  # no turn
    if join == "round":
        return _in_disk(q, v, h)
    s = 1.0 if cr >= 0 else -1.0   # turning left (cross > 0): the outer side is the right
    o_in, o_out = s * _right(tin), s * _right(tout)
    cos_half = math.sqrt(max(0.0, (1.0 + dot) / 2.0))  # cos(phi / 2), phi the turning angle
    if join == "miter" and cos_half > 0 and 1.0 / cos_half <= miter_limit:
        bis = _unit(o_in + o_out)
        tip = v + (h / cos_half) * bis
        return _in_convex(q, [v, v + h * o_in, tip, v + h * o_out])
    return _in_convex(q, [v, v + h * o_in, v + h * o_out])  # bevel


def _cap_mask(q, v, t, h, cap):
    if cap == "round":
        return _in_disk(q, v, h)
    if cap == "square":
        n = _right(t)
        return _in_convex(q, [v + h * n, v + h * n + h * t, v - h * n + h * t, v - h * n])
    return None


def _stroke_mask(outline, q, w, cap, join, miter_limit):
    h = 0.5 * w
    covered = np.zeros(len(q), dtype=bool)
    for segs, closed in outline:
        nd = [s for s in segs if not s.degenerate]
        if not nd:  # zero-length subpath
            p = segs[0].pts[0]
            if cap == "round":
                covered |= _in_disk(q, p, h)
            elif cap == "square":
                covered |= ((np.abs(q[:, 0] - p[0]) <= h) & (np.abs(q[:, 1] - p[1]) <= h))
            continue
        for s in nd:
            _sweep(q, covered, s.pts, h, s.t0, s.t1)
        joins = [(nd[i].pts[-1], nd[i].t1, nd[i + 1].t0) for i in range(len(nd) - 1)]
        if closed:
            joins.append((nd[0].pts[0], nd[-1].t1, nd[0].t0))
        for v, tin, tout in joins:
            m = _join_mask(q, v, tin, tout, h, join, miter_limit)
            if m is not None:
                covered |= m
        if not closed:
            for v, t in ((nd[0].pts[0], -nd[0].t0), (nd[-1].pts[-1], nd[-1].t1)):
                m = _cap_mask(q, v, t, h, cap)
                if m is not None:
                    covered |= m
    return covered


# ================================================================================ paints

def stop_colors(offsets, colors, t) -> np.ndarray:
    """Straight RGBA [M, 4] of the stops at t (pad spread: clamped to the first / last stop)."""
    offsets = _np(offsets).reshape(-1)
    colors = _np(colors).reshape(-1, 4)
    t = np.asarray(t, dtype=np.float64)
    if len(offsets) == 1:
        return np.broadcast_to(colors[0], t.shape + (4,)).copy()
    i = np.searchsorted(offsets, t, side="right")  # offsets[i-1] <= t < offsets[i]
    out = np.empty(t.shape + (4,))
    before, after = i == 0, i >= len(offsets)
    out[before] = colors[0]
    out[after] = colors[-1]
    mid = ~(before | after)
    j = i[mid]
    o0, o1 = offsets[j - 1], offsets[j]
    f = ((t[mid] - o0) / (o1 - o0))[:, None]
    out[mid] = (1 - f) * colors[j - 1] + f * colors[j]
    return out


def paint_straight(paint, q, bbox) -> np.ndarray:
    """Straight RGBA [M, 4] of a paint at local points q [M, 2]; ``bbox`` = (min, max) of the
    shape's local fill geometry, used by objectBoundingBox units."""
    from vecfit.scene import LinearGradient, RadialGradient, Solid
    M = len(q)
    if isinstance(paint, Solid):
        return np.broadcast_to(_np(paint.color).reshape(4), (M, 4)).copy()
    if not isinstance(paint, (LinearGradient, RadialGradient)):
        raise TypeError(type(paint))
    m = _np(paint.transform).reshape(3, 3)
    if paint.units == "objectBoundingBox":
        lo, hi = bbox
        size = hi - lo
        if size[0] <= 0 or size[1] <= 0:
            return np.zeros((M, 4))  # SVG: a bbox gradient on a zero-area bbox paints nothing
        m = np.array([[size[0], 0, lo[0]], [0, size[1], lo[1]], [0, 0, 1.0]]) @ m
    elif paint.units != "userSpaceOnUse":
        raise ValueError(paint.units)
    if abs(np.linalg.det(m[:2, :2])) < 1e-300:
        return np.zeros((M, 4))
    g = _apply(np.linalg.inv(m), q)  # gradient coordinates
    offsets, colors = paint.offsets, paint.colors
    if isinstance(paint, LinearGradient):
        s, e = _np(paint.start).reshape(2), _np(paint.end).reshape(2)
        d = e - s
        dd = float(d @ d)
        if dd == 0.0:
            return stop_colors(offsets, colors, np.ones(M))  # last stop colour
        t = (g - s) @ d / dd
    else:
        c, f = _np(paint.center).reshape(2), _np(paint.focal).reshape(2)
        r = float(_np(paint.radius).reshape(()))
        if r <= 0.0:
            return stop_colors(offsets, colors, np.ones(M))
        fc = f - c
        dist = math.hypot(fc[0], fc[1])
        if dist > FOCAL_CLAMP * r:
            f = c + fc * (FOCAL_CLAMP * r / dist)
        # largest t >= 0 with |g - (f + t (c - f))| = t r
        d = c - f
        u = g - f
        a = float(d @ d) - r * r  # < 0: the focal point is inside the circle
        b = u @ d
        cc = np.einsum("ij,ij->i", u, u)
        t = (b - np.sqrt(b * b - a * cc)) / a
    return stop_colors(offsets, colors, np.clip(t, 0.0, 1.0))


def _premul(c):
    out = c.copy()
    out[..., :3] *= out[..., 3:4]
    return out


# ============================================================================== shapes

def _shape_matrix(scene, shape, width, height) -> np.ndarray:
    chain, g = [], shape.group
    while g is not None and g >= 0:
        chain.append(g)
        g = scene.groups[g].parent
    m = np.diag([width / float(scene.width), height / float(scene.height), 1.0])
    m = m @ _np(scene.view).reshape(3, 3)
    for gi in reversed(chain):
        m = m @ _np(scene.groups[gi].transform).reshape(3, 3)
    return m @ _np(shape.transform).reshape(3, 3)


def _group_chain(scene, shape) -> list[int]:
    chain, g = [], shape.group
    while g is not None and g >= 0:
        chain.append(g)
        g = scene.groups[g].parent
    return chain[::-1]


def _prepare_geometry(geometry, tol):
    """(kind, fill data, outline for the stroke or None, local fill bbox) or None if not drawn."""
    from vecfit.scene import Circle, Ellipse, Path, Rect
    if isinstance(geometry, Path):
        outline = _path_outline(geometry, tol)
        if not outline:
            return None
        boxes = [bezier_bbox(c) for segs, _ in path_segments(geometry.points, geometry.degrees,
                                                             geometry.subpaths) for c in segs]
        bbox = (np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0))
        return "path", outline, outline, bbox
    if isinstance(geometry, Circle):
        c, r = _np(geometry.center).reshape(2), float(_np(geometry.radius).reshape(()))
        if r <= 0:
            return None
        return "circle", (c, r), None, (c - r, c + r)
    if isinstance(geometry, Ellipse):
        c, (rx, ry) = _np(geometry.center).reshape(2), _np(geometry.radii).reshape(2)
        if rx <= 0 or ry <= 0:
            return None
        return "ellipse", (c, rx, ry), _ellipse_outline(c, rx, ry, tol), \
            (c - [rx, ry], c + [rx, ry])
    if isinstance(geometry, Rect):
        p0, p1 = _np(geometry.p_min).reshape(2), _np(geometry.p_max).reshape(2)
        rx, ry = _np(geometry.corner_radii).reshape(2)
        if p1[0] <= p0[0] or p1[1] <= p0[1]:
            return None
        return "rect", (p0, p1, rx, ry), _rect_outline(p0, p1, rx, ry, tol), (p0, p1)
    raise TypeError(type(geometry))


def _ink_bbox(kind, fill_data, outline, bbox, shape, has_stroke):
    """Conservative local-space bounding box of everything the shape may draw."""
    lo, hi = np.array(bbox[0], dtype=np.float64), np.array(bbox[1], dtype=np.float64)
    if kind == "path":  # control polygons (convex hull property) cover the flattened outline
        allp = np.concatenate([s.pts for segs, _ in outline for s in segs])
        lo, hi = np.minimum(lo, allp.min(axis=0)), np.maximum(hi, allp.max(axis=0))
    if has_stroke:
        h = 0.5 * float(_np(shape.stroke_width).reshape(()))
        f = max(1.0, math.sqrt(2.0), shape.miter_limit if shape.linejoin == "miter" else 1.0)
        lo, hi = lo - h * f, hi + h * f
    return lo, hi


class _Grid:
    """The supersampled grid: sample (jy, jx) lies at ((jx + ox) / s, (jy + oy) / s) pixels."""

    def __init__(self, width, height, s, jitter, seed):
        self.W, self.H, self.s = width, height, s
        if jitter:
            rng = np.random.default_rng(seed)
            self.off = rng.random((height * s, width * s, 2))
        else:
            self.off = None

    def window(self, lo, hi):
        s = self.s
        jx0 = max(0, int(math.floor(lo[0] * s)) - 1)
        jy0 = max(0, int(math.floor(lo[1] * s)) - 1)
        jx1 = min(self.W * s, int(math.ceil(hi[0] * s)) + 1)
        jy1 = min(self.H * s, int(math.ceil(hi[1] * s)) + 1)
        return jy0, jy1, jx0, jx1

    def points(self, jy0, jy1, jx0, jx1):
        jy, jx = np.meshgrid(np.arange(jy0, jy1, dtype=np.float64),
                             np.arange(jx0, jx1, dtype=np.float64), indexing="ij")
        if self.off is None:
            x, y = jx + 0.5, jy + 0.5
        else:
            o = self.off[jy0:jy1, jx0:jx1]
            x, y = jx + o[..., 0], jy + o[..., 1]
        return np.stack([x.ravel(), y.ravel()], axis=1) / self.s


def _draw_shape(scene, shape, grid, width, height):
    """(window, premultiplied layer [M, 4]) of one shape, or None when it draws nothing."""
    m = _shape_matrix(scene, shape, width, height)
    A = m[:2, :2]
    if abs(np.linalg.det(A)) < 1e-300:
        return None
    smax = float(np.linalg.svd(A, compute_uv=False)[0])
    tol = FLATTEN_TOL_PX / smax
    prep = _prepare_geometry(shape.geometry, tol)
    if prep is None:
        return None
    kind, fill_data, outline, bbox = prep
    w = float(_np(shape.stroke_width).reshape(()))
    has_fill = shape.fill is not None
    has_stroke = shape.stroke is not None and w > 0
    if not (has_fill or has_stroke):
        return None
    lo, hi = _ink_bbox(kind, fill_data, outline, bbox, shape, has_stroke)
    corners = _apply(m, np.array([[lo[0], lo[1]], [hi[0], lo[1]], [lo[0], hi[1]], [hi[0], hi[1]]]))
    win = grid.window(corners.min(axis=0), corners.max(axis=0))
    if win[1] <= win[0] or win[3] <= win[2]:
        return None
    q = _apply(np.linalg.inv(m), grid.points(*win))
    layer = np.zeros((len(q), 4))
    if has_fill:
        mask = _fill_mask(fill_data, kind, q, tol, shape.fill_rule)
        if mask.any():
            col = paint_straight(shape.fill, q[mask], bbox)
            col[:, 3] *= float(_np(shape.fill_opacity).reshape(()))
            layer[mask] = _premul(col)
    if has_stroke:
        if kind == "circle":
            c, r = fill_data
            mask = np.abs(r - np.hypot(q[:, 0] - c[0], q[:, 1] - c[1])) <= 0.5 * w
        else:
            mask = _stroke_mask(outline, q, w, shape.linecap, shape.linejoin,
                                float(shape.miter_limit))
        if mask.any():
            col = paint_straight(shape.stroke, q[mask], bbox)
            col[:, 3] *= float(_np(shape.stroke_opacity).reshape(()))
            src = _premul(col)
            layer[mask] = src + (1.0 - src[:, 3:4]) * layer[mask]
    layer *= float(_np(shape.opacity).reshape(()))
    return win, layer


def _over(dst, win, src):
    jy0, jy1, jx0, jx1 = win
    d = dst[jy0:jy1, jx0:jx1].reshape(-1, 4)
    d[:] = src + (1.0 - src[:, 3:4]) * d
    dst[jy0:jy1, jx0:jx1] = d.reshape(jy1 - jy0, jx1 - jx0, 4)


def render_reference(scene, width, height, samples=8, background=None, *, jitter=False, seed=0,
                     premultiplied=False) -> np.ndarray:
    """Render ``scene`` at ``width`` x ``height`` pixels; straight RGBA [H, W, 4] float64 in [0, 1]
    (premultiplied RGBA with ``premultiplied=True``).

    samples: samples x samples point samples per pixel, box-filtered. jitter: jitter each sample
    inside its stratum (numpy generator seeded with ``seed``) instead of the stratum centre.
    background: None (transparent) or a straight RGBA tuple composited behind everything.
    """
    width, height, s = int(width), int(height), int(samples)
    grid = _Grid(width, height, s, jitter, seed)
    full = (0, height * s, 0, width * s)
    base = np.zeros((height * s, width * s, 4))
    stack: list[tuple[int, np.ndarray]] = []  # open group layers, root-most first

    def pop():
        g, buf = stack.pop()
        buf *= float(_np(scene.groups[g].opacity).reshape(()))
        target = stack[-1][1] if stack else base
        _over(target, full, buf.reshape(-1, 4))

    for shape in scene.shapes:
        chain = _group_chain(scene, shape)
        k = 0
        while k < len(stack) and k < len(chain) and stack[k][0] == chain[k]:
            k += 1
        while len(stack) > k:
            pop()
        for g in chain[k:]:
            stack.append((g, np.zeros_like(base)))
        drawn = _draw_shape(scene, shape, grid, width, height)
        if drawn is not None:
            target = stack[-1][1] if stack else base
            _over(target, *drawn)
    while stack:
        pop()

    img = base.reshape(height, s, width, s, 4).mean(axis=(1, 3))
    if background is not None:
        bg = _premul(np.asarray(background, dtype=np.float64).reshape(4))
        img = img + (1.0 - img[..., 3:4]) * bg
    img = np.clip(img, 0.0, 1.0)
    if premultiplied:
        return img
    out = np.zeros_like(img)
    a = img[..., 3]
    nz = a > 0
    out[nz, :3] = img[nz, :3] / a[nz, None]
    out[..., 3] = a
    return np.clip(out, 0.0, 1.0)


def premultiply(img) -> np.ndarray:
    """Straight [..., 4] RGBA -> premultiplied."""
    return _premul(np.asarray(img, dtype=np.float64))
