// Where the backward pass adds dL/d(input): views of the gradient arrays (laid out like
// SceneArrays, in doubles so that sums over many samples keep their precision). On the
// CPU each lane adds into a SceneGrads of its own, summed in lane order at the end; on a
// GPU all threads share one set of arrays and add atomically.
#pragma once

#include <vector>

#include "common/portable.h"
#include "scene/scene.h"

namespace vf {

// One gradient entry: `+=` is a plain add on the host and an atomic one on the device.
struct GradRef {
    double* p = nullptr;
    VF_HD void operator+=(double v) const {
#ifdef __CUDA_ARCH__
        atomicAdd(p, v);
#else
        *p += v;
#endif
    }
};

struct GradPtr {
    double* p = nullptr;
    VF_HD GradRef operator[](size_t i) const { return {p + i}; }
    VF_HD GradPtr operator+(size_t k) const { return {p + k}; }
};

struct GradView {
    GradPtr points, point_widths, ellipses, draw_params, paint_params, stop_offsets, stop_colors, layer_opacity;
};

// Host gradient arrays (one lane's, or the result).
struct SceneGrads {
    std::vector<double> points, point_widths, ellipses, draw_params, paint_params, stop_offsets, stop_colors,
        layer_opacity;
    void resize_like(const SceneArrays& a) {
        points.assign(2 * a.n_points, 0);
        point_widths.assign(a.n_point_widths, 0);
        ellipses.assign(ELLIPSE_COLS * a.n_ellipses, 0);
        draw_params.assign(DRAW_FCOLS * a.n_draws, 0);
        paint_params.assign(PAINT_FCOLS * a.n_paints, 0);
        stop_offsets.assign(a.n_stops, 0);
        stop_colors.assign(4 * a.n_stops, 0);
        layer_opacity.assign(a.n_layers, 0);
    }
    void add(const SceneGrads& o) {
        auto acc = [](std::vector<double>& x, const std::vector<double>& y) {
            for (size_t i = 0; i < x.size(); ++i) x[i] += y[i];
        };
        acc(points, o.points); acc(point_widths, o.point_widths); acc(ellipses, o.ellipses); acc(draw_params, o.draw_params);
        acc(paint_params, o.paint_params); acc(stop_offsets, o.stop_offsets);
        acc(stop_colors, o.stop_colors); acc(layer_opacity, o.layer_opacity);
    }
    GradView view() {
        return {{points.data()},       {point_widths.data()}, {ellipses.data()},     {draw_params.data()},
                {paint_params.data()}, {stop_offsets.data()}, {stop_colors.data()}, {layer_opacity.data()}};
    }
};

}  // namespace vf
