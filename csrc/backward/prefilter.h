// The analytical prefilter's chain rule: coverage is K(sd / r), a smooth function of the
// signed distance sd, so there is no boundary term; dL/d(sd) goes to the parameters the
// closest piece was built from.
#pragma once

#include <cmath>

#include "backward/control_points.h"
#include "backward/grads.h"
#include "backward/hits.h"
#include "common/bezier.h"
#include "common/ellipse.h"
#include "common/portable.h"
#include "scene/coverage.h"
#include "scene/scene.h"
#include "scene/stroke.h"

namespace vf {

// Adds g_sd * d(sd)/d(parameters) for a hit of the analytical prefilter. At a closest
// point the first-order condition holds, so the solver's t* drops out (implicit
// function theorem): d|B(t*) - p| / dP_i = basis_i(t*) (B(t*) - p) / |B(t*) - p|.
// Joins, caps, butt ends and bevel edges bounding sweeps (the seam rule, scene/coverage.h
// bevel_edge): central differences of their construction in the vertex, the tangents'
// angles and the width. entry_sdf_backward at the end dispatches to the pieces.

// v = d sd / d(pixel-space point idx); idx < 0: a point no input holds.
VF_HD void add_point_grad(const GradView& g, int32_t idx, Vec2 v) {
    if (idx < 0) return;
    g.points[2 * (size_t)idx] += v.x;
    g.points[2 * (size_t)idx + 1] += v.y;
}

// An ellipse row (centre c, axes A: point c + A u): k v for the centre, k v (x) u for A.
VF_HD void add_ellipse_grad(const GradView& g, const PreparedDraw& d, double k, Vec2 v, Vec2 u) {
    GradPtr ge = g.ellipses + ELLIPSE_COLS * (size_t)d.ellipse_row;
    ge[0] += k * v.x; ge[1] += k * v.y;
    ge[2] += k * v.x * u.x; ge[3] += k * v.x * u.y;
    ge[4] += k * v.y * u.x; ge[5] += k * v.y * u.y;
}

// Fills: sd = -+ the distance to the closest point of a fill segment or the ellipse.
VF_HD void fill_sdf_backward(const SceneView& sc, const PreparedDraw& d, const Hit& h, Vec2 p, double g_sd,
                             const GradView& g) {
    const SdfArg& arg = h.arg;
    double sign = h.sd < 0 ? -1 : 1;
    double dist = distance(arg.closest, p);
    if (arg.kind == SdfArg::SEGMENT) {
        // d sd / d(closest point): the inward direction, sign (closest - p) / dist off the
        // edge; on it, the unit normal on the inside's side (none where both or neither are).
        // On a vertex (a second segment within ON_EDGE), half to each: the central derivative.
        bool vertex = dist < ON_EDGE && arg.item2 >= 0;
        for (int k = 0; k < (vertex ? 2 : 1); ++k) {
            const PreparedSegment& seg = sc.fill_items[k == 0 ? arg.item : arg.item2];
            double t = k == 0 ? arg.t : arg.t2;
            int side = k == 0 ? arg.side : arg.side2;
            Vec2 inward;
            if (dist >= ON_EDGE) inward = (sign / dist) * (arg.closest - p);
            else {
                Vec2 tangent = seg_deriv(seg.seg, t);
                double speed = length(tangent);
                if (side == 0 || speed <= 0) continue;
                inward = (side / speed) * perp(tangent);
            }
            double w = vertex ? 0.5 * g_sd : g_sd;
            for (int i = 0; i <= seg.seg.degree; ++i)
                add_point_grad(g, seg.point_index[i], (w * bernstein(seg.seg.degree, i, t)) * inward);
        }
        return;
    }
    if (dist <= 0) return;
    Vec2 dir = (1 / dist) * (arg.closest - p);  // d dist / d(closest point)
    if (arg.kind == SdfArg::ELLIPSE) {
        Vec2 u = inverse(d.ellipse_axes) * (arg.closest - d.ellipse_center);
        add_ellipse_grad(g, d, g_sd * sign, dir, u);
    }
}

// What the chain rule of every stroke piece shares. A stroke's sd (pixels) is
// metric_scale times its sd in stroke space, where geometry is M times pixel geometry
// (M the draw's metric): q = M p.
struct StrokeChain {
    const SceneView& sc;
    const PreparedDraw& d;
    const GradView& g;
    Vec2 p, q;    // the point, in pixel and in stroke space
    double gs;    // dL/d(stroke-space sd) = g_sd * metric_scale
    GradPtr gw;   // the draw's draw_params row: width (= 2 hw), miter limit, metric (a b c d)

    // M^T v: a stroke-space gradient seen in pixel space.
    VF_HD Vec2 mt(Vec2 v) const {
        return d.metric_identity ? v : Vec2{d.metric.a * v.x + d.metric.c * v.y, d.metric.b * v.x + d.metric.d * v.y};
    }
    VF_HD Vec2 to_pix(Vec2 v) const { return d.metric_identity ? v : d.metric_inv * v; }
    VF_HD void add_point(int32_t idx, Vec2 v) const { add_point_grad(g, idx, v); }
    // d sd_s / d M[r][c] = v[r] (anchor - p)[c] for a piece built around `anchor` whose
    // stroke-space gradient is v (times k).
    VF_HD void add_metric(Vec2 v, Vec2 anchor_minus_p, double k) const {
        if (d.metric_identity) return;
        gw[2] += k * v.x * anchor_minus_p.x;
        gw[3] += k * v.x * anchor_minus_p.y;
        gw[4] += k * v.y * anchor_minus_p.x;
        gw[5] += k * v.y * anchor_minus_p.y;
    }
};

// The metric's part through metric_scale = |det M|^-1/2: d ms / dM = -ms/2 M^-T.
VF_HD void metric_scale_backward(const StrokeChain& c, double sd, double g_sd) {
    const PreparedDraw& d = c.d;
    double sd_s = sd / d.metric_scale, k = -0.5 * g_sd * sd_s * d.metric_scale;
    Mat2 it = inverse(d.metric);  // (M^-T)[r][c] = (M^-1)[c][r]
    c.gw[2] += k * it.a; c.gw[3] += k * it.c; c.gw[4] += k * it.b; c.gw[5] += k * it.d;
}

// Per-point widths: sd = |B(t*) - q| - hw(t*) at a critical point t* of the distance,
// g(t) = (B(t) - q).B'(t) = 0. The distance is stationary in t there (no t* term, as
// above); hw(t*) is not: its term is hw'(t*) dt*/dtheta with dt*/dtheta = -(dg/dtheta) /
// (dg/dt) (implicit function theorem), dg/dt = |B'|^2 + (B - q).B'' and dg/dP_i = b_i B' +
// b_i' (B - q). On a straight tapered line this term is the slope hw'/|B'| times the
// tangential offset: not small. Widths: d sd / d w_i = -b_i(t*) / 2. Whole-segment basis
// and parameter.
VF_HD void varying_sweep_sdf_backward(const StrokeChain& c, const SdfArg& arg) {
    const SceneView& sc = c.sc;
    const StrokeSegment& s = sc.stroke_items[arg.item];
    Segment W = whole_segment(sc, c.d, s);
    int n = W.degree;
    int32_t idx[4];
    stroke_item_indices(sc, s, idx);
    double T = whole_t(s, arg.t);
    double hc[4] = {0, 0, 0, 0};
    for (int i = 0; i <= n; ++i) hc[i] = idx[i] >= 0 ? vmax(0.0, sc.point_hw[idx[i]]) : 0.0;
    double hw1 = bez_scalar_deriv(hc, n, T);
    Vec2 B = seg_eval(W, T), B1 = seg_deriv(W, T), B2 = seg_deriv2(W, T);
    Vec2 r = B - c.q;
    double dist = length(r), D = dot(B1, B1) + dot(r, B2);
    Vec2 dir = dist > 0 ? (1 / dist) * r : Vec2{0, 0};  // on the curve: the kink of |.|
    // dg/dt = 0 where q is a centre of curvature (t* not differentiable): no term.
    double k = std::fabs(D) > 1e-9 * dot(B1, B1) ? hw1 / D : 0.0;
    for (int i = 0; i <= n; ++i) {
        double bi = bernstein(n, i, T), dbi = bernstein_deriv(n, i, T);
        Vec2 v = bi * dir + k * (bi * B1 + dbi * r);  // d sd_s / d P_i (stroke space)
        c.add_point(idx[i], c.gs * c.mt(v));
        c.add_metric(v, c.to_pix(W.p[i]) - c.p, c.gs);
        if (width_free(sc, idx[i])) c.g.point_widths[idx[i]] += -0.5 * c.gs * bi;
    }
}

// A sweep of uniform width or a stroked ellipse: sd = |closest - q| - hw, where the
// closest point lies on the curve (SWEEP) or the ellipse (ELLIPSE).
VF_HD void sweep_sdf_backward(const StrokeChain& c, const SdfArg& arg) {
    const SceneView& sc = c.sc;
    const PreparedDraw& d = c.d;
    double dist = distance(arg.closest, c.q);
    c.gw[0] += -0.5 * c.gs;
    if (dist <= 0) return;
    Vec2 dir = (1 / dist) * (arg.closest - c.q);
    Vec2 anchor = d.metric_identity ? arg.closest : d.metric_inv * arg.closest;
    c.add_metric(dir, anchor - c.p, c.gs);
    if (arg.kind == SdfArg::ELLIPSE) {
        Vec2 u = inverse(d.ellipse_axes) * (anchor - d.ellipse_center);
        add_ellipse_grad(c.g, d, c.gs, c.mt(dir), u);
        return;
    }
    const StrokeSegment& s = sc.stroke_items[arg.item];
    int32_t idx[4];
    stroke_item_indices(sc, s, idx);
    for (int i = 0; i <= s.seg.degree; ++i)
        c.add_point(idx[i], (c.gs * bernstein(s.seg.degree, i, whole_t(s, arg.t))) * c.mt(dir));
}

// The piece at a stroke item's end (its butt end line, cap or join), rebuilt from the
// vertex V, the tangents meeting there and a half width: its signed distance at qq.
struct EndPiece {
    const PreparedDraw& d;
    const StrokeEnd& stored;  // as preparation built it
    Vec2 V;
    int side;                 // 0: the item's start, 1: its end
    bool butt, join, point;   // butt end line; join with the next item; a zero-length subpath's dot
    bool seam;                // the join's bevel edge bounding a sweep (SdfArg::SEAM)
    double sign;              // of the hit's sd (the butt end line's distance is unsigned)

    VF_HD double sd(Vec2 qq, Vec2 t_in, Vec2 t_out, double w) const {
        if (butt) {
            Vec2 n = perp(t_in);
            return sign * point_line_segment_distance(qq, V - w * n, V + w * n);
        }
        StrokeEnd e;
        if (seam) {  // -(distance to the outer edge), inside the sweep next to the bevel
            e = make_join(V, t_in, t_out, d.join, w, d.miter_limit);
            const Vec2* edge = bevel_edge(e);
            return edge ? -point_line_segment_distance(qq, edge[0], edge[1]) : 0.0;
        }
        if (join) e = make_join(V, t_in, t_out, d.join, w, d.miter_limit);
        else if (point) {
            e = stored;
            e.hw = w;
        } else e = make_cap(V, side == 0 ? -t_in : t_in, d.cap, w);
        return end_sdf(e, qq);
    }
};

// BUTT / END / SEAM: central differences of EndPiece::sd in q (the vertex moves the piece:
// d/dV = -d/dq), in the half width and in the angles of the tangents, which turn with the
// control points of their end frames. A SEAM hit at an item's start is its prev item's
// join: it is handled as that item's end.
VF_HD void end_sdf_backward(const StrokeChain& c, const Hit& h) {
    const SceneView& sc = c.sc;
    const PreparedDraw& d = c.d;
    const SdfArg& arg = h.arg;
    const Vec2 q = c.q;
    const double gs = c.gs;
    bool seam = arg.kind == SdfArg::SEAM;
    const int item = seam && arg.side == 0 ? sc.stroke_items[arg.item].prev : arg.item;
    const StrokeSegment& s = sc.stroke_items[item];
    int side = seam ? 1 : arg.side;
    bool point = s.seg.degree == 1 && s.seg.p[0].x == s.seg.p[1].x && s.seg.p[0].y == s.seg.p[1].y;
    EndFrame in = end_frame(whole_segment(sc, d, s), side == 1), out;
    bool join = side == 1 && (arg.kind == SdfArg::END || seam) && s.next >= 0 && s.end.kind != StrokeEnd::NONE;
    if (join) out = end_frame(whole_segment(sc, d, sc.stroke_items[s.next]), false);
    Vec2 V = side == 0 ? s.seg.p[0] : seg_end(s.seg);
    const StrokeEnd& stored = side == 0 ? s.start : s.end;
    double hw = stored.hw;  // the draw's, or the vertex's (per-point widths)
    const EndPiece piece{d, stored, V, side, arg.kind == SdfArg::BUTT, join, point, seam, h.sd < 0 ? -1.0 : 1.0};
    auto value = [&](Vec2 qq, Vec2 t_in, Vec2 t_out, double w) { return piece.sd(qq, t_in, t_out, w); };
    auto rotate = [](Vec2 v, double a) {
        return Vec2{v.x * std::cos(a) - v.y * std::sin(a), v.x * std::sin(a) + v.y * std::cos(a)};
    };
    const double hq = 1e-6 * vmax(1.0, hw), ha = 1e-6;
    Vec2 to = join ? out.t : in.t;
    // translation of the vertex moves the piece: d/dV = -d/dq
    double dqx = (value(q + Vec2{hq, 0}, in.t, to, hw) - value(q - Vec2{hq, 0}, in.t, to, hw)) / (2 * hq);
    double dqy = (value(q + Vec2{0, hq}, in.t, to, hw) - value(q - Vec2{0, hq}, in.t, to, hw)) / (2 * hq);
    int32_t idx[4];
    stroke_item_indices(sc, s, idx);
    c.add_point(side == 0 ? idx[0] : idx[s.seg.degree], (-gs) * c.mt(Vec2{dqx, dqy}));
    // q = M p and V = M V_pix enter as q - V: d/dM = (d sd/dq) (p - V_pix)
    c.add_metric(Vec2{dqx, dqy}, c.p - (d.metric_identity ? V : d.metric_inv * V), gs);
    // the half width (one-sided where it is about 0: a join of negative width does not exist)
    double dw = hw > hq ? (value(q, in.t, to, hw + hq) - value(q, in.t, to, hw - hq)) / (2 * hq)
                        : (value(q, in.t, to, hw + hq) - value(q, in.t, to, hw)) / (hq - vmin(hw, 0.0));
    if (!d.varying) c.gw[0] += 0.5 * gs * dw;
    else if (width_free(sc, stored.width_index)) c.g.point_widths[stored.width_index] += 0.5 * gs * dw;
    // the tangents' angles: a frame turns by N . (d head - d tail) / length
    auto add_frame = [&](const EndFrame& f, const int32_t* fidx, double rate, const Segment& w) {
        if (f.length <= 0 || rate == 0 || point) return;
        Vec2 N = c.mt(perp(f.t));
        c.add_point(fidx[f.head], (gs * rate / f.length) * N);
        c.add_point(fidx[f.tail], (-gs * rate / f.length) * N);
        Vec2 span = w.p[f.head] - w.p[f.tail];
        c.add_metric(perp(f.t), d.metric_identity ? span : d.metric_inv * span, gs * rate / f.length);
    };
    add_frame(in, idx, (value(q, rotate(in.t, ha), to, hw) - value(q, rotate(in.t, -ha), to, hw)) / (2 * ha),
              whole_segment(sc, d, s));
    if (join) {
        int32_t nidx[4];
        stroke_item_indices(sc, sc.stroke_items[s.next], nidx);
        add_frame(out, nidx, (value(q, in.t, rotate(to, ha), hw) - value(q, in.t, rotate(to, -ha), hw)) / (2 * ha),
                  whole_segment(sc, d, sc.stroke_items[s.next]));
    }
}

// Adjoint of entry_sdf (scene/tiles.h) for one hit of the analytical prefilter: dL/d(sd)
// = g_sd, to every parameter the closest piece (h.arg) was built from.
VF_HD void entry_sdf_backward(const SceneView& sc, const Hit& h, Vec2 p, double g_sd, const GradView& g) {
    const PreparedDraw& d = sc.draws[h.draw];
    if (d.kind == DRAW_FILL) {
        fill_sdf_backward(sc, d, h, p, g_sd, g);
        return;
    }
    const StrokeChain c{sc, d, g, p, d.metric_identity ? p : d.metric * p, g_sd * d.metric_scale,
                        g.draw_params + DRAW_FCOLS * (size_t)h.draw};
    if (!d.metric_identity) metric_scale_backward(c, h.sd, g_sd);
    if (h.arg.kind == SdfArg::SWEEP && d.varying) varying_sweep_sdf_backward(c, h.arg);
    else if (h.arg.kind == SdfArg::ELLIPSE || h.arg.kind == SdfArg::SWEEP) sweep_sdf_backward(c, h.arg);
    else end_sdf_backward(c, h);  // BUTT / END / SEAM
}

}  // namespace vf
