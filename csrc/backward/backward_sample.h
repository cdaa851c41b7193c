// The backward pass's per-sample work, shared by the CPU lanes (backward.cpp) and the
// CUDA kernels (cuda/backward.cu), after Li et al. 2020, section 5. Monte Carlo mode:
//   * interior term: per pixel sample, reverse-mode through front-to-back compositing
//     (with layers) into paint parameters, stop offsets / colours and layer opacities;
//   * boundary term (Reynolds transport): stratified samples on every boundary of every
//     draw (fill segments, ellipses, stroke offset curves, caps, joins, butt ends), each
//     weighted by its length element; at p+ = p + eps n (just outside) the scene is
//     composited once with the draw forced to cover p+ and once as it is. The difference
//     times the normal velocity of p goes to the parameters. A shared edge is counted
//     once, an occluded one gives zero, and a boundary piece that lies inside another
//     piece of the same stroke changes nothing.
// Analytical prefilter: the chain rule through the kernel K(sd / r) and the signed
// distance, whose derivative needs no derivative of the root solver (sdf_backward).
// On the CPU, gradients accumulate in one buffer per lane (a fixed slice of the work),
// summed in lane order: the result is deterministic for a given seed and thread count. On
// a GPU the threads add atomically, in no fixed order: sums agree to rounding.
// The lists a sample needs (hits, tape) live in Buffers the caller sizes: to the scene's
// worst case on the CPU, a fixed size per GPU thread (an overflow is flagged there, and
// the pass is redone on the CPU).
#pragma once

#include <cmath>

#include "backward/grads.h"
#include "common/sampling.h"
#include "forward/forward.h"
#include "scene/coverage.h"
#include "scene/layers.h"
#include "scene/paint.h"
#include "scene/stroke.h"
#include "scene/tiles.h"

namespace vf {

constexpr double EPS_NORMAL = 1e-4;  // pixels: how far p+ and p- lie from the boundary

struct Hit {
    int draw;
    double c[4];  // premultiplied colour of the draw at the point (times its coverage)
    // analytical prefilter only: coverage K(sd / r), the signed distance, the paint colour
    // (premultiplied) and the piece the distance came from
    double cov = 1, sd = 0, paint[4] = {0, 0, 0, 0};
    SdfArg arg;
};

VF_HD int tile_of(const TileView& bins, Vec2 p) {
    int tx = vclamp((int)std::floor(p.x / TILE), 0, bins.nx - 1);
    int ty = vclamp((int)std::floor(p.y / TILE), 0, bins.ny - 1);
    return ty * bins.nx + tx;
}

VF_HD bool covers(const SceneView& sc, const TileView& bins, const TileEntry& e, const Box& region, Vec2 p) {
    const Box& b = sc.draws[e.draw].box;
    return p.x >= b.x0 && p.x <= b.x1 && p.y >= b.y0 && p.y <= b.y1 && entry_covers(sc, bins, e, region, p);
}

// Does draw `draw` cover p? (p inside the tile grid's reach.)
VF_HD bool draw_covers_at(const SceneView& sc, const TileView& bins, int draw, Vec2 p) {
    int tile = tile_of(bins, p);
    Box region = bins.region(tile);
    if (p.x < region.x0 || p.x > region.x1 || p.y < region.y0 || p.y > region.y1) return false;
    const TileEntry* es = bins.begin(tile);
    int n = bins.count(tile);
    int lo = 0, hi = n;  // entries are sorted by draw index (paint order)
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (es[mid].draw < draw) lo = mid + 1; else hi = mid;
    }
    if (lo >= n || es[lo].draw != draw) return false;
    return covers(sc, bins, es[lo], region, p);
}

// Draws covering p, front to back, with their premultiplied colours; `forced` (if >= 0)
// counts as covering. Returns the count.
VF_HD int collect_hits(const SceneView& sc, const TileView& bins, Vec2 p, int forced, Buffer<Hit>& hits) {
    hits.clear();
    int tile = tile_of(bins, p);
    Box region = bins.region(tile);
    bool in_region = p.x >= region.x0 && p.x <= region.x1 && p.y >= region.y0 && p.y <= region.y1;
    const TileEntry* es = bins.begin(tile);
    int n = in_region ? bins.count(tile) : 0;
    bool forced_done = forced < 0;
    // Without layers, what lies behind a second opaque draw cannot matter: the first
    // opaque one hides it, and that one's alpha derivative needs only the composite behind
    // it, which the second one ends.
    bool may_stop = forced < 0 && sc.layer_parent.size() <= 1;
    int opaque = 0;
    auto add = [&](int draw) {
        Hit h;
        h.draw = draw;
        paint_color(sc, sc.paints[sc.draws[draw].paint], p, h.c);
        hits.push_back(h);
        if (h.c[3] >= 1) ++opaque;
    };
    for (int k = n - 1; k >= 0 && !(may_stop && opaque >= 2); --k) {
        int draw = es[k].draw;
        if (!forced_done && forced > draw) {
            add(forced);
            forced_done = true;
        }
        if (draw == forced) {
            add(forced);
            forced_done = true;
            continue;
        }
        if (covers(sc, bins, es[k], region, p)) add(draw);
    }
    if (!forced_done) add(forced);
    return (int)hits.size();
}

// Analytical prefilter: the draws reaching p, front to back, with fractional coverage.
VF_HD void collect_hits_analytic(const SceneView& sc, const TileView& bins, Vec2 p, double r, Buffer<Hit>& hits) {
    hits.clear();
    int tile = tile_of(bins, p);
    Box region = bins.region(tile);
    const TileEntry* es = bins.begin(tile);
    for (int k = bins.count(tile) - 1; k >= 0; --k) {
        const TileEntry& e = es[k];
        const PreparedDraw& d = sc.draws[e.draw];
        Box near = grown(d.box, r);
        if (p.x < near.x0 || p.x > near.x1 || p.y < near.y0 || p.y > near.y1) continue;
        Hit h;
        h.draw = e.draw;
        h.sd = entry_sdf(sc, bins, e, region, p, r, &h.arg);
        h.cov = kernel_coverage(h.sd / r);
        if (h.cov <= 0) continue;
        paint_color(sc, sc.paints[d.paint], p, h.paint);
        for (int i = 0; i < 4; ++i) h.c[i] = h.cov * h.paint[i];
        hits.push_back(h);
    }
}

// The jump at p when draw `forced` comes to cover it, for scenes without layers:
// composite = F + T (c_d + (1 - a_d) B) with the draw, F + T B without it, where T is
// the transmittance of what lies in front of the draw and B the composite behind it, so
// delta = T (c_d - a_d B). One front-to-back pass that stops as soon as T is 0 (the
// draw is hidden) or B is opaque.
VF_HD void jump_without_layers(const SceneView& sc, const TileView& bins, Vec2 p, int forced, double delta[4]) {
    for (int i = 0; i < 4; ++i) delta[i] = 0;
    int tile = tile_of(bins, p);
    Box region = bins.region(tile);
    if (p.x < region.x0 || p.x > region.x1 || p.y < region.y0 || p.y > region.y1) return;
    const TileEntry* es = bins.begin(tile);
    double T = 1, B[4] = {0, 0, 0, 0}, c[4];
    for (int k = bins.count(tile) - 1; k >= 0; --k) {
        int draw = es[k].draw;
        if (draw == forced) continue;
        if (draw > forced) {  // in front
            if (!covers(sc, bins, es[k], region, p)) continue;
            paint_color(sc, sc.paints[sc.draws[draw].paint], p, c);
            T *= 1 - c[3];
            if (T <= 0) return;
        } else {  // behind
            if (!covers(sc, bins, es[k], region, p)) continue;
            paint_color(sc, sc.paints[sc.draws[draw].paint], p, c);
            double k2 = 1 - B[3];
            for (int i = 0; i < 4; ++i) B[i] += k2 * c[i];
            if (B[3] >= 1) break;
        }
    }
    double cd[4];
    paint_color(sc, sc.paints[sc.draws[forced].paint], p, cd);
    for (int i = 0; i < 4; ++i) delta[i] = T * (cd[i] - cd[3] * B[i]);
}

// Compositing of hits (given front to back) evaluated back to front, with the tape needed
// to run it in reverse.
struct TapeOp {
    enum Kind { OVER, PUSH, POP } kind;
    int ref;           // hit index (OVER) or layer (PUSH/POP)
    double prev[4];    // the frame's colour before the op (OVER) / the parent's (POP)
    double layer[4];   // the closed layer's colour (POP)
};

struct Tape {
    using Op = TapeOp;
    static constexpr TapeOp::Kind OVER = TapeOp::OVER, PUSH = TapeOp::PUSH, POP = TapeOp::POP;
    Buffer<TapeOp> ops;
};

// dL/d(a hit's premultiplied colour).
struct Quad {
    double v[4];
    VF_HD double& operator[](int i) { return v[i]; }
    VF_HD double operator[](int i) const { return v[i]; }
};

VF_HD void composite(const SceneView& sc, const Buffer<Hit>& hits, Tape* tape, double out[4]) {
    LayerFrame stack[MAX_LAYER_DEPTH];
    int top = 0;
    stack[0].layer = 0;
    for (int i = 0; i < 4; ++i) stack[0].c[i] = 0;
    if (tape) tape->ops.clear();
    auto pop = [&] {
        LayerFrame& child = stack[top];
        LayerFrame& parent = stack[top - 1];
        double op = sc.layer_opacity[child.layer];
        if (tape) {
            Tape::Op o{Tape::POP, child.layer, {}, {}};
            for (int i = 0; i < 4; ++i) { o.prev[i] = parent.c[i]; o.layer[i] = child.c[i]; }
            tape->ops.push_back(o);
        }
        double k = 1 - op * child.c[3];
        for (int i = 0; i < 4; ++i) parent.c[i] = op * child.c[i] + k * parent.c[i];
        --top;
    };
    for (int h = (int)hits.size() - 1; h >= 0; --h) {
        enter_layer(sc, stack, top, sc.draws[hits[h].draw].layer, pop, [&](int opened) {
            if (tape) tape->ops.push_back({Tape::PUSH, opened, {}, {}});
        });
        LayerFrame& f = stack[top];
        if (tape) {
            Tape::Op o{Tape::OVER, h, {}, {}};
            for (int i = 0; i < 4; ++i) o.prev[i] = f.c[i];
            tape->ops.push_back(o);
        }
        const double* c = hits[h].c;
        for (int i = 0; i < 4; ++i) f.c[i] = c[i] + (1 - c[3]) * f.c[i];
    }
    while (top > 0) pop();
    for (int i = 0; i < 4; ++i) out[i] = stack[0].c[i];
}

// Reverse of composite: g is dL/d(result); adds dL/d(hit colour) into g_hits and
// dL/d(layer opacity) into grads.
VF_HD void composite_backward(const SceneView& sc, const Buffer<Hit>& hits, const Tape& tape, const double g[4],
                        Buffer<Quad>& g_hits, const GradView& grads) {
    g_hits.clear();
    for (int k = 0; k < hits.size(); ++k) g_hits.push_back(Quad{{0, 0, 0, 0}});
    double adj[MAX_LAYER_DEPTH][4];
    int top = 0;
    for (int i = 0; i < 4; ++i) adj[0][i] = g[i];
    for (int k = (int)tape.ops.size() - 1; k >= 0; --k) {
        const Tape::Op& o = tape.ops[k];
        double* a = adj[top];
        if (o.kind == Tape::OVER) {
            const double* c = hits[o.ref].c;
            double dp = a[0] * o.prev[0] + a[1] * o.prev[1] + a[2] * o.prev[2] + a[3] * o.prev[3];
            for (int i = 0; i < 4; ++i) g_hits[o.ref][i] += a[i];
            g_hits[o.ref][3] -= dp;
            for (int i = 0; i < 4; ++i) a[i] *= 1 - c[3];
        } else if (o.kind == Tape::POP) {
            double op = sc.layer_opacity[o.ref];
            double dp = a[0] * o.prev[0] + a[1] * o.prev[1] + a[2] * o.prev[2] + a[3] * o.prev[3];
            double dl = a[0] * o.layer[0] + a[1] * o.layer[1] + a[2] * o.layer[2] + a[3] * o.layer[3];
            grads.layer_opacity[o.ref] += dl - o.layer[3] * dp;
            double* child = adj[top + 1];
            for (int i = 0; i < 4; ++i) child[i] = op * a[i];
            child[3] -= op * dp;
            double k2 = 1 - op * o.layer[3];
            for (int i = 0; i < 4; ++i) a[i] *= k2;
            ++top;
        } else {  // PUSH: the layer's frame began empty; back to the parent's adjoint
            --top;
        }
    }
}

// ------------------------------------------------------------------- boundaries

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

// A boundary piece: what to sample and how many samples.
struct Piece {
    enum Kind { FILL_SEGMENT, ELLIPSE, OFFSET, END } kind;
    int draw, item, side, count;
};

VF_HD double polygon_length(const Segment& s) {
    double l = 0;
    for (int i = 0; i < s.degree; ++i) l += distance(s.p[i], s.p[i + 1]);
    return l;
}

VF_HD double bernstein(int n, int i, double t) {
    static const double binom[4][4] = {{1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
    double u = 1 - t, v = binom[n][i];
    for (int k = 0; k < i; ++k) v *= t;
    for (int k = i; k < n; ++k) v *= u;
    return v;
}

// d/dt of bernstein(n, i, t): n (b_{i-1}^{n-1} - b_i^{n-1}).
VF_HD double bernstein_deriv(int n, int i, double t) {
    if (n == 0) return 0;
    double a = i >= 1 ? bernstein(n - 1, i - 1, t) : 0.0, b = i <= n - 1 ? bernstein(n - 1, i, t) : 0.0;
    return n * (a - b);
}

// Per-point widths: whether point k's width takes gradients. A negative input is clamped
// to 0 (no gradient, as the clamp has none); 0 itself does, so a width can grow from 0.
VF_HD bool width_free(const SceneView& sc, int32_t k) { return k >= 0 && (size_t)k < sc.point_hw.size() && sc.point_hw[k] >= 0; }

// Pixel-space control-point indices of a stroke item (its straightened form uses the ends).
VF_HD void stroke_item_indices(const SceneView& sc, const StrokeSegment& s, int32_t idx[4]) {
    const PreparedSegment& src = sc.segments[s.source];
    for (int i = 0; i < 4; ++i) idx[i] = -1;
    if (s.seg.degree == src.seg.degree) {
        for (int i = 0; i <= s.seg.degree; ++i) idx[i] = src.point_index[i];
    } else {
        idx[0] = src.point_index[0];
        idx[s.seg.degree] = src.point_index[src.seg.degree];
    }
}

// The whole stroke-space segment a stroke item is a piece of (as preparation made it).
VF_HD Segment whole_segment(const SceneView& sc, const PreparedDraw& d, const StrokeSegment& s) {
    Segment w = sc.segments[s.source].seg;
    if (!d.metric_identity) w = transformed(w, d.metric);
    return straightened(w, d.varying);
}

// A piece's parameter t as a parameter of the whole segment.
VF_HD double whole_t(const StrokeSegment& s, double t) { return s.t0 + t * (s.t1 - s.t0); }

// The frame of a stroke item's end: unit tangent (direction of travel) and the two
// control points it comes from (head - tail), with their distance, in stroke space.
struct EndFrame {
    Vec2 t;
    int head = 0, tail = 0;  // control point numbers within the segment
    double length = 0;
};

VF_HD EndFrame end_frame(const Segment& s, bool end) {
    EndFrame f;
    int n = s.degree;
    if (end) {
        f.head = n;
        for (int i = n - 1; i >= 0; --i)
            if (dot(s.p[n] - s.p[i], s.p[n] - s.p[i]) > 1e-24) { f.tail = i; break; }
    } else {
        f.tail = 0;
        for (int i = 1; i <= n; ++i)
            if (dot(s.p[i] - s.p[0], s.p[i] - s.p[0]) > 1e-24) { f.head = i; break; }
    }
    Vec2 d = s.p[f.head] - s.p[f.tail];
    f.length = length(d);
    f.t = f.length > 0 ? (1 / f.length) * d : Vec2{1, 0};
    return f;
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

// ------------------------------------------------------- analytical prefilter

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


// ------------------------------------------------------- one pixel, one boundary sample

// Work space of one interior pixel: the hits at a sample, the compositing tape, and the
// hits' adjoints.
struct InteriorScratch {
    Buffer<Hit> hits;
    Tape tape;
    Buffer<Quad> g_hits;
    VF_HD bool overflow() const { return hits.overflow || tape.ops.overflow || g_hits.overflow; }
};

// Interior term of pixel (x, y) (and, for the analytical prefilter, all of it: coverage
// is a smooth function of the geometry there, so there is no boundary term). o: the
// plan's options (filter radius settled); gp: dL/d(the pixel's premultiplied colour).
VF_HD void interior_pixel(const SceneView& sc, const TileView& bins, const RenderOptions& o, const double* gp,
                          int x, int y, InteriorScratch& w, const GradView& g) {
    if (gp[0] == 0 && gp[1] == 0 && gp[2] == 0 && gp[3] == 0) return;
    const int N = o.samples;
    const double R = o.filter_radius;
    const bool analytic = o.mode == MODE_ANALYTIC;
    uint64_t pixel = (uint64_t)y * o.width + x;
    double wsum = 0;
    for (int s = 0; s < N * N; ++s) {
        double fx = ((s % N) + 0.5) / N, fy = ((s / N) + 0.5) / N;
        if (o.mode == MODE_MC) sample_position(o.seed, pixel, s, N, fx, fy);
        wsum += filter_weight(o.filter, R, R * (2 * fx - 1), R * (2 * fy - 1));
    }
    if (wsum <= 0) return;
    for (int s = 0; s < N * N; ++s) {
        double fx = ((s % N) + 0.5) / N, fy = ((s / N) + 0.5) / N;
        if (o.mode == MODE_MC) sample_position(o.seed, pixel, s, N, fx, fy);
        double dx = R * (2 * fx - 1), dy = R * (2 * fy - 1);
        double wt = filter_weight(o.filter, R, dx, dy) / wsum;
        if (wt <= 0) continue;
        Vec2 p{x + 0.5 + dx, y + 0.5 + dy};
        if (analytic) collect_hits_analytic(sc, bins, p, R, w.hits);
        else collect_hits(sc, bins, p, -1, w.hits);
        if (w.hits.empty()) continue;
        double c[4], gs[4];
        composite(sc, w.hits, &w.tape, c);
        // Past a list's end (a GPU thread's fixed lists) the tape may have lost the POP
        // of a PUSH it kept, which composite_backward cannot walk back. The pass will be
        // redone with longer lists anyway: stop here.
        if (w.overflow()) return;
        for (int i = 0; i < 4; ++i) gs[i] = wt * gp[i];
        composite_backward(sc, w.hits, w.tape, gs, w.g_hits, g);
        for (int k = 0; k < w.hits.size(); ++k) {
            const Hit& h = w.hits[k];
            double gpaint[4];
            for (int i = 0; i < 4; ++i) gpaint[i] = h.cov * w.g_hits[k][i];
            paint_color_backward(sc, sc.draws[h.draw].paint, p, gpaint, g);
            if (!analytic) continue;
            double g_cov = 0;
            for (int i = 0; i < 4; ++i) g_cov += w.g_hits[k][i] * h.paint[i];
            double g_sd = g_cov * kernel_slope(h.sd / R) / R;
            if (g_sd != 0) sdf_backward(sc, h, p, g_sd, g);
        }
    }
}

// What every boundary sample needs to know about the image.
struct BoundaryContext {
    int width = 0, height = 0;
    double R = 0.5;               // filter radius
    int filter = 0;
    double filter_integral = 1;   // of the unnormalised filter over its support
    bool no_layers = true;
    const double* gpix = nullptr; // dL/d(premultiplied colour) per pixel
};

// Boundary term of sample j of piece pc (index `key`): where the draw's coverage changes
// across the boundary point, the change of the composite there, spread over the pixels
// whose filter reaches the point, times the point's normal velocity.
VF_HD void boundary_sample(const SceneView& sc, const TileView& bins, const BoundarySampler& pass, const Piece& pc,
                           int j, uint64_t key, const BoundaryContext& bc, Buffer<Hit>& hits, const GradView& g) {
    const double R = bc.R;
    const int W = bc.width, H = bc.height;
    BoundarySample bs;
    if (!pass.sample(pc, j, key, g, bs)) return;
    Vec2 p = bs.p;
    if (!(p.x >= -R && p.x <= W + R && p.y >= -R && p.y <= H + R)) return;
    // Just inside a stroke piece is inside the stroke by construction (within w/2 of the
    // curve along its normal); fills need both sides for orientation.
    bool fill_piece = pc.kind == Piece::FILL_SEGMENT || (pc.kind == Piece::ELLIPSE && pc.side == 0);
    bool in_minus = !fill_piece || draw_covers_at(sc, bins, bs.draw, p - EPS_NORMAL * bs.n);
    bool in_plus = draw_covers_at(sc, bins, bs.draw, p + EPS_NORMAL * bs.n);
    if (pc.kind == Piece::FILL_SEGMENT && !in_minus && in_plus) {
        bs.n = -bs.n;  // the segment runs the other way round
        for (int i = 0; i < bs.nv; ++i) bs.v[i].value = -bs.v[i].value;
        vswap(in_minus, in_plus);
    }
    if (!in_minus || in_plus) return;  // no change of coverage across p
    Vec2 outside = p + EPS_NORMAL * bs.n;
    double delta[4];
    if (bc.no_layers) {
        jump_without_layers(sc, bins, outside, bs.draw, delta);
    } else {
        double c_in[4], c_out[4];
        collect_hits(sc, bins, outside, bs.draw, hits);
        composite(sc, hits, nullptr, c_in);
        collect_hits(sc, bins, outside, -1, hits);
        composite(sc, hits, nullptr, c_out);
        for (int i = 0; i < 4; ++i) delta[i] = c_in[i] - c_out[i];
    }
    if (delta[0] == 0 && delta[1] == 0 && delta[2] == 0 && delta[3] == 0) return;
    int x0 = vmax(0, (int)std::floor(p.x - R)), x1 = vmin(W - 1, (int)std::floor(p.x + R));
    int y0 = vmax(0, (int)std::floor(p.y - R)), y1 = vmin(H - 1, (int)std::floor(p.y + R));
    double total = 0;
    for (int py = y0; py <= y1; ++py)
        for (int px = x0; px <= x1; ++px) {
            // Half-open support, as a pixel's samples are: a point on the line between two
            // pixels belongs to one of them, not both.
            double dx = p.x - (px + 0.5), dy = p.y - (py + 0.5);
            if (dx < -R || dx >= R || dy < -R || dy >= R) continue;
            double w = filter_weight(bc.filter, R, dx, dy) / bc.filter_integral;
            const double* gp = bc.gpix + 4 * ((size_t)py * W + px);
            total += w * (gp[0] * delta[0] + gp[1] * delta[1] + gp[2] * delta[2] + gp[3] * delta[3]);
        }
    total *= bs.weight;
    if (total == 0) return;
    for (int i = 0; i < bs.nv; ++i) bs.v[i].target += total * bs.v[i].value;
}

}  // namespace vf
