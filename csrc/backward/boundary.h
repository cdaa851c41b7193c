// Monte Carlo boundary sampling (Li et al. 2020, section 5, the boundary term): the
// boundary pieces of every draw (fill segments, ellipses, stroke offset curves, caps,
// joins, butt ends) and their samples, each a point with its outward normal, its length
// weight and how it moves along the normal per unit change of each parameter.
#pragma once

#include <cmath>

#include "backward/control_points.h"
#include "backward/grads.h"
#include "common/bezier.h"
#include "common/portable.h"
#include "common/sampling.h"
#include "scene/scene.h"
#include "scene/stroke.h"

namespace vf {

constexpr double EPS_NORMAL = 1e-4;  // pixels: how far p+ and p- lie from the boundary

// One boundary sample: a point, its outward normal (pixel space), its length weight, and
// how the point moves along the normal per unit change of each parameter it depends on.
struct Velocity {
    GradRef target;
    double value;
};

struct BoundarySample {
    Vec2 p, n;
    double weight = 0;  // length element / samples
    int draw = -1;
    Velocity v[32];
    int nv = 0;
    VF_HD void add(GradPtr t, size_t i, double value) {
        if (nv < 32 && value != 0) v[nv++] = {t[i], value};
    }
};

// A boundary piece: what to sample, how many samples, and what each counts for beyond its
// share of the piece's length (1, or 1 / the chance that a piece kept by lot was drawn:
// see boundary_pieces in backward.cpp).
struct Piece {
    enum Kind { FILL_SEGMENT, ELLIPSE, OFFSET, END } kind;
    int draw, item, side, count;
    double scale = 1;
};

VF_HD double polygon_length(const Segment& s) {
    double l = 0;
    for (int i = 0; i < s.degree; ++i) l += distance(s.p[i], s.p[i + 1]);
    return l;
}

// Boundary samples of the pieces (see boundary_pieces in backward.cpp): a point on the
// boundary, its outward normal, length weight and normal velocities. Held by value so
// that a GPU kernel can take it as an argument.
struct BoundarySampler {
    SceneView sc_;
    uint64_t seed_ = 0;

    // Fills bs for sample j of the piece; false if the sample does not exist.
    VF_HD bool sample(const Piece& pc, int j, uint64_t key, const GradView& g, BoundarySample& bs) const {
        double u, unused;
        sample_uniform2(seed_ ^ 0xb0b0b0b0ull, key, (uint64_t)j, u, unused);
        double t = (j + u) / pc.count;
        bs.nv = 0;
        bs.draw = pc.draw;
        const PreparedDraw& d = sc_.draws[pc.draw];
        switch (pc.kind) {
            case Piece::FILL_SEGMENT: return fill_sample(sc_.fill_items[d.first_item + pc.item], t, pc.count, g, bs);
            case Piece::ELLIPSE: return ellipse_sample(pc, d, t, g, bs);
            case Piece::OFFSET: return offset_sample(pc, d, t, g, bs);
            default: return end_sample(pc, d, t, g, bs);
        }
    }


    // Stroke space -> pixel space for a point, a normal (as a covector) and a normal velocity.
    VF_HD Vec2 to_pixel(const PreparedDraw& d, Vec2 q) const { return d.metric_identity ? q : d.metric_inv * q; }
    // Pixel normal for stroke-space normal n_q, and the factor that turns a stroke-space
    // normal velocity into a pixel-space one.
    VF_HD Vec2 pixel_normal(const PreparedDraw& d, Vec2 n_q, double& factor) const {
        if (d.metric_identity) {
            factor = 1;
            return n_q;
        }
        Vec2 m{d.metric.a * n_q.x + d.metric.c * n_q.y, d.metric.b * n_q.x + d.metric.d * n_q.y};  // M^T n
        double l = length(m);
        factor = l > 0 ? 1 / l : 0;
        return factor * m;
    }
    // Pixel-space velocity coefficients of a stroke-space point displacement along n_q,
    // for the pixel point with index idx: (M^T n_q) / |M^T n_q| scaled by w.
    VF_HD void add_point(const GradView& g, BoundarySample& bs, int32_t idx, Vec2 n_pixel, double w) const {
        if (idx < 0) return;
        bs.add(g.points, 2 * (size_t)idx, w * n_pixel.x);
        bs.add(g.points, 2 * (size_t)idx + 1, w * n_pixel.y);
    }
    // Same for a stroke-space direction vector e (not the normal): w * (M^T e).n_q / |M^T n_q|
    VF_HD void add_point_dir(const PreparedDraw& d, const GradView& g, BoundarySample& bs, int32_t idx, Vec2 e,
                       double factor, double w) const {
        if (idx < 0) return;
        Vec2 m = d.metric_identity ? e : Vec2{d.metric.a * e.x + d.metric.c * e.y, d.metric.b * e.x + d.metric.d * e.y};
        bs.add(g.points, 2 * (size_t)idx, w * factor * m.x);
        bs.add(g.points, 2 * (size_t)idx + 1, w * factor * m.y);
    }

    // Normal velocity per entry of the stroke metric M (stroke space = M pixel space): the
    // point is p = M^-1 q with q built from M times pixel geometry, and normal changes are
    // tangential, so dv/dM_rc = factor n_q[r] (anchor - p)[c], where anchor is the pixel
    // point the piece is built around (the curve point, or the vertex).
    VF_HD void add_metric(const PreparedDraw& d, int draw, const GradView& g, BoundarySample& bs, Vec2 n_q, double factor,
                    Vec2 anchor_minus_p) const {
        if (d.metric_identity) return;
        size_t base = DRAW_FCOLS * (size_t)draw + 2;
        bs.add(g.draw_params, base + 0, factor * n_q.x * anchor_minus_p.x);
        bs.add(g.draw_params, base + 1, factor * n_q.x * anchor_minus_p.y);
        bs.add(g.draw_params, base + 2, factor * n_q.y * anchor_minus_p.x);
        bs.add(g.draw_params, base + 3, factor * n_q.y * anchor_minus_p.y);
    }

    VF_HD bool fill_sample(const PreparedSegment& s, double t, int count, const GradView& g, BoundarySample& bs) const {
        Vec2 dp = seg_deriv(s.seg, t);
        double speed = length(dp);
        if (speed <= 0) return false;
        bs.p = seg_eval(s.seg, t);
        bs.n = (1 / speed) * Vec2{dp.y, -dp.x};  // one side; the caller picks the outward one
        bs.weight = speed / count;
        for (int i = 0; i <= s.seg.degree; ++i) add_point(g, bs, s.point_index[i], bs.n, bernstein(s.seg.degree, i, t));
        return true;
    }

    // Ellipse q = c + A (cos, sin) from its pixel-space row; a stroke offsets it by
    // side * hw along the normal in stroke space (q_s = M q).
    VF_HD bool ellipse_sample(const Piece& pc, const PreparedDraw& d, double t, const GradView& g, BoundarySample& bs) const {
        double phi = 2 * M_PI * t;
        Vec2 u{std::cos(phi), std::sin(phi)}, du{-std::sin(phi), std::cos(phi)};
        Mat2 M = d.kind == DRAW_STROKE ? d.metric : Mat2{};
        Mat2 A = d.ellipse_axes;
        Vec2 c = d.ellipse_center;
        Vec2 q = M * (c + A * u), dq = M * (A * du), ddq = M * (A * (-1.0 * u));
        double sp = length(dq);
        if (sp <= 0) return false;
        Vec2 n = (1 / sp) * Vec2{dq.y, -dq.x};
        if (dot(n, q - M * c) < 0) n = -n;  // outward
        double side = d.kind == DRAW_STROKE ? pc.side : 0, hw = d.half_width;
        Vec2 n_side = side < 0 ? -n : n;
        double kappa = std::fabs(cross(dq, ddq)) / (sp * sp * sp);
        double stretch = side == 0 ? 1 : std::fabs(1 + side * hw * kappa);
        double factor;
        bs.n = pixel_normal(d, n_side, factor);
        Vec2 point = q + (side * hw) * n;
        bs.p = d.kind == DRAW_STROKE ? to_pixel(d, point) : point;
        Vec2 step = (sp * stretch / sp) * dq;
        bs.weight = length(d.kind == DRAW_STROKE ? to_pixel(d, step) : step) * 2 * M_PI / pc.count;
        // d q_s / d c = M, d q_s / d A[r][k] = M e_r u_k; normal changes are tangential.
        size_t row = ELLIPSE_COLS * (size_t)d.ellipse_row;
        Vec2 mt{M.a * n_side.x + M.c * n_side.y, M.b * n_side.x + M.d * n_side.y};  // M^T n
        bs.add(g.ellipses, row + 0, factor * mt.x);
        bs.add(g.ellipses, row + 1, factor * mt.y);
        bs.add(g.ellipses, row + 2, factor * mt.x * u.x);
        bs.add(g.ellipses, row + 3, factor * mt.x * u.y);
        bs.add(g.ellipses, row + 4, factor * mt.y * u.x);
        bs.add(g.ellipses, row + 5, factor * mt.y * u.y);
        if (d.kind == DRAW_STROKE) {
            bs.add(g.draw_params, DRAW_FCOLS * (size_t)pc.draw, 0.5 * factor);
            add_metric(d, pc.draw, g, bs, n_side, factor, (c + A * u) - bs.p);
        }
        return true;
    }

    VF_HD bool offset_sample(const Piece& pc, const PreparedDraw& d, double t, const GradView& g, BoundarySample& bs) const {
        const StrokeSegment& s = sc_.stroke_items[d.first_item + pc.item];
        if (d.varying) return offset_sample_varying(pc, d, s, t, g, bs);
        Vec2 b1 = seg_deriv(s.seg, t);
        double sp = length(b1);
        if (sp <= 0) return false;
        Vec2 T = (1 / sp) * b1, N = perp(T);
        double hw = d.half_width, side = pc.side;
        Vec2 q = seg_eval(s.seg, t) + (side * hw) * N;
        // q' = B' + side hw N', N' = perp(T'), T' = (B'' - (B''.T) T) / |B'|
        Vec2 b2 = seg_deriv2(s.seg, t);
        Vec2 tprime = (1 / sp) * (b2 - dot(b2, T) * T);
        Vec2 dq = b1 + (side * hw) * perp(tprime);
        Vec2 n_q = side * N;
        double factor;
        bs.n = pixel_normal(d, n_q, factor);
        bs.p = to_pixel(d, q);
        bs.weight = length(d.metric_identity ? dq : d.metric_inv * dq) / pc.count;
        int32_t idx[4];
        stroke_item_indices(sc_, s, idx);
        for (int i = 0; i <= s.seg.degree; ++i)
            add_point_dir(d, g, bs, idx[i], n_q, factor, bernstein(s.seg.degree, i, whole_t(s, t)));
        bs.add(g.draw_params, DRAW_FCOLS * (size_t)pc.draw, 0.5 * factor);
        add_metric(d, pc.draw, g, bs, n_q, factor, to_pixel(d, seg_eval(s.seg, t)) - bs.p);
        return true;
    }

    // Per-point widths: the offset curve o(t) = B(t) + side hw(t) N(t) (stroke space). Its
    // tangent o' = B' + side (hw' N + hw N') is no longer parallel to B' (the width's
    // slope tilts it), so the normal n_o, the length element |o'| and the velocities are
    // the offset curve's own. Per unit displacement of control point i (stroke space):
    // b_i moves B; N turns by -b_i' / |B'| (delta . N) T, which moves o along T, seen
    // along n_o since T . n_o != 0; widths move o by side b_i N. Basis functions and B'
    // are the whole segment's (the piece's parameter maps to it linearly, and only
    // b_i' / |B'| enters).
    VF_HD bool offset_sample_varying(const Piece& pc, const PreparedDraw& d, const StrokeSegment& s, double t,
                               const GradView& g, BoundarySample& bs) const {
        const Segment& ps = s.seg;
        Vec2 b1 = seg_deriv(ps, t);
        double sp = length(b1);
        if (sp <= 0) return false;
        Vec2 T = (1 / sp) * b1, N = perp(T);
        double side = pc.side;
        double hw = bez_scalar(s.hw, ps.degree, t), hw1 = bez_scalar_deriv(s.hw, ps.degree, t);
        Vec2 b2 = seg_deriv2(ps, t);
        Vec2 tprime = (1 / sp) * (b2 - dot(b2, T) * T);
        Vec2 q = seg_eval(ps, t) + (side * hw) * N;
        Vec2 dq = b1 + side * (hw1 * N + hw * perp(tprime));
        double dl = length(dq);
        if (dl <= 0) return false;
        Vec2 n_q = (1 / dl) * Vec2{dq.y, -dq.x};
        if (dot(n_q, side * N) < 0) n_q = -n_q;  // outward: the side's normal, tilted
        double factor;
        bs.n = pixel_normal(d, n_q, factor);
        bs.p = to_pixel(d, q);
        bs.weight = length(d.metric_identity ? dq : d.metric_inv * dq) / pc.count;
        Segment W = whole_segment(sc_, d, s);
        int n = W.degree;
        double T_whole = whole_t(s, t);
        double wsp = length(seg_deriv(W, T_whole));
        if (wsp <= 0) return false;
        int32_t idx[4];
        stroke_item_indices(sc_, s, idx);
        double tilt = side * hw * dot(T, n_q) / wsp;  // the N-turning term's weight per b_i'
        for (int i = 0; i <= n; ++i) {
            double bi = bernstein(n, i, T_whole), dbi = bernstein_deriv(n, i, T_whole);
            add_point_dir(d, g, bs, idx[i], bi * n_q - (tilt * dbi) * N, factor, 1.0);
            if (width_free(sc_, idx[i]))
                bs.add(g.point_widths, (size_t)idx[i], 0.5 * side * bi * dot(N, n_q) * factor);
        }
        // Metric: sum_i c_i (x) P_i(pixel) - n_q (x) p, with sum b_i P_i = B and sum b_i' P_i = B'.
        add_metric(d, pc.draw, g, bs, n_q, factor, to_pixel(d, seg_eval(W, T_whole)) - bs.p);
        add_metric(d, pc.draw, g, bs, N, -factor * tilt, to_pixel(d, seg_deriv(W, T_whole)));
        return true;
    }

    // The end pieces of a stroke item: the cap before it (side 0), or the join or cap
    // after it (side 1), sampled along the outline that can be the stroke's boundary (not
    // the seams with the sweeps). Translation exactly; tangent rotations and the width by
    // central differences of the construction.
    struct EndGeometry {
        bool valid = false, butt = false, join = false;
        Vec2 at;               // the vertex
        EndFrame in, out;      // frames: in = of this item's end (or start); out = the next item's start
    };

    VF_HD EndGeometry end_geometry(const PreparedDraw& d, const StrokeSegment& s, int side) const {
        EndGeometry eg;
        const StrokeEnd& e = side == 0 ? s.start : s.end;
        eg.butt = side == 0 ? s.butt_start : s.butt_end;
        if (e.kind == StrokeEnd::NONE && !eg.butt) return eg;
        eg.valid = true;
        // Frames of the whole segments (a piece's end frame is the whole segment's, and
        // its control points are the ones the gradients belong to).
        if (side == 0) {
            eg.at = s.seg.p[0];
            eg.in = end_frame(whole_segment(sc_, d, s), false);
        } else {
            eg.at = seg_end(s.seg);
            eg.in = end_frame(whole_segment(sc_, d, s), true);
            if (s.next >= 0 && e.kind != StrokeEnd::NONE && !eg.butt) {
                eg.join = true;
                eg.out = end_frame(whole_segment(sc_, d, sc_.stroke_items[s.next]), false);
            }
        }
        return eg;
    }

    // Point and outward normal at fraction lam of the outline of the piece built from the
    // given tangents and half width; returns the outline's length.
    VF_HD double outline(const PreparedDraw& d, const EndGeometry& eg, int side, const StrokeSegment& s, Vec2 t_in,
                   Vec2 t_out, double hw, double lam, Vec2& q, Vec2& n) const {
        const StrokeEnd& stored = side == 0 ? s.start : s.end;
        if (eg.butt) {  // the end normal line, facing along the outward tangent
            Vec2 axis = side == 0 ? -t_in : t_in, nn = perp(axis);
            q = eg.at + ((2 * lam - 1) * hw) * nn;
            n = axis;
            return 2 * hw;
        }
        StrokeEnd e;
        if (eg.join) e = make_join(eg.at, t_in, t_out, d.join, hw, d.miter_limit);
        else if (stored.kind == StrokeEnd::SQUARE && s.seg.degree == 1 && s.seg.p[0].x == s.seg.p[1].x &&
                 s.seg.p[0].y == s.seg.p[1].y)
            e = stored;  // the dot of a zero-length subpath: axis fixed
        else e = make_cap(eg.at, side == 0 ? -t_in : t_in, d.cap, hw);
        if (e.kind == StrokeEnd::DISK) {
            double phi = 2 * M_PI * lam;
            n = {std::cos(phi), std::sin(phi)};
            q = e.center + hw * n;
            return 2 * M_PI * hw;
        }
        if (e.kind == StrokeEnd::SQUARE) {  // three outer edges of the half square
            Vec2 A = e.axis, B = perp(A);
            double x = 4 * hw * lam;
            if (x < hw) { q = e.center + x * A + hw * B; n = B; }
            else if (x < 3 * hw) { q = e.center + hw * A + (2 * hw - x) * B; n = A; }
            else { q = e.center + (4 * hw - x) * A - hw * B; n = -B; }
            return 4 * hw;
        }
        if (e.kind == StrokeEnd::POLYGON) {  // outer edges: poly[1] .. poly[n-1]
            int edges = e.n_poly - 2;
            double lens[2], total = 0;
            for (int k = 0; k < edges; ++k) total += (lens[k] = distance(e.poly[k + 1], e.poly[k + 2]));
            if (total <= 0) return 0;
            double x = lam * total;
            int k = 0;
            while (k + 1 < edges && x > lens[k]) x -= lens[k++];
            Vec2 a = e.poly[k + 1], b = e.poly[k + 2];
            q = a + (lens[k] > 0 ? x / lens[k] : 0.0) * (b - a);
            n = normalized(perp(b - a));
            if (dot(n, q - e.poly[0]) < 0) n = -n;
            return total;
        }
        return 0;
    }

    VF_HD bool end_sample(const Piece& pc, const PreparedDraw& d, double t, const GradView& g, BoundarySample& bs) const {
        const StrokeSegment& s = sc_.stroke_items[d.first_item + pc.item];
        EndGeometry eg = end_geometry(d, s, pc.side);
        if (!eg.valid) return false;
        const StrokeEnd& stored = pc.side == 0 ? s.start : s.end;
        double hw = stored.hw;  // the draw's, or the vertex's (per-point widths)
        Vec2 q, n;
        Vec2 t_out = eg.join ? eg.out.t : eg.in.t;
        double len = outline(d, eg, pc.side, s, eg.in.t, t_out, hw, t, q, n);
        if (len <= 0) return false;
        double factor;
        bs.n = pixel_normal(d, n, factor);
        bs.p = to_pixel(d, q);
        // length in pixels: the outline's stroke-space length, scaled along its direction
        Vec2 dir = perp(n);
        bs.weight = len * length(d.metric_identity ? dir : d.metric_inv * dir) / pc.count;
        int32_t idx[4];
        stroke_item_indices(sc_, s, idx);
        int vertex = pc.side == 0 ? idx[0] : idx[s.seg.degree];
        add_point_dir(d, g, bs, vertex, n, factor, 1.0);
        // rotation of a frame by a small angle h, and the width
        const double h = 1e-6, dw = 1e-6 * vmax(hw, 1.0);
        auto rotate = [](Vec2 v, double a) {
            return Vec2{v.x * std::cos(a) - v.y * std::sin(a), v.x * std::sin(a) + v.y * std::cos(a)};
        };
        auto normal_rate = [&](Vec2 ti_p, Vec2 to_p, Vec2 ti_m, Vec2 to_m, double hw_p, double hw_m, double step) {
            Vec2 qp, qm, nn;
            outline(d, eg, pc.side, s, ti_p, to_p, hw_p, t, qp, nn);
            outline(d, eg, pc.side, s, ti_m, to_m, hw_m, t, qm, nn);
            return dot(qp - qm, n) / (2 * step);
        };
        double rate_in = normal_rate(rotate(eg.in.t, h), t_out, rotate(eg.in.t, -h), t_out, hw, hw, h);
        // dtheta = N . (d head - d tail) / L for the frame's control points (stroke space)
        add_metric(d, pc.draw, g, bs, n, factor, to_pixel(d, eg.at) - bs.p);
        auto add_frame = [&](const EndFrame& f, const int32_t* fidx, double rate, const Segment& w) {
            if (f.length <= 0 || rate == 0) return;
            Vec2 N = perp(f.t);
            add_point_dir(d, g, bs, fidx[f.head], N, factor, rate / f.length);
            add_point_dir(d, g, bs, fidx[f.tail], N, factor, -rate / f.length);
            // the frame's direction is M (head - tail) in pixel terms
            add_metric(d, pc.draw, g, bs, N, factor * rate / f.length, to_pixel(d, w.p[f.head] - w.p[f.tail]));
        };
        add_frame(eg.in, idx, rate_in, whole_segment(sc_, d, s));
        if (eg.join) {
            double rate_out = normal_rate(eg.in.t, rotate(t_out, h), eg.in.t, rotate(t_out, -h), hw, hw, h);
            int32_t nidx[4];
            stroke_item_indices(sc_, sc_.stroke_items[s.next], nidx);
            add_frame(eg.out, nidx, rate_out, whole_segment(sc_, d, sc_.stroke_items[s.next]));
        }
        // (one-sided where the width is about 0: a join of negative width does not exist)
        double rate_w = hw > dw ? normal_rate(eg.in.t, t_out, eg.in.t, t_out, hw + dw, hw - dw, dw)
                                : 2 * normal_rate(eg.in.t, t_out, eg.in.t, t_out, hw + dw, hw, dw);
        if (!d.varying) bs.add(g.draw_params, DRAW_FCOLS * (size_t)pc.draw, 0.5 * rate_w * factor);
        else if (width_free(sc_, stored.width_index))
            bs.add(g.point_widths, (size_t)stored.width_index, 0.5 * rate_w * factor);
        return true;
    }
};

}  // namespace vf
