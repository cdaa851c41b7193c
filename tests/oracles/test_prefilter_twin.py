"""The analytical backward, term by term, against a PyTorch twin of the prefilter.

The twin computes each pixel's coverage K(sd / r) from the same pieces as the core
(scene/coverage.h: fill segments; per stroke segment its sweep, butt end lines, caps and
joins, and the bevel edges that bound the sweeps beside them, DESIGN.md "Strokes"), with the closest points found without gradients (the distance
is stationary there) and autograd through the distance and the kernel. One scene per
piece kind, each a single shape over white at 1 sample per pixel: the twin's image must
equal the core's (so the twin is the same function), then every point's gradient and the
width's must agree, so a wrong term is named by its test. Tolerance: 1e-3 of the largest
gradient (the core's joins and caps use central differences with a 1e-6 step).
Cost: about 3 s.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import vecfit
from vecfit.scene import Path, Scene, Shape, Solid

from helpers import slow_unless

SIZE = 24
R = 0.5  # the box filter's kernel radius at 1 sample per pixel
COLOR = (0.2, 0.4, 0.6)
T = torch.linspace(0, 1, 4001, dtype=torch.float64)


def bezier(P, t):
    """Points [.., 2] of the Bezier with control points P [n + 1, 2] at parameters t."""
    n = P.shape[0] - 1
    out = 0
    for i in range(n + 1):
        b = float(math.comb(n, i)) * t ** i * (1 - t) ** (n - i)
        out = out + b[..., None] * P[i]
    return out


def bezier_deriv(P, t):
    n = P.shape[0] - 1
    return bezier(n * (P[1:] - P[:-1]), t) if n > 1 else (P[1] - P[0]).expand(*t.shape, 2)


def unit(v):
    return v / v.norm(dim=-1, keepdim=True)


def perp(v):
    return torch.stack([-v[..., 1], v[..., 0]], dim=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def centres():
    y, x = torch.meshgrid(torch.arange(SIZE, dtype=torch.float64) + 0.5,
                          torch.arange(SIZE, dtype=torch.float64) + 0.5, indexing="ij")
    return torch.stack([x, y], dim=-1).reshape(-1, 2)


def refine(P, q, t):
    """Newton on g(t) = (B - q).B' from t (no gradient): the stationary points."""
    with torch.no_grad():
        n = P.shape[0] - 1
        P2 = n * (n - 1) * (P[2:] - 2 * P[1:-1] + P[:-2]) if n > 1 else None
        for _ in range(30):
            r, d1 = bezier(P, t) - q, bezier_deriv(P, t)
            d2 = bezier(P2, t) if n > 1 else torch.zeros_like(d1)
            g, dg = (r * d1).sum(-1), (d1 * d1).sum(-1) + (r * d2).sum(-1)
            t = torch.where(dg > 0, t - g / dg, t).clamp(0, 1)
    return t


def closest_distance(P, q):
    """|B(t*) - q| at the closest point t* on [0, 1] (ends included): fills."""
    with torch.no_grad():
        t = T[(bezier(P.detach(), T)[None] - q[:, None]).norm(dim=-1).argmin(dim=1)]
        t = refine(P.detach(), q, t)
    return (bezier(P, t) - q).norm(dim=-1)


def sweep_distance(P, q):
    """min over interior local minima t* of |B(t) - q| (inf where there is none): the
    sweep's critical points; for a line the foot of the perpendicular within the segment."""
    with torch.no_grad():
        d = (bezier(P.detach(), T)[None] - q[:, None]).norm(dim=-1)
        interior = torch.zeros_like(d, dtype=torch.bool)
        interior[:, 1:-1] = (d[:, 1:-1] <= d[:, :-2]) & (d[:, 1:-1] <= d[:, 2:])
        dm = torch.where(interior, d, torch.full_like(d, float("inf")))
        k = dm.argmin(dim=1)
        ok = torch.isfinite(dm.gather(1, k[:, None])[:, 0])
        t = refine(P.detach(), q, T[k])
        ok &= (t > 0) & (t < 1)
    dist = (bezier(P, t) - q).norm(dim=-1)
    return torch.where(ok, dist, torch.full_like(dist, float("inf")))


def segment_distance(q, a, b):
    d = b - a
    t = (((q - a) * d).sum(-1) / (d * d).sum(-1)).clamp(0, 1)
    return (a + t[..., None] * d - q).norm(dim=-1)


def join_polygon_sd(poly, q):
    """scene/coverage.h join_polygon_sdf: depth inside counts only the outer edges."""
    n = len(poly)
    dists = torch.stack([segment_distance(q, poly[i], poly[(i + 1) % n]) for i in range(n)])
    outer = dists[1:n - 1].min(dim=0).values
    c = torch.stack([cross(poly[(i + 1) % n] - poly[i], q - poly[i]) for i in range(n)])
    inside = ~((c > 0).any(dim=0) & (c < 0).any(dim=0))
    return torch.where(inside, -outer, dists.min(dim=0).values)


def join_polygon(v, t_in, t_out, kind, hw, miter_limit=4.0):
    """scene/stroke.h make_join's polygon: the vertex, then its outer points (a bevel
    triangle, or the miter quadrilateral within the limit)."""
    s = 1.0 if float(cross(t_in, t_out).detach()) >= 0 else -1.0
    n_in, n_out = -s * perp(t_in), -s * perp(t_out)
    cos_half = (0.5 * (1 + (t_in * t_out).sum())).clamp(min=0).sqrt()
    if kind == "miter" and 1 / float(cos_half.detach()) <= miter_limit:
        return [v, v + hw * n_in, v + (hw / cos_half) * unit(n_in + n_out), v + hw * n_out]
    return [v, v + hw * n_in, v + hw * n_out]


def join_sd(v, t_in, t_out, kind, hw, q, miter_limit=4.0):
    if kind == "round":
        return (q - v).norm(dim=-1) - hw
    return join_polygon_sd(join_polygon(v, t_in, t_out, kind, hw, miter_limit), q)


def bevel_edge_distance(v, t_in, t_out, kind, hw, q):
    """The seam rule (scene/coverage.h bevel_edge): the distance to a bevel's outer edge
    (also a miter's past its limit), which bounds the depth of the sweeps on both sides;
    None for other joins."""
    if kind == "round":
        return None
    poly = join_polygon(v, t_in, t_out, kind, hw)
    return segment_distance(q, poly[1], poly[2]) if len(poly) == 3 else None


def cap_sd(v, outward, kind, hw, q):
    if kind == "round":
        return (q - v).norm(dim=-1) - hw
    r = q - v
    s, u = (r * outward).sum(-1), cross(outward, r)
    au = u.abs()
    inside = (s >= 0) & (s <= hw) & (au <= hw)
    ds = torch.where(s < 0, -s, (s - hw).clamp(min=0))
    du = (au - hw).clamp(min=0)
    outside = (ds * ds + du * du).sqrt()
    return torch.where(inside, -torch.minimum(hw - s, hw - au), outside)


def end_tangent(P, t):
    return unit(bezier_deriv(P, torch.tensor(float(t), dtype=torch.float64)))


def stroke_sd(segments, hw, q, cap, join, seams=None):
    """An open stroke of the segments (control points each) with the cap and join.
    seams, if a list: gets per pixel whether a bevel edge bounded a sweep there."""
    sds = []
    for k, P in enumerate(segments):
        sd = sweep_distance(P, q) - hw
        t0, t1 = end_tangent(P, 0), end_tangent(P, 1)
        ends = [(0, P[0], t0, k == 0), (1, P[-1], t1, k == len(segments) - 1)]
        if cap == "butt" and (k == 0 or k == len(segments) - 1):
            dl = torch.stack([segment_distance(q, at - hw * perp(t), at + hw * perp(t))
                              for side, at, t, free in ends if free]).min(dim=0).values
            sd = torch.where(sd <= 0, torch.maximum(sd, -dl), torch.minimum(sd, dl))
        # the joins at this sweep's ends: (vertex, incoming tangent, outgoing tangent)
        joins = ([(P[0], end_tangent(segments[k - 1], 1), t0)] if k > 0 else []) + \
            ([(P[-1], t1, end_tangent(segments[k + 1], 0))] if k + 1 < len(segments) else [])
        for v, t_in, t_out in joins:
            e = bevel_edge_distance(v, t_in, t_out, join, hw, q)
            if e is not None:
                bounded = (sd <= 0) & (-e > sd)
                if seams is not None:
                    seams.append(bounded.detach())
                sd = torch.where(sd <= 0, torch.maximum(sd, -e), sd)
        for side, at, t, free in ends:
            if free and cap != "butt":
                sd = torch.minimum(sd, cap_sd(at, -t if side == 0 else t, cap, hw, q))
            if side == 1 and not free:
                t_out = unit(bezier_deriv(segments[k + 1], torch.tensor(0.0, dtype=torch.float64)))
                sd = torch.minimum(sd, join_sd(at, t, t_out, join, hw, q))
        sds.append(sd)
    return torch.stack(sds).min(dim=0).values


def coverage(sd):
    d = sd.clamp(-R, R) / R
    return 0.5 + (d ** 3 - 3 * d) / 4


def twin_image(cov):
    c = torch.tensor(COLOR, dtype=torch.float64)
    return (cov[:, None] * c + (1 - cov[:, None])).reshape(SIZE, SIZE, 3)


def core(points, degrees, width=None, cap="butt", join="miter", closed=False):
    """Core image (rgb) and the gradients of L = sum W rgb in the points (and the width)."""
    pts = points.clone().float().requires_grad_(True)
    path = Path(points=pts, degrees=np.array(degrees), subpaths=[(0, len(degrees), closed)])
    paint = Solid(torch.tensor([*COLOR, 1.0]))
    if width is None:
        shape = Shape(geometry=path, fill=paint)
        w = None
    else:
        w = torch.tensor(float(width), requires_grad=True)
        shape = Shape(geometry=path, stroke=paint, stroke_width=w, linecap=cap, linejoin=join)
    img = vecfit.render(Scene(width=SIZE, height=SIZE, shapes=[shape]), SIZE, SIZE, samples=1, mode="analytic",
                        background=(1, 1, 1))[..., :3]
    (img.double() * WEIGHTS).sum().backward()
    return img.detach().double(), pts.grad.double(), (None if w is None else w.grad.double())


WEIGHTS = torch.rand(SIZE, SIZE, 3, generator=torch.Generator().manual_seed(3), dtype=torch.float64)


def split(points, degrees):
    out, i = [], 0
    for d in degrees:
        out.append(points[i:i + d + 1])
        i += d
    return out


def compare(name, core_img, core_grads, twin_cov, twin_params):
    img = twin_image(twin_cov)
    assert torch.allclose(img, core_img, atol=2e-5), \
        f"{name}: the twin's image differs from the core's by {float((img - core_img).abs().max()):.3g}"
    (img * WEIGHTS).sum().backward()
    for label, got, param in zip(("points", "width"), core_grads, twin_params):
        if got is None:
            continue
        want = param.grad
        scale = float(want.abs().max()) + 1e-9
        err = float((got - want).abs().max())
        assert err <= 1e-3 * scale, f"{name}, {label}: core {got.numpy()} vs twin {want.numpy()}"


FILLS = {
    "line": (torch.tensor([[4.2, 5.1], [19.3, 7.4], [12.6, 19.8]]), [1, 1, 1]),
    "quadratic": (torch.tensor([[4.2, 5.1], [24.0, 2.0], [18.3, 17.4], [6.6, 19.8]]), [2, 1, 1]),
    "cubic": (torch.tensor([[4.2, 5.1], [10.0, -3.0], [25.0, 8.0], [18.3, 17.4], [6.6, 19.8]]), [3, 1, 1]),
}


@pytest.mark.parametrize("kind", slow_unless(list(FILLS), ["cubic"]))
def test_fill_segments(kind):
    points, degrees = FILLS[kind]
    core_img, g_points, _ = core(points, degrees, closed=True)
    P = points.double().clone().requires_grad_(True)
    closed = torch.cat([P, P[:1]])
    q = centres()
    dist = torch.stack([closest_distance(S, q) for S in split(closed, degrees)]).min(dim=0).values
    inside = ((1 - core_img[..., 0]) / (1 - COLOR[0])).reshape(-1) > 0.5  # the sign, from the core's coverage
    compare(f"fill {kind}", core_img, (g_points,), coverage(torch.where(inside, -dist, dist)), (P,))


STROKES = {
    # (points, degrees, width, cap, join): each names the piece it is there for
    "line sweep, butt ends": (torch.tensor([[4.3, 6.2], [19.6, 15.1]]), [1], 3.2, "butt", "miter"),
    "quadratic sweep": (torch.tensor([[3.3, 18.2], [11.0, -2.0], [20.6, 17.1]]), [2], 2.6, "butt", "miter"),
    "cubic sweep": (torch.tensor([[3.3, 14.2], [8.0, 0.5], [16.0, 26.0], [20.6, 7.1]]), [3], 2.4, "butt", "miter"),
    "thin line (half width below the kernel radius)": (torch.tensor([[4.3, 6.2], [19.6, 15.1]]), [1], 0.6, "butt",
                                                       "miter"),
    "round caps": (torch.tensor([[5.3, 7.2], [18.6, 14.1]]), [1], 4.4, "round", "miter"),
    "square caps": (torch.tensor([[6.3, 7.2], [17.6, 14.1]]), [1], 4.4, "square", "miter"),
    "round join": (torch.tensor([[3.2, 18.1], [11.7, 5.3], [20.4, 17.6]]), [1, 1], 3.6, "butt", "round"),
    "bevel join": (torch.tensor([[3.2, 18.1], [11.7, 5.3], [20.4, 17.6]]), [1, 1], 3.6, "butt", "bevel"),
    "miter join": (torch.tensor([[3.2, 18.1], [11.7, 5.3], [20.4, 17.6]]), [1, 1], 3.6, "butt", "miter"),
    "join of curves": (torch.tensor([[3.2, 18.1], [4.0, 8.0], [11.7, 5.3], [17.0, 9.0], [20.4, 17.6]]), [2, 2], 3.0,
                       "round", "miter"),
    # the seam rule: a wide bevel whose edge bounds both sweeps' depth within the kernel's
    # reach of pixel centres, and a miter's bevel fallback (a 160-degree turn) between curves
    "bevel seams": (torch.tensor([[4.06, 11.55], [13.5, 8.25], [9.96, 17.6]]), [1, 1], 7.4, "butt", "bevel"),
    "miter past its limit, curves": (torch.tensor([[2.6, 9.05], [9.0, 6.75], [17.4, 9.85], [10.0, 10.55], [3.1, 13.35]]),
                                     [2, 2], 4.2, "round", "miter"),
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(STROKES))
def test_strokes(kind):
    points, degrees, width, cap, join = STROKES[kind]
    core_img, g_points, g_width = core(points, degrees, width, cap, join)
    P = points.double().clone().requires_grad_(True)
    w = torch.tensor(width, dtype=torch.float64, requires_grad=True)
    seams = []
    sd = stroke_sd(split(P, degrees), w / 2, centres(), cap, join, seams)
    if "seam" in kind or "past its limit" in kind:
        # the scene must exercise the rule: pixels whose depth a bevel edge bounds, within the
        # kernel's reach of the edge (where the coverage depends on it)
        used = torch.stack(seams).any(dim=0) & (sd.detach().abs() < R)
        assert int(used.sum()) >= 2, f"{kind}: the seam rule decides no pixel"
    compare(f"stroke, {kind}", core_img, (g_points, g_width), coverage(sd), (P, w))
