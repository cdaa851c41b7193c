// Forward pass on the CPU: the tiles are shared out between threads; each pixel is
// shaded by pixel_forward (forward/pixel.h), which a CUDA build runs on the GPU as well.
#include <algorithm>
#include <vector>

#include "common/cancel.h"
#include "common/phase_clock.h"
#include "common/thread_pool.h"
#include "forward/forward.h"
#include "forward/pixel.h"

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
    plan.bins = bin_draws(sc, o.width, o.height, margin + 1e-6, o.brute_force);
    premultiplied_background(o, plan.background);
    return plan;
}

void render_forward(const PreparedScene& prepared, const RenderOptions& o, float* out) {
    ForwardPlan plan = plan_forward(prepared, o);
    const SceneView sc = prepared.view();
    const TileView bins = plan.bins.view();
    const int W = o.width, H = o.height;
    PhaseTimer timer(PHASE_FORWARD);
    ThreadPool::instance().parallel_for(bins.nx * bins.ny, o.threads, [&](int tile, int) {
        int tx = tile % bins.nx, ty = tile / bins.nx;
        for (int y = ty * TILE; y < std::min(H, (ty + 1) * TILE) && !cancelled(); ++y)
            for (int x = tx * TILE; x < std::min(W, (tx + 1) * TILE); ++x)
                pixel_forward(sc, bins, plan.options, plan.background, x, y, out + 4 * ((size_t)y * W + x));
    });
}

double filter_radius_gradient(const PreparedScene& prepared, const RenderOptions& o, const float* g) {
    ForwardPlan plan = plan_forward(prepared, o);
    const RenderOptions& s = plan.options;
    if (s.mode != MODE_MC || (s.filter != FILTER_TENT && s.filter != FILTER_PARABOLIC && s.filter != FILTER_HANN))
        return 0.0;
    const SceneView sc = prepared.view();
    const TileView bins = plan.bins.view();
    const int W = s.width, H = s.height, N = s.samples;
    const double R = s.filter_radius;
    std::vector<double> per_tile(bins.nx * bins.ny, 0.0);  // summed in order: independent of threads
    ThreadPool::instance().parallel_for(bins.nx * bins.ny, s.threads, [&](int tile, int) {
        int tx = tile % bins.nx, ty = tile / bins.nx;
        double total = 0;
        for (int y = ty * TILE; y < std::min(H, (ty + 1) * TILE); ++y)
            for (int x = tx * TILE; x < std::min(W, (tx + 1) * TILE); ++x) {
                const float* gp = g + 4 * ((size_t)y * W + x);
                if (bins.count(tile) == 0 || (gp[0] == 0 && gp[1] == 0 && gp[2] == 0 && gp[3] == 0)) continue;
                uint64_t pixel = (uint64_t)y * W + x;
                double acc = 0, wsum = 0;
                for (int k = 0; k < N * N; ++k) {  // the samples of pixel_forward, in its order
                    double fx, fy;
                    sample_position(s.seed, pixel, k, N, fx, fy);
                    double ux = 2 * fx - 1, uy = 2 * fy - 1;
                    double w = filter_weight(s.filter, R, R * ux, R * uy);
                    if (w <= 0) continue;
                    wsum += w;
                    double c[4];
                    sample_forward(sc, bins, tile, {x + 0.5 + R * ux, y + 0.5 + R * uy}, s, c);
                    acc += filter_radius_kernel(s.filter, ux, uy) *
                           (gp[0] * c[0] + gp[1] * c[1] + gp[2] * c[2] + gp[3] * c[3]);
                }
                if (wsum > 0) total += acc / (R * wsum);
            }
        per_tile[tile] = total;
    });
    double sum = 0;
    for (double t : per_tile) sum += t;
    return sum;
}

}  // namespace vf
