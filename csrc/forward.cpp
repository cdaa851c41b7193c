// Forward pass: per tile, per pixel, per sample, composite the draws that cover the sample
// front to back (stopping once it is opaque), with nested layers for group opacity.
#include <algorithm>
#include <cmath>

#include "coverage.h"
#include "layers.h"
#include "paint.h"
#include "render.h"
#include "sampling.h"
#include "thread_pool.h"
#include "tiles.h"

namespace vf {
namespace {

// Parabolic prefilter kernel: coverage of a half-plane at signed distance d (in units of
// the kernel radius, positive outside): 1/2 + (d^3 - 3d)/4 on [-1, 1].
inline double kernel_coverage(double d) {
    if (d <= -1) return 1;
    if (d >= 1) return 0;
    return 0.5 + (d * d * d - 3 * d) * 0.25;
}

// Front-to-back compositing with a stack of open layers. Each frame accumulates the
// premultiplied colour of its layer; closing a layer scales it by the layer's opacity
// and puts it under what its parent has so far.
struct Compositor {
    const PreparedScene& sc;
    struct Frame {
        int layer;
        double c[4];
    } stack[MAX_LAYER_DEPTH];
    int top = 0;

    explicit Compositor(const PreparedScene& s) : sc(s) {
        stack[0].layer = 0;
        for (double& v : stack[0].c) v = 0;
    }

    void pop() {
        Frame& child = stack[top--];
        Frame& parent = stack[top];
        double k = (1 - parent.c[3]) * sc.layer_opacity[child.layer];
        for (int i = 0; i < 4; ++i) parent.c[i] += k * child.c[i];
    }

    void enter(int layer) {
        if (stack[top].layer == layer) return;
        while (!layer_contains(sc, stack[top].layer, layer)) pop();
        int chain[MAX_LAYER_DEPTH];
        int n = layers_between(sc, stack[top].layer, layer, chain);
        for (int i = 0; i < n; ++i) {
            Frame& f = stack[++top];
            f.layer = chain[i];
            for (double& v : f.c) v = 0;
        }
    }

    // Adds a premultiplied colour under what the current layer has.
    void under(const double c[4], double coverage) {
        Frame& f = stack[top];
        double k = (1 - f.c[3]) * coverage;
        for (int i = 0; i < 4; ++i) f.c[i] += k * c[i];
    }

    bool opaque() const { return top == 0 && stack[0].c[3] >= 1 - 1e-12; }

    void finish(double out[4]) {
        while (top > 0) pop();
        for (int i = 0; i < 4; ++i) out[i] = stack[0].c[i];
    }
};

struct LocalItems {
    const LocalItem* li;
    int n;
    int size() const { return n; }
    int operator[](int i) const { return li[i].item; }
};

// Coverage of one draw at p in [0, 1]: a step (Monte Carlo) or the prefiltered kernel.
double entry_coverage(const PreparedScene& sc, const TileBins& bins, const TileEntry& e, const Box& region,
                      Vec2 p, const RenderOptions& o) {
    const PreparedDraw& d = sc.draws[e.draw];
    const bool analytic = o.mode == MODE_ANALYTIC;
    const double r = o.filter_radius;
    const bool brute = o.brute_force;
    LocalItems local{bins.items.data() + e.first, e.count};
    AllItems all{d.n_items};
    if (d.kind == DRAW_STROKE) {
        if (analytic) {
            double sd = brute ? stroke_sdf(sc, d, all, p, r) : stroke_sdf(sc, d, local, p, r);
            return kernel_coverage(sd / r);
        }
        return (brute ? stroke_contains(sc, d, all, p) : stroke_contains(sc, d, local, p)) ? 1.0 : 0.0;
    }
    if (d.is_ellipse) {
        if (analytic) return kernel_coverage(ellipse_fill_sdf(d, p, r) / r);
        return ellipse_contains(d.ellipse, p) ? 1.0 : 0.0;
    }
    int w = brute ? draw_winding_all(sc, d, p) : tile_winding(sc, bins, e, region, p);
    bool inside = winding_inside(w, d.fill_rule);
    if (!analytic) return inside ? 1.0 : 0.0;
    double dist = brute ? fill_distance(sc, d, all, p, r) : fill_distance(sc, d, local, p, r);
    return kernel_coverage((inside ? -dist : dist) / r);
}

// Premultiplied colour of the scene at pixel-space point p, from the tile's entries.
void eval_point(const PreparedScene& sc, const TileBins& bins, int tile, Vec2 p, const RenderOptions& o,
                double out[4]) {
    Compositor comp(sc);
    const TileEntry* entries = bins.begin(tile);
    Box region = bins.region(tile);
    for (int k = bins.count(tile) - 1; k >= 0; --k) {
        const TileEntry& e = entries[k];
        const PreparedDraw& d = sc.draws[e.draw];
        if (p.x < d.box.x0 - o.filter_radius || p.x > d.box.x1 + o.filter_radius ||
            p.y < d.box.y0 - o.filter_radius || p.y > d.box.y1 + o.filter_radius)
            continue;
        double coverage = entry_coverage(sc, bins, e, region, p, o);
        if (coverage <= 0) continue;
        double c[4];
        paint_color(sc, sc.paints[d.paint], p, c);
        if (c[3] <= 0) continue;
        comp.enter(d.layer);
        comp.under(c, coverage);
        if (comp.opaque()) break;
    }
    comp.finish(out);
}

}  // namespace

void render_forward(const PreparedScene& sc, const RenderOptions& o, float* out) {
    const int W = o.width, H = o.height, N = std::max(1, o.samples);
    const double R = o.filter == FILTER_BOX ? 0.5 : std::max(0.5, o.filter_radius);
    RenderOptions opt = o;
    opt.filter_radius = R;
    double margin = std::max(0.0, R - 0.5) + (o.mode == MODE_ANALYTIC ? R : 0.0);
    TileBins bins = bin_draws(sc, W, H, margin + 1e-6, o.brute_force);

    double bg[4] = {0, 0, 0, 0};
    if (o.has_background) {
        double a = std::clamp(o.background[3], 0.0, 1.0);
        for (int i = 0; i < 3; ++i) bg[i] = std::clamp(o.background[i], 0.0, 1.0) * a;
        bg[3] = a;
    }

    ThreadPool::instance().parallel_for(bins.nx * bins.ny, o.threads, [&](int tile, int) {
        int tx = tile % bins.nx, ty = tile / bins.nx;
        int n = bins.count(tile);
        for (int y = ty * TILE; y < std::min(H, (ty + 1) * TILE); ++y) {
            for (int x = tx * TILE; x < std::min(W, (tx + 1) * TILE); ++x) {
                double acc[4] = {0, 0, 0, 0}, wsum = 0;
                uint64_t pixel = (uint64_t)y * W + x;
                for (int s = 0; s < N * N; ++s) {
                    double fx = ((s % N) + 0.5) / N, fy = ((s / N) + 0.5) / N;  // strata centres
                    if (o.mode == MODE_MC) sample_position(o.seed, pixel, s, N, fx, fy);
                    double dx = R * (2 * fx - 1), dy = R * (2 * fy - 1);
                    double w = filter_weight(o.filter, R, dx, dy);
                    if (w <= 0) continue;
                    double c[4] = {0, 0, 0, 0};
                    if (n > 0) eval_point(sc, bins, tile, {x + 0.5 + dx, y + 0.5 + dy}, opt, c);
                    for (int i = 0; i < 4; ++i) acc[i] += w * c[i];
                    wsum += w;
                }
                float* px = out + 4 * pixel;
                // Filtered premultiplied colour, the background under it, then straight RGBA.
                double k = wsum > 0 ? 1 / wsum : 0, c[4];
                for (int i = 0; i < 4; ++i) c[i] = acc[i] * k;
                double rest = 1 - c[3];
                for (int i = 0; i < 4; ++i) c[i] += rest * bg[i];
                double a = c[3];
                for (int i = 0; i < 3; ++i) px[i] = a > 0 ? (float)std::clamp(c[i] / a, 0.0, 1.0) : 0.0f;
                px[3] = (float)std::clamp(a, 0.0, 1.0);
            }
        }
    });
}

}  // namespace vf
