// The backward pass's per-sample work, shared by the CPU lanes (backward.cpp) and the
// CUDA kernels (cuda/backward.cu), after Li et al. 2020, section 5: here the drivers, one
// pixel (pixel_backward, the adjoint of forward/pixel.h's pixel_forward, by way of
// sample_backward) and one boundary sample (boundary_sample); the parts they run are in
// hits.h, composite.h, paint.h, boundary.h and prefilter.h. Monte Carlo mode:
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
// distance, whose derivative needs no derivative of the root solver (entry_sdf_backward).
// On the CPU, gradients accumulate in one buffer per lane (a fixed slice of the work),
// summed in lane order: the result is deterministic for a given seed and thread count. On
// a GPU the threads add atomically, in no fixed order: sums agree to rounding.
// The lists a sample needs (hits, tape) live in Buffers the caller sizes: to the scene's
// worst case on the CPU, a fixed size per GPU thread (an overflow is flagged there, and
// the pass is redone on the CPU).
#pragma once

#include <cmath>

#include "backward/boundary.h"
#include "backward/composite.h"
#include "backward/grads.h"
#include "backward/hits.h"
#include "backward/paint.h"
#include "backward/prefilter.h"
#include "common/portable.h"
#include "common/sampling.h"
#include "forward/forward.h"
#include "scene/scene.h"
#include "scene/tiles.h"

namespace vf {

// Work space of pixel_backward, reused from sample to sample: the hits at a sample, the
// compositing tape, and the hits' adjoints.
struct SampleScratch {
    Buffer<Hit> hits;
    Tape tape;
    Buffer<Quad> g_hits;
    VF_HD bool overflow() const { return hits.overflow || tape.ops.overflow || g_hits.overflow; }
};

// Adjoint of sample_forward (forward/pixel.h), the premultiplied colour of the scene at
// p: g_c is dL/d(that colour); adds dL/d(paint parameters, stops, layer opacities) and,
// for the analytical prefilter, dL/d(geometry) through the signed distances. Returns
// false where a list overflowed (a GPU thread's fixed lists): past a list's end the tape
// may have lost the POP of a PUSH it kept, which composite_backward cannot walk back, so
// nothing is added and the pass is to be redone with longer lists.
VF_HD bool sample_backward(const SceneView& sc, const TileView& bins, Vec2 p, const RenderOptions& o,
                           const double g_c[4], SampleScratch& w, const GradView& g,
                           const FieldView* fields = nullptr, int sample = 0) {
    const double R = o.filter_radius;
    const bool analytic = o.mode == MODE_ANALYTIC;
    if (analytic) collect_hits_analytic(sc, bins, p, R, w.hits, fields, sample);
    else collect_hits(sc, bins, p, -1, w.hits);
    if (w.hits.empty()) return true;
    double c[4];
    composite_forward(sc, w.hits, &w.tape, c);
    if (w.overflow()) return false;
    composite_backward(sc, w.hits, w.tape, g_c, w.g_hits, g);
    for (int k = 0; k < w.hits.size(); ++k) {
        const Hit& h = w.hits[k];
        double gpaint[4];
        for (int i = 0; i < 4; ++i) gpaint[i] = h.cov * w.g_hits[k][i];
        paint_color_backward(sc, sc.draws[h.draw].paint, p, gpaint, g);
        if (!analytic) continue;
        double g_cov = 0;
        for (int i = 0; i < 4; ++i) g_cov += w.g_hits[k][i] * h.paint[i];
        double g_sd = g_cov * kernel_slope(h.sd / R) / R;
        if (g_sd != 0) entry_sdf_backward(sc, h, p, g_sd, g);
    }
    return true;
}

// Adjoint of pixel_forward (forward/pixel.h) at pixel (x, y): the interior term of the
// Monte Carlo mode, and for the analytical prefilter all of it (coverage is a smooth
// function of the geometry there, so there is no boundary term). o: the plan's options
// (filter radius settled); gp: dL/d(the pixel's premultiplied colour), background
// excluded (see pixel_adjoints in backward.cpp).
VF_HD void pixel_backward(const SceneView& sc, const TileView& bins, const RenderOptions& o, const double* gp,
                          int x, int y, SampleScratch& w, const GradView& g, const FieldView* fields = nullptr) {
    if (gp[0] == 0 && gp[1] == 0 && gp[2] == 0 && gp[3] == 0) return;
    const int N = o.samples;
    const double R = o.filter_radius;
    uint64_t pixel = (uint64_t)y * o.width + x;
    // The weights' sum; the box filter's weights are all 1, so its sum needs no positions
    // (which would cost more than the one sample interior_samples = 1 visits).
    double wsum = o.filter == FILTER_BOX ? N * N : 0;
    for (int s = 0; o.filter != FILTER_BOX && s < N * N; ++s) {
        double fx = ((s % N) + 0.5) / N, fy = ((s / N) + 0.5) / N;
        if (o.mode == MODE_MC) sample_position(o.seed, pixel, s, N, fx, fy);
        wsum += filter_weight(o.filter, R, R * (2 * fx - 1), R * (2 * fy - 1));
    }
    if (wsum <= 0) return;
    // A random run of K consecutive samples (of N x N) stands for all of them, weighted by
    // N^2 / K: each sample is visited with probability K / N^2, so the sum stays unbiased.
    const int all = N * N;
    const int K = (o.mode == MODE_MC && o.interior_samples > 0 && o.interior_samples < all) ? o.interior_samples : all;
    const int first = K < all ? (int)(mix64(o.seed * 0x2545f4914f6cdd1dull ^ mix64(pixel + 0x632be59bd9b4e019ull)) % (uint64_t)all) : 0;
    wsum *= (double)K / all;
    for (int k = 0; k < K; ++k) {
        const int s = (first + k) % all;
        double fx = ((s % N) + 0.5) / N, fy = ((s / N) + 0.5) / N;
        if (o.mode == MODE_MC) sample_position(o.seed, pixel, s, N, fx, fy);
        double dx = R * (2 * fx - 1), dy = R * (2 * fy - 1);
        double wt = filter_weight(o.filter, R, dx, dy) / wsum;
        if (wt <= 0) continue;
        double g_c[4];  // the sample's share of the pixel's adjoint
        for (int i = 0; i < 4; ++i) g_c[i] = wt * gp[i];
        if (!sample_backward(sc, bins, {x + 0.5 + dx, y + 0.5 + dy}, o, g_c, w, g, fields,
                             fields ? tile_sample(x, y, o.width, all, s) : 0))
            return;
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

// p + e n with the product and the sum each rounded, on the host and the device alike.
VF_HD Vec2 nudged(Vec2 p, double e, Vec2 n) { return {mul_add_rn(p.x, e, n.x), mul_add_rn(p.y, e, n.y)}; }

// The pixels a boundary sample at p reaches, its change being at p+ (`outside`, p nudged
// EPS_NORMAL along the outward normal):
//   * where p+ is outside the area the pixels sample ([0.5 - R, W - 0.5 + R) per axis, the
//     canvas for the box filter), no pixel sees the change (false): an edge on the canvas
//     border facing out counts for nothing, on all four sides;
//   * else the pixels whose half-open support holds p, as a pixel's samples are (on the
//     line between two pixels, the one on its +x / +y side: counting it in both made
//     mcseem2's gradients 1.4x too large).
// Both are decided at the point moved by (NUDGE, NUDGE), towards the +x / +y side.
// Neither decision is taken at rounding level: p on a pixel line or the border (integer
// coordinates, a canvas-sized rect) is one rounding of seg_eval from either side, and
// nvcc's contracted multiply-adds round differently from the host's.
struct BoundarySupport {
    Vec2 at;  // p moved by (NUDGE, NUDGE)
    int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
    double R = 0.5;
    // Whether pixel (px, py)'s support holds the sample; (dx, dy) its offset from the centre.
    VF_HD bool holds(int px, int py, double& dx, double& dy) const {
        dx = at.x - (px + 0.5);
        dy = at.y - (py + 0.5);
        return !(dx < -R || dx >= R || dy < -R || dy >= R);
    }
};

VF_HD bool boundary_support(Vec2 p, Vec2 outside, double R, int W, int H, BoundarySupport& s) {
    const double lo = 0.5 - R, NUDGE = 1e-3 * EPS_NORMAL;
    Vec2 o{outside.x + NUDGE, outside.y + NUDGE};  // (p+ on the border line: the +x / +y side)
    if (!(o.x >= lo && o.x < W - lo && o.y >= lo && o.y < H - lo)) return false;
    s.at = {p.x + NUDGE, p.y + NUDGE};
    s.R = R;
    // (clamped before the conversion: coordinates of 1e15 px and more overflow an int)
    s.x0 = clamp_to_int(std::floor(s.at.x - R), 0, W);
    s.x1 = clamp_to_int(std::floor(s.at.x + R), -1, W - 1);
    s.y0 = clamp_to_int(std::floor(s.at.y - R), 0, H);
    s.y1 = clamp_to_int(std::floor(s.at.y + R), -1, H - 1);
    return true;
}

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
    bool in_minus = true, in_plus;
    if (fill_piece)
        draw_covers_pair(sc, bins, bs.draw, nudged(p, -EPS_NORMAL, bs.n), nudged(p, EPS_NORMAL, bs.n), in_minus, in_plus);
    else
        in_plus = draw_covers_at(sc, bins, bs.draw, nudged(p, EPS_NORMAL, bs.n));
    if (pc.kind == Piece::FILL_SEGMENT && !in_minus && in_plus) {
        bs.n = -bs.n;  // the segment runs the other way round
        for (int i = 0; i < bs.nv; ++i) bs.v[i].value = -bs.v[i].value;
        vswap(in_minus, in_plus);
    }
    if (!in_minus || in_plus) return;  // no change of coverage across p
    Vec2 outside = nudged(p, EPS_NORMAL, bs.n);  // (after the flip above)
    BoundarySupport support;
    if (!boundary_support(p, outside, R, W, H, support)) return;  // the change is off the canvas
    // (a draw behind with its own edge through p, on the same side, moves with this one: see
    // jump_without_layers)
    Vec2 inside = nudged(p, -EPS_NORMAL, bs.n);
    double delta[4];
    if (bc.no_layers) {
        jump_without_layers(sc, bins, outside, inside, bs.draw, delta);
    } else {
        double c_in[4], c_out[4];
        collect_hits_of<true>(sc, bins, outside, bs.draw, hits, bs.draw, inside);
        composite_forward(sc, hits, nullptr, c_in);
        collect_hits_of<true>(sc, bins, outside, -1, hits, bs.draw, inside);
        composite_forward(sc, hits, nullptr, c_out);
        for (int i = 0; i < 4; ++i) delta[i] = c_in[i] - c_out[i];
    }
    if (delta[0] == 0 && delta[1] == 0 && delta[2] == 0 && delta[3] == 0) return;
    double total = 0;
    for (int py = support.y0; py <= support.y1; ++py)
        for (int px = support.x0; px <= support.x1; ++px) {
            double dx, dy;
            if (!support.holds(px, py, dx, dy)) continue;
            double w = filter_weight(bc.filter, R, dx, dy) / bc.filter_integral;
            const double* gp = bc.gpix + 4 * ((size_t)py * W + px);
            total += w * (gp[0] * delta[0] + gp[1] * delta[1] + gp[2] * delta[2] + gp[3] * delta[3]);
        }
    total *= bs.weight * pc.scale;
    if (total == 0) return;
    for (int i = 0; i < bs.nv; ++i) bs.v[i].target += total * bs.v[i].value;
}

}  // namespace vf
