// Forward pass on the CPU: the tiles are shared out between threads; each pixel is
// shaded by pixel_forward (forward/pixel.h), which a CUDA build runs on the GPU as well.
#include <algorithm>
#include <array>
#include <vector>

#include "common/cancel.h"
#include "common/phase_clock.h"
#include "common/thread_pool.h"
#include "forward/forward.h"
#include "forward/pixel.h"
#include "scene/field.h"

namespace vf {

RenderOptions settled(const RenderOptions& o) {
    RenderOptions s = o;
    s.samples = std::max(1, o.samples);
    s.filter_radius = o.filter == FILTER_BOX ? 0.5 : std::max(0.5, o.filter_radius);
    return s;
}

void premultiplied_background(const RenderOptions& o, double out[4]) {
    for (int i = 0; i < 4; ++i) out[i] = 0;
    if (!o.has_background) return;
    double a = std::clamp(o.background[3], 0.0, 1.0);
    for (int i = 0; i < 3; ++i) out[i] = std::clamp(o.background[i], 0.0, 1.0) * a;
    out[3] = a;
}

ForwardPlan plan_forward(const PreparedScene& sc, const RenderOptions& o) {
    ForwardPlan plan;
    plan.options = settled(o);
    const double R = plan.options.filter_radius;
    double margin = std::max(0.0, R - 0.5) + (o.mode == MODE_ANALYTIC ? R : 0.0);
    PhaseTimer timer(PHASE_PLAN);
    plan.bins = bin_draws(sc, o.width, o.height, margin + 1e-6, o.brute_force, o.threads);
    premultiplied_background(o, plan.background);
    return plan;
}

namespace {

// A tile's samples for tile_forward, reused from tile to tile by a worker.
struct TileSamples {
    std::vector<Vec2> p;
    std::vector<double> weight;
    std::vector<std::array<double, 4>> colour;  // premultiplied, composited front to back
    std::vector<int> active, winding;            // samples not yet opaque; winding per active sample
    std::vector<int> row_begin;                  // active[row_begin[r]...]: those of pixel row r onwards
    std::vector<int> row_of;                     // pixel row of each sample
    std::vector<double> fx, fy;                  // one pixel's sample positions
};

// The Monte Carlo forward pass of one tile, draw by draw rather than sample by sample
// (scenes without layers, on the CPU): a tile entry's crossings are counted for all the
// tile's samples in one loop per segment, so that the segment's data stays at hand and
// the branches on where samples lie repeat from sample to sample, where pixel_forward
// goes through every entry's segments once per sample. Same samples, same integer
// windings, the same compositing operations in the same order per sample: the image is
// pixel_forward's bit for bit (the GPU runs pixel_forward).
void tile_forward(const SceneView& sc, const TileView& bins, const RenderOptions& o, const double bg[4], int tile,
                  float* out, TileSamples& ts) {
    const int N = o.samples, per_pixel = N * N, W = o.width, H = o.height;
    const double R = o.filter_radius;
    const int tx = tile % bins.nx, ty = tile / bins.nx;
    const int x0 = tx * TILE, y0 = ty * TILE, x1 = std::min(W, x0 + TILE), y1 = std::min(H, y0 + TILE);
    const size_t n = (size_t)(x1 - x0) * (y1 - y0) * per_pixel;
    ts.p.resize(n);
    ts.weight.resize(n);
    ts.colour.assign(n, {0, 0, 0, 0});
    ts.active.clear();
    ts.winding.resize(n);
    ts.row_of.resize(n);
    ts.fx.resize(per_pixel);
    ts.fy.resize(per_pixel);
    size_t i = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            pixel_sample_positions(o.seed, (uint64_t)y * W + x, N, ts.fx.data(), ts.fy.data());
            for (int s = 0; s < per_pixel; ++s, ++i) {  // pixel_forward's samples, in its order
                double dx = R * (2 * ts.fx[s] - 1), dy = R * (2 * ts.fy[s] - 1);
                ts.weight[i] = filter_weight(o.filter, R, dx, dy);
                ts.p[i] = {x + 0.5 + dx, y + 0.5 + dy};
                ts.row_of[i] = y - y0;
                if (ts.weight[i] > 0) ts.active.push_back((int)i);
            }
        }
    const TileEntry* entries = bins.begin(tile);
    const Box region = bins.region(tile);
    const int rows = y1 - y0;
    ts.row_begin.resize(rows + 1);
    auto index_rows = [&] {  // (active stays in row order)
        int a = 0, n_active = (int)ts.active.size();
        for (int r = 0; r <= rows; ++r) {
            while (a < n_active && ts.row_of[ts.active[a]] < r) ++a;
            ts.row_begin[r] = a;
        }
    };
    index_rows();
    for (int k = bins.count(tile) - 1; k >= 0 && !ts.active.empty(); --k) {
        const TileEntry& e = entries[k];
        const PreparedDraw& d = sc.draws[e.draw];
        const PreparedPaint& paint = sc.paints[d.paint];
        const bool solid = paint.kind == PAINT_SOLID;
        double c[4];
        if (solid) {
            paint_color(sc, paint, {0, 0}, c);
            if (c[3] <= 0) continue;
        }
        const Box near = grown(d.box, R);
        // Only the pixel rows whose samples (within R of their row's centre line) can lie in
        // the draw's box are visited: the active samples are in row order, so theirs are one
        // run, active[a0, a1). (A hair wider than the box: a sample on its edge is visited.)
        const int nr0 = clamp_to_int(std::ceil(near.y0 - 0.5 - R - 1e-7) - y0, 0, rows);
        const int nr1 = clamp_to_int(std::floor(near.y1 - 0.5 + R + 1e-7) - y0, -1, rows - 1);
        if (nr0 > nr1) continue;
        const int a0 = ts.row_begin[nr0], a1 = ts.row_begin[nr1 + 1];
        if (a0 == a1) continue;
        const bool counted = d.kind == DRAW_FILL && !d.is_ellipse;  // windings counted here
        if (counted) {
            for (int a = a0; a < a1; ++a) ts.winding[a] = e.winding;
            const PreparedSegment* segs = sc.fill_items.data() + d.first_item;
            const LocalItem* items = bins.items.data() + e.first;
            for (int li = 0; li < e.count; ++li) {
                const LocalItem& item = items[li];
                // Only the rows whose samples (within R of their row's centre line) can lie
                // in the segment's height range can cross it. (Clamped as doubles: a
                // coordinate can be 10^28 px.)
                int r0 = std::max(nr0, clamp_to_int(std::ceil(item.y0 - 0.5 - R) - y0, 0, rows));
                int r1 = std::min(nr1, clamp_to_int(std::floor(item.y1 - 0.5 + R) - y0, -1, rows - 1));
                if (r0 <= r1) {
                    const PreparedSegment& seg = segs[item.item];
                    for (int a = ts.row_begin[r0]; a < ts.row_begin[r1 + 1]; ++a)
                        ts.winding[a] += ray_crossings(seg, ts.p[ts.active[a]], region.x1);
                }
                if (item.cross >= 0) {  // the vertical leg: every sample at or below
                    const LegCrossings& c = bins.crossings[item.cross];
                    for (int j = 0; j < c.n; ++j)
                        for (int a = a0; a < a1; ++a)
                            if (c.y[j] <= ts.p[ts.active[a]].y) ts.winding[a] += c.dir[j];
                }
            }
        }
        int kept = a0;
        for (int a = a0; a < a1; ++a) {
            const int si = ts.active[a];
            const Vec2 q = ts.p[si];
            bool opaque = false;
            if (q.x >= near.x0 && q.x <= near.x1 && q.y >= near.y0 && q.y <= near.y1 &&
                (counted ? winding_inside(ts.winding[a], d.fill_rule) : entry_covers(sc, bins, e, region, q))) {
                if (!solid) paint_color(sc, paint, q, c);
                if (c[3] > 0) {
                    std::array<double, 4>& f = ts.colour[si];
                    double under = (1 - f[3]) * 1.0;  // FrontToBackCompositor::under, coverage 1
                    for (int ch = 0; ch < 4; ++ch) f[ch] += under * c[ch];
                    opaque = f[3] >= 1 - 1e-12;
                }
            }
            if (!opaque) ts.active[kept++] = si;
        }
        if (kept < a1) {  // samples turned opaque: drop them, the rest in order
            ts.active.erase(ts.active.begin() + kept, ts.active.begin() + a1);
            index_rows();
        }
    }
    i = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            double acc[4] = {0, 0, 0, 0}, wsum = 0;
            for (int s = 0; s < per_pixel; ++s, ++i) {
                double w = ts.weight[i];
                if (w <= 0) continue;
                for (int ch = 0; ch < 4; ++ch) acc[ch] += w * ts.colour[i][ch];
                wsum += w;
            }
            pixel_output(acc, wsum, bg, out + 4 * ((size_t)y * W + x), o.premultiplied);
        }
}

}  // namespace

void render_forward(const PreparedScene& prepared, const RenderOptions& o, float* out) {
    ForwardPlan plan = plan_forward(prepared, o);
    const SceneView sc = prepared.view();
    const TileView bins = plan.bins.view();
    const int W = o.width, H = o.height;
    const RenderOptions& s = plan.options;
    const bool by_entry = s.mode == MODE_MC && !s.brute_force && sc.layer_parent.size() <= 1 && s.samples <= 64;
    const int threads = std::max(1, o.threads > 0 ? o.threads : ThreadPool::hardware_threads());
    std::vector<TileSamples> scratch(threads);
    // The analytical mode: a tile's long fill entries ahead, segment by segment (scene/field.h).
    const bool fields = s.mode == MODE_ANALYTIC && !s.brute_force;
    std::vector<SampleGrid> grids(fields ? threads : 0);
    std::vector<TileFields> tile_fields(fields ? threads : 0);
    PhaseTimer timer(PHASE_FORWARD);
    // (and its long stroke entries, with their items' bounds)
    const std::vector<StrokeBound> stroke_bound = fields ? stroke_bounds(sc, bins, threads) : std::vector<StrokeBound>();
    ThreadPool::instance().parallel_for(bins.nx * bins.ny, threads, [&](int tile, int worker) {
        if (by_entry) {
            if (!cancelled()) tile_forward(sc, bins, s, plan.background, tile, out, scratch[worker]);
            return;
        }
        FieldView view;
        if (fields && bins.count(tile) > 0 && !cancelled()) {
            grids[worker].build(bins, tile, W, H, s.samples, s.filter_radius);
            tile_fields[worker].compute(sc, bins, tile, grids[worker], s.filter_radius, false,
                                        stroke_bound.empty() ? nullptr : stroke_bound.data());
            view = tile_fields[worker].view();
        }
        int tx = tile % bins.nx, ty = tile / bins.nx;
        for (int y = ty * TILE; y < std::min(H, (ty + 1) * TILE) && !cancelled(); ++y)
            for (int x = tx * TILE; x < std::min(W, (tx + 1) * TILE); ++x)
                pixel_forward(sc, bins, s, plan.background, x, y, out + 4 * ((size_t)y * W + x),
                              view.slot ? &view : nullptr);
    });
}

double filter_radius_gradient(const PreparedScene& prepared, const RenderOptions& o, const float* pixels,
                              const float* g) {
    ForwardPlan plan = plan_forward(prepared, o);
    const RenderOptions& s = plan.options;
    // The box's radius is fixed, and the others are settled to at least 0.5 px: there the
    // image does not depend on the radius.
    if (s.mode != MODE_MC || s.filter == FILTER_BOX || !(o.filter_radius >= 0.5)) return 0.0;
    const SceneView sc = prepared.view();
    const TileView bins = plan.bins.view();
    const int W = s.width, H = s.height, N = s.samples, per_pixel = N * N;
    const double R = s.filter_radius;
    // E[W] over the square of u, exact: a sum of the samples' weights would correlate with them
    const double mean_weight = filter_integral(s.filter, R) / (4 * R * R);
    const bool edge_term = s.filter == FILTER_GAUSSIAN;  // the only filter not 0 on its edge
    // Samples of their own, not the image's: g comes from the image, and an estimate from
    // the same samples correlates with it (on diffvg's optimize_pixel_filter.py, 2 x 2
    // samples and an L2 loss, that bias alone pushed the radius below 0)
    const uint64_t seed = mix64(s.seed ^ 0x2f1a7e5d3c9b8a61ull);
    std::vector<double> per_tile(bins.nx * bins.ny, 0.0);  // summed in order: independent of threads
    ThreadPool::instance().parallel_for(bins.nx * bins.ny, s.threads, [&](int tile, int) {
        if (bins.count(tile) == 0) return;
        int tx = tile % bins.nx, ty = tile / bins.nx;
        double total = 0;
        for (int y = ty * TILE; y < std::min(H, (ty + 1) * TILE); ++y)
            for (int x = tx * TILE; x < std::min(W, (tx + 1) * TILE); ++x) {
                const float* gp = g + 4 * ((size_t)y * W + x);
                if (gp[0] == 0 && gp[1] == 0 && gp[2] == 0 && gp[3] == 0) continue;
                const float* b = pixels + 4 * ((size_t)y * W + x);
                // g . (c - b) at offset u: b, the pixel as rendered, is independent of these
                // samples, and a flat region then adds exactly nothing instead of noise
                auto g_dot_change = [&](double ux, double uy) {
                    double c[4];
                    sample_forward(sc, bins, tile, {x + 0.5 + R * ux, y + 0.5 + R * uy}, s, c);
                    return gp[0] * (c[0] - b[0]) + gp[1] * (c[1] - b[1]) + gp[2] * (c[2] - b[2]) +
                           gp[3] * (c[3] - b[3]);
                };
                uint64_t pixel = (uint64_t)y * W + x;
                double acc = 0;
                for (int k = 0; k < per_pixel; ++k) {
                    double fx, fy;
                    sample_position(seed, pixel, k, N, fx, fy);
                    double ux = 2 * fx - 1, uy = 2 * fy - 1;
                    double d = filter_radius_kernel(s.filter, ux, uy);
                    if (d != 0) acc += d * g_dot_change(ux, uy);
                }
                acc /= per_pixel;
                if (edge_term) {  // 2 E_edge[W (c - b)], N samples a side
                    double edge = 0;
                    for (int j = 0; j < 4 * N; ++j) {
                        double jitter, unused, ux, uy;
                        sample_uniform2(seed, pixel, (uint64_t)(per_pixel + j), jitter, unused);
                        support_edge_point(j, N, jitter, ux, uy);
                        edge += filter_weight(s.filter, R, R * ux, R * uy) * g_dot_change(ux, uy);
                    }
                    acc += 2 * edge / (4 * N);
                }
                total += acc / (R * mean_weight);
            }
        per_tile[tile] = total;
    });
    double sum = 0;
    for (double t : per_tile) sum += t;
    return sum;
}

}  // namespace vf
