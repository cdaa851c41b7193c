// The scene dict (vecfit/renderer/pack.py) as the core's SceneArrays, each table checked
// against its row width; and gradients back by the same names.
#include "python/scene_arrays.h"

#include <stdexcept>
#include <vector>

namespace py = pybind11;

namespace vf::python {

SceneArrays SceneInput::arrays() const {
    SceneArrays a;
    a.points = rows(points, POINT_COLS, a.n_points, "points");
    a.point_widths = rows(point_widths, 1, a.n_point_widths, "point_widths");
    a.segments = rows(segments, SEGMENT_COLS, a.n_segments, "segments");
    a.subpaths = rows(subpaths, SUBPATH_COLS, a.n_subpaths, "subpaths");
    a.shapes = rows(shapes, SHAPE_COLS, a.n_shapes, "shapes");
    a.ellipses = rows(ellipses, ELLIPSE_COLS, a.n_ellipses, "ellipses");
    a.draws = rows(draws, DRAW_COLS, a.n_draws, "draws");
    int n;
    a.draw_params = rows(draw_params, DRAW_FCOLS, n, "draw_params");
    if (n != a.n_draws) throw std::invalid_argument("vecfit core: draw_params does not match draws");
    a.paints = rows(paints, PAINT_COLS, a.n_paints, "paints");
    a.paint_params = rows(paint_params, PAINT_FCOLS, n, "paint_params");
    if (n != a.n_paints) throw std::invalid_argument("vecfit core: paint_params does not match paints");
    a.stop_offsets = rows(stop_offsets, 1, a.n_stops, "stop_offsets");
    a.stop_colors = rows(stop_colors, STOP_COLOR_COLS, n, "stop_colors");
    if (n != a.n_stops) throw std::invalid_argument("vecfit core: stop_colors does not match stop_offsets");
    a.layer_parents = rows(layer_parents, 1, a.n_layers, "layer_parents");
    a.layer_opacity = rows(layer_opacity, 1, n, "layer_opacity");
    if (n != a.n_layers) throw std::invalid_argument("vecfit core: layer_opacity does not match layer_parents");
    return a;
}

SceneInput scene_input(const py::dict& s) {
    SceneInput in;
    in.points = s["points"].cast<Array<float>>();
    // optional: per-point stroke widths (absent or empty when no draw has them)
    in.point_widths = s.contains("point_widths") ? s["point_widths"].cast<Array<float>>() : Array<float>(0);
    in.segments = s["segments"].cast<Array<int32_t>>();
    in.subpaths = s["subpaths"].cast<Array<int32_t>>();
    in.shapes = s["shapes"].cast<Array<int32_t>>();
    in.ellipses = s["ellipses"].cast<Array<float>>();
    in.draws = s["draws"].cast<Array<int32_t>>();
    in.draw_params = s["draw_params"].cast<Array<float>>();
    in.paints = s["paints"].cast<Array<int32_t>>();
    in.paint_params = s["paint_params"].cast<Array<float>>();
    in.stop_offsets = s["stop_offsets"].cast<Array<float>>();
    in.stop_colors = s["stop_colors"].cast<Array<float>>();
    in.layer_parents = s["layer_parents"].cast<Array<int32_t>>();
    in.layer_opacity = s["layer_opacity"].cast<Array<float>>();
    return in;
}

py::dict grads_dict(const SceneGrads& g) {
    auto out = [](const std::vector<double>& v, py::ssize_t cols) {
        py::array_t<float> arr({(py::ssize_t)(cols > 0 ? v.size() / cols : v.size()), cols});
        float* p = arr.mutable_data();
        for (size_t i = 0; i < v.size(); ++i) p[i] = (float)v[i];
        return arr;
    };
    py::dict r;
    r["points"] = out(g.points, POINT_COLS);
    r["point_widths"] = out(g.point_widths, 1);
    r["ellipses"] = out(g.ellipses, ELLIPSE_COLS);
    r["draw_params"] = out(g.draw_params, DRAW_FCOLS);
    r["paint_params"] = out(g.paint_params, PAINT_FCOLS);
    r["stop_offsets"] = out(g.stop_offsets, 1);
    r["stop_colors"] = out(g.stop_colors, STOP_COLOR_COLS);
    r["layer_opacity"] = out(g.layer_opacity, 1);
    return r;
}

}  // namespace vf::python
