// The scene at arbitrary points (points.h): forward and adjoint, all points in one call.
#include "backward/points.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "backward/pixel.h"
#include "common/cancel.h"
#include "common/thread_pool.h"
#include "forward/pixel.h"
#include "scene/tiles.h"

namespace vf {
namespace {

// One tile (the 8 x 8 pixels at the origin) grown to reach every point and, beyond it,
// the kernel's radius: every point is in its region, every draw within r of one is listed.
TileBins points_bins(const PreparedScene& sc, const RenderOptions& o, const double* xy, int n) {
    double reach = 0;
    for (int i = 0; i < n; ++i)
        reach = std::max({reach, std::fabs(xy[2 * i]), std::fabs(xy[2 * i + 1]), std::fabs(xy[2 * i] - TILE),
                          std::fabs(xy[2 * i + 1] - TILE)});
    return bin_draws(sc, 1, 1, reach + 2 * o.filter_radius + 1, /*every_tile=*/true, o.threads);
}

RenderOptions points_options(const RenderOptions& o) {
    RenderOptions s = settled(o);
    s.mode = MODE_ANALYTIC;
    s.samples = 1;
    s.width = s.height = 1;
    s.has_background = false;
    return s;
}

constexpr int CHUNK = 64;  // points per task

}  // namespace

void render_points(const PreparedScene& prepared, const RenderOptions& options, const double* xy, int n, float* out) {
    const RenderOptions o = points_options(options);
    const TileBins bins = points_bins(prepared, o, xy, n);
    const SceneView sc = prepared.view();
    const TileView view = bins.view();
    const double bg[4] = {0, 0, 0, 0};
    ThreadPool::instance().parallel_for((n + CHUNK - 1) / CHUNK, o.threads, [&](int task, int) {
        for (int i = task * CHUNK; i < std::min(n, (task + 1) * CHUNK) && !cancelled(); ++i) {
            double c[4] = {0, 0, 0, 0};
            if (view.count(0) > 0) sample_forward(sc, view, 0, {xy[2 * i], xy[2 * i + 1]}, o, c);
            pixel_output(c, 1.0, bg, out + 4 * (size_t)i);
        }
    });
}

void render_points_backward(const PreparedScene& prepared, const SceneArrays& a, const RenderOptions& options,
                            const double* xy, int n, const float* colours, const float* d_colours, SceneGrads& out,
                            double* d_xy) {
    const RenderOptions o = points_options(options);
    const TileBins bins = points_bins(prepared, o, xy, n);
    const SceneView sc = prepared.view();
    const TileView view = bins.view();
    int most = view.count(0), depth = 0;
    for (int32_t dl : prepared.layer_depth) depth = std::max(depth, (int)dl);
    const int max_hits = most + 1, max_ops = max_hits * (1 + 2 * (depth + 1)) + depth + 1;
    const int tasks = (n + CHUNK - 1) / CHUNK;
    const int lanes = std::max(1, std::min(tasks, o.threads > 0 ? o.threads : ThreadPool::hardware_threads()));
    std::vector<SceneGrads> grads(lanes);
    for (SceneGrads& g : grads) g.resize_like(a);
    ThreadPool::instance().parallel_for(lanes, lanes, [&](int lane, int) {
        std::vector<Hit> hits(max_hits);
        std::vector<TapeOp> ops(max_ops);
        std::vector<Quad> g_hits(max_hits);
        SampleScratch w{{hits.data(), max_hits}, {{ops.data(), max_ops}}, {g_hits.data(), max_hits}};
        // One point's gradients alone (to read its translation off them), then added to the lane's.
        SceneGrads one;
        one.resize_like(a);
        const GradView g = one.view();
        for (int task = lane; task < tasks; task += lanes)
            for (int i = task * CHUNK; i < std::min(n, (task + 1) * CHUNK) && !cancelled(); ++i) {
                // dL/d(premultiplied colour) from dL/d(straight), as pixel_adjoints does
                const float* s = colours + 4 * (size_t)i;
                const float* ds = d_colours + 4 * (size_t)i;
                double gc[4];
                if (s[3] <= 0) {
                    gc[0] = gc[1] = gc[2] = 0;
                    gc[3] = ds[3];
                } else {
                    double sum = 0;
                    for (int k = 0; k < 3; ++k) {
                        gc[k] = ds[k] / s[3];
                        sum += ds[k] * s[k];
                    }
                    gc[3] = ds[3] - sum / s[3];
                }
                d_xy[2 * i] = d_xy[2 * i + 1] = 0;
                if (view.count(0) == 0 || (gc[0] == 0 && gc[1] == 0 && gc[2] == 0 && gc[3] == 0)) continue;
                sample_backward(sc, view, {xy[2 * i], xy[2 * i + 1]}, o, gc, w, g);
                // The point moving by t is the geometry moving by -t (points, ellipse
                // centres); a paint sees it through its affine map q = M p + m.
                double dx = 0, dy = 0;
                for (size_t k = 0; k < one.points.size(); k += 2) {
                    dx -= one.points[k];
                    dy -= one.points[k + 1];
                }
                for (size_t k = 0; k < one.ellipses.size(); k += ELLIPSE_COLS) {
                    dx -= one.ellipses[k];
                    dy -= one.ellipses[k + 1];
                }
                for (int q = 0; q < (int)sc.paints.size(); ++q) {
                    const Affine& m = sc.paints[q].to_paint;
                    double gx = one.paint_params[PAINT_FCOLS * q + 2], gy = one.paint_params[PAINT_FCOLS * q + 5];
                    dx += m.m00 * gx + m.m10 * gy;
                    dy += m.m01 * gx + m.m11 * gy;
                }
                d_xy[2 * i] = dx;
                d_xy[2 * i + 1] = dy;
                grads[lane].add(one);
                one.resize_like(a);  // (zeroed)
            }
    });
    out = grads[0];
    for (int l = 1; l < lanes; ++l) out.add(grads[l]);
}

}  // namespace vf
