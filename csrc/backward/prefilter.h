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
// Joins, caps and butt ends: central differences of their construction in the vertex,
// the tangents' angles and the width.
VF_HD void sdf_backward(const SceneView& sc, const Hit& h, Vec2 p, double g_sd, const GradView& g) {
    const PreparedDraw& d = sc.draws[h.draw];
    const SdfArg& arg = h.arg;
    auto add_pixel_point = [&](int32_t idx, Vec2 v) {  // v: d sd / d(pixel point)
        if (idx < 0) return;
        g.points[2 * (size_t)idx] += v.x;
        g.points[2 * (size_t)idx + 1] += v.y;
    };
    auto mt = [&](Vec2 v) {  // M^T v: a stroke-space gradient seen in pixel space
        return d.metric_identity ? v : Vec2{d.metric.a * v.x + d.metric.c * v.y, d.metric.b * v.x + d.metric.d * v.y};
    };
    if (d.kind == DRAW_FILL) {
        double sign = h.sd < 0 ? -1 : 1;
        double dist = distance(arg.closest, p);
        if (dist <= 0) return;
        Vec2 dir = (1 / dist) * (arg.closest - p);  // d dist / d(closest point)
        if (arg.kind == SdfArg::SEGMENT) {
            const PreparedSegment& seg = sc.fill_items[arg.item];
            for (int i = 0; i <= seg.seg.degree; ++i)
                add_pixel_point(seg.point_index[i], (g_sd * sign * bernstein(seg.seg.degree, i, arg.t)) * dir);
        } else if (arg.kind == SdfArg::ELLIPSE) {
            Vec2 u = inverse(d.ellipse_axes) * (arg.closest - d.ellipse_center);
            GradPtr ge = g.ellipses + ELLIPSE_COLS * (size_t)d.ellipse_row;
            double k = g_sd * sign;
            ge[0] += k * dir.x; ge[1] += k * dir.y;
            ge[2] += k * dir.x * u.x; ge[3] += k * dir.x * u.y;
            ge[4] += k * dir.y * u.x; ge[5] += k * dir.y * u.y;
        }
        return;
    }
    // Strokes: sd (pixels) = metric_scale * sd (stroke space).
    double gs = g_sd * d.metric_scale;
    Vec2 q = d.metric_identity ? p : d.metric * p;
    double hw = d.half_width;
    GradPtr gw = g.draw_params + DRAW_FCOLS * (size_t)h.draw;  // width = 2 hw
    // The stroke metric M: stroke-space geometry is M times pixel geometry, q = M p, and
    // metric_scale = |det M|^-1/2. d sd_s / d M[r][c] = v[r] (anchor - p)[c] for a piece
    // built around `anchor` whose stroke-space gradient is v.
    auto add_metric = [&](Vec2 v, Vec2 anchor_minus_p, double k) {
        if (d.metric_identity) return;
        gw[2] += k * v.x * anchor_minus_p.x;
        gw[3] += k * v.x * anchor_minus_p.y;
        gw[4] += k * v.y * anchor_minus_p.x;
        gw[5] += k * v.y * anchor_minus_p.y;
    };
    if (!d.metric_identity) {  // metric_scale: d ms / dM = -ms/2 M^-T
        double sd_s = h.sd / d.metric_scale, k = -0.5 * g_sd * sd_s * d.metric_scale;
        Mat2 it = inverse(d.metric);  // (M^-T)[r][c] = (M^-1)[c][r]
        gw[2] += k * it.a; gw[3] += k * it.c; gw[4] += k * it.b; gw[5] += k * it.d;
    }
    auto to_pix = [&](Vec2 v) { return d.metric_identity ? v : d.metric_inv * v; };
    if (arg.kind == SdfArg::SWEEP && d.varying) {
        // Per-point widths: sd = |B(t*) - q| - hw(t*) at a critical point t* of the
        // distance, g(t) = (B(t) - q).B'(t) = 0. The distance is stationary in t there
        // (no t* term, as above); hw(t*) is not: its term is hw'(t*) dt*/dtheta with
        // dt*/dtheta = -(dg/dtheta) / (dg/dt) (implicit function theorem), dg/dt =
        // |B'|^2 + (B - q).B'' and dg/dP_i = b_i B' + b_i' (B - q). On a straight tapered
        // line this term is the slope hw'/|B'| times the tangential offset: not small.
        // Widths: d sd / d w_i = -b_i(t*) / 2. Whole-segment basis and parameter.
        const StrokeSegment& s = sc.stroke_items[arg.item];
        Segment W = whole_segment(sc, d, s);
        int n = W.degree;
        int32_t idx[4];
        stroke_item_indices(sc, s, idx);
        double T = whole_t(s, arg.t);
        double hc[4] = {0, 0, 0, 0};
        for (int i = 0; i <= n; ++i) hc[i] = idx[i] >= 0 ? vmax(0.0, sc.point_hw[idx[i]]) : 0.0;
        double hw1 = bez_scalar_deriv(hc, n, T);
        Vec2 B = seg_eval(W, T), B1 = seg_deriv(W, T), B2 = seg_deriv2(W, T);
        Vec2 r = B - q;
        double dist = length(r), D = dot(B1, B1) + dot(r, B2);
        Vec2 dir = dist > 0 ? (1 / dist) * r : Vec2{0, 0};  // on the curve: the kink of |.|
        // dg/dt = 0 where q is a centre of curvature (t* not differentiable): no term.
        double k = std::fabs(D) > 1e-9 * dot(B1, B1) ? hw1 / D : 0.0;
        for (int i = 0; i <= n; ++i) {
            double bi = bernstein(n, i, T), dbi = bernstein_deriv(n, i, T);
            Vec2 v = bi * dir + k * (bi * B1 + dbi * r);  // d sd_s / d P_i (stroke space)
            add_pixel_point(idx[i], gs * mt(v));
            add_metric(v, to_pix(W.p[i]) - p, gs);
            if (width_free(sc, idx[i])) g.point_widths[idx[i]] += -0.5 * gs * bi;
        }
        return;
    }
    if (arg.kind == SdfArg::ELLIPSE || arg.kind == SdfArg::SWEEP) {
        double dist = distance(arg.closest, q);
        gw[0] += -0.5 * gs;
        if (dist <= 0) return;
        Vec2 dir = (1 / dist) * (arg.closest - q);
        Vec2 anchor = d.metric_identity ? arg.closest : d.metric_inv * arg.closest;
        add_metric(dir, anchor - p, gs);
        if (arg.kind == SdfArg::ELLIPSE) {
            Vec2 local = anchor;
            Vec2 u = inverse(d.ellipse_axes) * (local - d.ellipse_center);
            Vec2 m = mt(dir);
            GradPtr ge = g.ellipses + ELLIPSE_COLS * (size_t)d.ellipse_row;
            ge[0] += gs * m.x; ge[1] += gs * m.y;
            ge[2] += gs * m.x * u.x; ge[3] += gs * m.x * u.y;
            ge[4] += gs * m.y * u.x; ge[5] += gs * m.y * u.y;
            return;
        }
        const StrokeSegment& s = sc.stroke_items[arg.item];
        int32_t idx[4];
        stroke_item_indices(sc, s, idx);
        for (int i = 0; i <= s.seg.degree; ++i)
            add_pixel_point(idx[i], (gs * bernstein(s.seg.degree, i, whole_t(s, arg.t))) * mt(dir));
        return;
    }
    // BUTT / END: rebuild the piece from (vertex, tangent angles, half width).
    const StrokeSegment& s = sc.stroke_items[arg.item];
    int side = arg.side;
    bool point = s.seg.degree == 1 && s.seg.p[0].x == s.seg.p[1].x && s.seg.p[0].y == s.seg.p[1].y;
    EndFrame in = end_frame(whole_segment(sc, d, s), side == 1), out;
    bool join = side == 1 && arg.kind == SdfArg::END && s.next >= 0 && s.end.kind != StrokeEnd::NONE;
    if (join) out = end_frame(whole_segment(sc, d, sc.stroke_items[s.next]), false);
    Vec2 V = side == 0 ? s.seg.p[0] : seg_end(s.seg);
    const StrokeEnd& stored = side == 0 ? s.start : s.end;
    hw = stored.hw;  // the draw's, or the vertex's (per-point widths)
    double sign = h.sd < 0 ? -1 : 1;
    auto value = [&](Vec2 qq, Vec2 t_in, Vec2 t_out, double w) {
        if (arg.kind == SdfArg::BUTT) {
            Vec2 n = perp(t_in);
            return sign * point_line_segment_distance(qq, V - w * n, V + w * n);
        }
        StrokeEnd e;
        if (join) e = make_join(V, t_in, t_out, d.join, w, d.miter_limit);
        else if (point) {
            e = stored;
            e.hw = w;
        } else e = make_cap(V, side == 0 ? -t_in : t_in, d.cap, w);
        return end_sdf(e, qq);
    };
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
    add_pixel_point(side == 0 ? idx[0] : idx[s.seg.degree], (-gs) * mt(Vec2{dqx, dqy}));
    // q = M p and V = M V_pix enter as q - V: d/dM = (d sd/dq) (p - V_pix)
    add_metric(Vec2{dqx, dqy}, p - (d.metric_identity ? V : d.metric_inv * V), gs);
    // (one-sided where the width is about 0: a join of negative width does not exist)
    double dw = hw > hq ? (value(q, in.t, to, hw + hq) - value(q, in.t, to, hw - hq)) / (2 * hq)
                        : (value(q, in.t, to, hw + hq) - value(q, in.t, to, hw)) / (hq - vmin(hw, 0.0));
    if (!d.varying) gw[0] += 0.5 * gs * dw;
    else if (width_free(sc, stored.width_index)) g.point_widths[stored.width_index] += 0.5 * gs * dw;
    auto add_frame = [&](const EndFrame& f, const int32_t* fidx, double rate, const Segment& w) {
        if (f.length <= 0 || rate == 0 || point) return;
        Vec2 N = mt(perp(f.t));
        add_pixel_point(fidx[f.head], (gs * rate / f.length) * N);
        add_pixel_point(fidx[f.tail], (-gs * rate / f.length) * N);
        Vec2 span = w.p[f.head] - w.p[f.tail];
        add_metric(perp(f.t), d.metric_identity ? span : d.metric_inv * span, gs * rate / f.length);
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

}  // namespace vf
