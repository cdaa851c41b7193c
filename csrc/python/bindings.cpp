// Python bindings of the core's API: checks and calls. numpy buffers in and out, the
// options as one typed RenderOptions, the passes of api/passes.h run while Python can
// still take a Ctrl-C (python/interrupt.h). The hooks only the tests call are in
// test_hooks.cpp.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "api/passes.h"
#include "backward/backward.h"
#include "backward/points.h"
#include "common/phase_clock.h"
#include "common/thread_pool.h"
#include "forward/forward.h"
#include "gpu/gpu.h"
#include "python/interrupt.h"
#include "python/test_hooks.h"
#include "scene/scene.h"
#include "trace/fit.h"
#include "trace/merge.h"
#include "trace/stretches.h"
#include "trace/subpixel.h"

namespace py = pybind11;
using namespace vf;

namespace {

template <typename T>
using Array = py::array_t<T, py::array::c_style | py::array::forcecast>;

// A table of rows `cols` wide: its row count n and data. A table of two or more dimensions
// must have rows of that width; a flat one must hold whole rows.
template <typename T>
const T* rows(const Array<T>& a, int cols, int& n, const char* name) {
    if (a.size() == 0) {
        n = 0;
        return nullptr;
    }
    if ((a.ndim() >= 2 && a.shape(a.ndim() - 1) != cols) || a.size() % cols != 0) {
        std::string shape;
        for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
        throw std::invalid_argument(std::string("vecfit core: ") + name + " has the wrong shape: rows of " +
                                    std::to_string(cols) + " expected, not [" + shape + "]");
    }
    n = (int)(a.size() / cols);
    return a.data();
}

int parse_mode(const std::string& m) {
    if (m == "mc") return MODE_MC;
    if (m == "analytic") return MODE_ANALYTIC;
    throw std::invalid_argument("mode must be 'mc' or 'analytic', not '" + m + "'");
}

// The pixel filters by their FilterKind value.
const char* const FILTER_NAMES[] = {"box", "tent", "gaussian", "parabolic", "hann"};

int parse_filter(const std::string& f) {
    for (int k = 0; k < 5; ++k)
        if (f == FILTER_NAMES[k]) return k;
    throw std::invalid_argument("filter must be 'box', 'tent', 'gaussian', 'parabolic' or 'hann', not '" + f + "'");
}

// The scene's arrays, kept alive for the duration of a call.
struct SceneInput {
    Array<float> points, point_widths, ellipses, draw_params, paint_params, stop_offsets, stop_colors, layer_opacity;
    Array<int32_t> segments, subpaths, shapes, draws, paints, layer_parents;

    SceneArrays arrays() const {
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
};

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

const char* mode_name(int mode) { return mode == MODE_ANALYTIC ? "analytic" : "mc"; }

const char* filter_name(int filter) { return filter >= 0 && filter < 5 ? FILTER_NAMES[filter] : "box"; }

// vecfit._core.RenderOptions(...): the options of every pass, checked once here.
RenderOptions make_options(int width, int height, int samples, const std::string& mode, const std::string& filter,
                           double filter_radius, uint64_t seed, int threads, py::object background,
                           int interior_samples, bool brute_force, bool premultiplied, double boundary_budget) {
    if (width <= 0 || height <= 0) throw std::invalid_argument("width and height must be positive");
    if (samples <= 0) throw std::invalid_argument("samples must be positive");
    if (interior_samples < 0) throw std::invalid_argument("interior_samples must be >= 0");
    if (!(boundary_budget >= 0) || !std::isfinite(boundary_budget))
        throw std::invalid_argument("boundary_budget must be a finite number >= 0");
    RenderOptions o;
    o.width = width;
    o.height = height;
    o.samples = samples;
    o.mode = parse_mode(mode);
    o.filter = parse_filter(filter);
    o.filter_radius = filter_radius;
    o.seed = seed;
    o.threads = threads;
    o.interior_samples = interior_samples;
    o.brute_force = brute_force;
    o.premultiplied = premultiplied;
    o.boundary_budget = boundary_budget;
    if (!background.is_none()) {
        auto bg = background.cast<std::vector<double>>();
        if (bg.size() != 4) throw std::invalid_argument("background must be 4 numbers (RGBA)");
        o.has_background = true;
        for (int i = 0; i < 4; ++i) o.background[i] = bg[i];
    }
    return o;
}

void check_image(const Array<float>& image, const RenderOptions& o, py::ssize_t count, const char* what) {
    if (image.size() != count * o.width * o.height * 4)
        throw std::invalid_argument(std::string(what) + " must be " + (count > 1 ? "batch x " : "") +
                                    "height x width x 4 of the options' size");
}

// A scene prepared by a forward pass, handed to Python (render_keeping) so that the
// backward pass of the same arrays (render_grad's `prepared`) need not prepare it again.
struct KeptScene {
    std::shared_ptr<const PreparedScene> scene;
};

py::array_t<float> render_into(const py::dict& scene, const RenderOptions& o, int device, KeptScene* keep) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    py::array_t<float> image({o.height, o.width, 4});
    float* out = image.mutable_data();
    interruptible([&] {
        std::shared_ptr<const PreparedScene> prepared = prepare_timed(a);
        forward_on(*prepared, o, device, out);
        if (keep) keep->scene = prepared;
    });
    return image;
}

py::array_t<float> render(const py::dict& scene, const RenderOptions& options, int device) {
    return render_into(scene, options, device, nullptr);
}

py::tuple render_keeping(const py::dict& scene, const RenderOptions& options, int device) {
    KeptScene keep;
    py::array_t<float> image = render_into(scene, options, device, &keep);
    return py::make_tuple(image, keep);
}

// The gradients of a scene's float arrays, as numpy arrays by the names render() takes.
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

// dL/d(filter radius), Monte Carlo mode: pixels is the image as rendered and g is dL/d(it),
// each height x width x 4, the filtered premultiplied colour of each pixel with the
// background excluded. On the CPU.
double filter_radius_grad(const py::dict& scene, Array<float> pixels, Array<float> g, const RenderOptions& options) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    if (options.mode != MODE_MC) throw std::invalid_argument("the filter radius's gradient is Monte Carlo's");
    check_image(pixels, options, 1, "pixels");
    check_image(g, options, 1, "g");
    py::gil_scoped_release release;
    return filter_radius_gradient(*prepare_timed(a), options, pixels.data(), g.data());
}

py::dict render_grad(const py::dict& scene, Array<float> image, Array<float> d_image, const RenderOptions& options,
                     double boundary_density, int device, bool emulate_gpu_lists, const KeptScene* kept) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    check_image(image, options, 1, "image");
    check_image(d_image, options, 1, "its gradient");
    SceneGrads g;
    interruptible([&] {
        // (kept: the forward pass's preparation of these same arrays)
        std::shared_ptr<const PreparedScene> prepared = kept && kept->scene ? kept->scene : prepare_timed(a);
        backward_on(*prepared, a, options, image.data(), d_image.data(), boundary_density, device, emulate_gpu_lists,
                    g);
    });
    return grads_dict(g);
}

// Bytes the core holds for the scene at these options, by part: the prepared scene and the
// forward pass's tiles (benchmarks/memory.py says where a render's memory goes).
py::dict footprint(const py::dict& scene, const RenderOptions& options) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    py::gil_scoped_release release;
    std::shared_ptr<const PreparedScene> sc = prepare_timed(a);
    ForwardPlan plan = plan_forward(*sc, options);
    auto bytes = [](const auto& v) { return (double)v.capacity() * sizeof(v[0]); };
    py::gil_scoped_acquire acquire;
    py::dict r;
    r["segments"] = bytes(sc->segments);
    r["fill_items"] = bytes(sc->fill_items);
    r["stroke_items"] = bytes(sc->stroke_items);
    r["draws"] = bytes(sc->draws) + bytes(sc->paints) + bytes(sc->point_hw);
    r["tile_entries"] = bytes(plan.bins.entries) + bytes(plan.bins.start);
    r["tile_items"] = bytes(plan.bins.items) + bytes(plan.bins.crossings);
    return r;
}

// The scene at n points (pixel space, [n, 2]) in the analytical mode with kernel radius
// filter_radius: [n, 4] straight RGBA (pydiffvg's eval_positions).
RenderOptions points_options(double filter_radius, int threads) {
    return make_options(1, 1, 1, "analytic", "tent", filter_radius, 0, threads, py::none(), 0, false, false, 0.0);
}

const double* points_of(const Array<double>& positions, int& n) {
    const double* xy = rows(positions, 2, n, "positions");
    return xy;
}

py::array_t<float> render_points_py(const py::dict& scene, Array<double> positions, double filter_radius, int threads) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    RenderOptions o = points_options(filter_radius, threads);
    int n = 0;
    const double* xy = points_of(positions, n);
    py::array_t<float> out({(py::ssize_t)n, (py::ssize_t)4});
    float* px = out.mutable_data();
    interruptible([&] { render_points(*prepare_timed(a), o, xy, n, px); });
    return out;
}

// render_points' adjoint: (dL/d(scene arrays) as render_grad's dict, dL/d(positions) [n, 2]).
py::tuple render_points_grad_py(const py::dict& scene, Array<double> positions, Array<float> colours,
                                Array<float> d_colours, double filter_radius, int threads) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    RenderOptions o = points_options(filter_radius, threads);
    int n = 0;
    const double* xy = points_of(positions, n);
    if (colours.size() != (py::ssize_t)n * 4 || d_colours.size() != colours.size())
        throw std::invalid_argument("colours and their gradient must be n x 4");
    SceneGrads g;
    py::array_t<double> d_xy({(py::ssize_t)n, (py::ssize_t)2});
    double* dp = d_xy.mutable_data();
    interruptible([&] {
        render_points_backward(*prepare_timed(a), a, o, xy, n, colours.data(), d_colours.data(), g, dp);
    });
    return py::make_tuple(grads_dict(g), d_xy);
}

std::vector<SceneInput> batch_inputs(const py::list& scenes, const std::vector<uint64_t>& seeds) {
    if (seeds.size() != scenes.size()) throw std::invalid_argument("a batch needs one seed per scene");
    std::vector<SceneInput> inputs;
    inputs.reserve(scenes.size());
    for (const py::handle& s : scenes) inputs.push_back(scene_input(s.cast<py::dict>()));
    return inputs;
}

std::vector<SceneArrays> batch_arrays(const std::vector<SceneInput>& inputs) {
    std::vector<SceneArrays> arrays;
    arrays.reserve(inputs.size());
    for (const SceneInput& in : inputs) arrays.push_back(in.arrays());
    return arrays;
}

// A batch of scenes at one size and options (each its own seed), parallel over the
// scenes on options.threads threads (api/passes.h forward_batch).
py::array_t<float> render_batch(const py::list& scenes, const RenderOptions& options,
                                const std::vector<uint64_t>& seeds) {
    std::vector<SceneInput> inputs = batch_inputs(scenes, seeds);
    std::vector<SceneArrays> arrays = batch_arrays(inputs);
    py::array_t<float> images({(py::ssize_t)inputs.size(), (py::ssize_t)options.height, (py::ssize_t)options.width,
                               (py::ssize_t)4});
    float* out = images.mutable_data();
    interruptible([&] { forward_batch(arrays, options, seeds, out); });
    return images;
}

// Gradients of a batch rendered by render_batch: one dict per scene, as render_grad's.
py::list render_grad_batch(const py::list& scenes, Array<float> images, Array<float> d_images,
                           const RenderOptions& options, const std::vector<uint64_t>& seeds,
                           double boundary_density) {
    std::vector<SceneInput> inputs = batch_inputs(scenes, seeds);
    std::vector<SceneArrays> arrays = batch_arrays(inputs);
    check_image(images, options, (py::ssize_t)inputs.size(), "images");
    check_image(d_images, options, (py::ssize_t)inputs.size(), "their gradients");
    std::vector<SceneGrads> grads;
    interruptible([&] { backward_batch(arrays, options, seeds, images.data(), d_images.data(), boundary_density, grads); });
    py::list out;
    for (const SceneGrads& g : grads) out.append(grads_dict(g));
    return out;
}

// The array layout of scene.h for Python (vecfit/renderer/layout.py reads it, so that
// Python keeps no copy): the enums of the integer tables, by the names Python uses, and
// the row width of every table a scene dict holds (the keys SceneInput reads).
py::dict layout() {
    auto named = [](std::initializer_list<std::pair<const char*, int>> items) {
        py::dict d;
        for (const auto& [name, value] : items) d[name] = value;
        return d;
    };
    py::dict l;
    l["shape_kinds"] = named({{"path", SHAPE_PATH}, {"ellipse", SHAPE_ELLIPSE}});
    l["draw_kinds"] = named({{"fill", DRAW_FILL}, {"stroke", DRAW_STROKE}});
    l["fill_rules"] = named({{"nonzero", NONZERO}, {"evenodd", EVENODD}});
    l["caps"] = named({{"butt", CAP_BUTT}, {"round", CAP_ROUND}, {"square", CAP_SQUARE}});
    l["joins"] = named({{"miter", JOIN_MITER}, {"round", JOIN_ROUND}, {"bevel", JOIN_BEVEL}});
    l["paint_kinds"] = named({{"solid", PAINT_SOLID}, {"linear", PAINT_LINEAR}, {"radial", PAINT_RADIAL}});
    l["columns"] = named({{"points", POINT_COLS},
                          {"point_widths", 1},
                          {"segments", SEGMENT_COLS},
                          {"subpaths", SUBPATH_COLS},
                          {"shapes", SHAPE_COLS},
                          {"ellipses", ELLIPSE_COLS},
                          {"draws", DRAW_COLS},
                          {"draw_params", DRAW_FCOLS},
                          {"paints", PAINT_COLS},
                          {"paint_params", PAINT_FCOLS},
                          {"stop_offsets", 1},
                          {"stop_colors", STOP_COLOR_COLS},
                          {"layer_parents", 1},
                          {"layer_opacity", 1}});
    return l;
}

// The tracer's Bézier fit of outline stretches (trace/fit.h): (segments [S, 4, 2], stretch of each).
py::tuple fit_stretches_py(const Array<double>& points, const Array<double>& tangents, const Array<double>& heading,
                           const Array<double>& arc, const Array<int64_t>& first, const Array<int64_t>& lengths,
                           const Array<double>& t1, const Array<double>& t2, double tolerance, double max_turn,
                           double newton_range, int newton_steps) {
    FitInput in;
    const int64_t m = (int64_t)heading.size(), k = (int64_t)first.size();
    if (points.size() != 2 * m || tangents.size() != 2 * m || arc.size() != m || lengths.size() != k ||
        t1.size() != 2 * k || t2.size() != 2 * k)
        throw std::invalid_argument("fit_stretches: expected points and tangents [M, 2], heading and arc [M], "
                                    "first and lengths [K], t1 and t2 [K, 2]");
    for (int64_t i = 0; i < k; ++i)
        if (lengths.data()[i] < 1 || first.data()[i] < 0 || first.data()[i] + lengths.data()[i] > m)
            throw std::invalid_argument("fit_stretches: a stretch reaches outside the points");
    if (!(tolerance > 0)) throw std::invalid_argument("fit_stretches: tolerance must be positive");
    in.points = points.data();
    in.tangents = tangents.data();
    in.heading = heading.data();
    in.arc = arc.data();
    in.stretches = k;
    in.first = first.data();
    in.lengths = lengths.data();
    in.t1 = t1.data();
    in.t2 = t2.data();
    in.tolerance = tolerance;
    in.max_turn = max_turn;
    in.newton_range = newton_range;
    in.newton_steps = newton_steps;
    FitResult r;
    {
        py::gil_scoped_release release;
        r = fit_stretches(in);
    }
    const py::ssize_t s = (py::ssize_t)r.owner.size();
    py::array_t<double> ctrl({s, (py::ssize_t)4, (py::ssize_t)2});
    py::array_t<int64_t> owner(s);
    std::copy(r.ctrl.begin(), r.ctrl.end(), ctrl.mutable_data());
    std::copy(r.owner.begin(), r.owner.end(), owner.mutable_data());
    return py::make_tuple(ctrl, owner);
}

// The tracer's sub-pixel placement of outline edges (trace/subpixel.h): the points moved.
py::array_t<double> refine_outlines_py(const Array<double>& points, const Array<int64_t>& lengths,
                                       const Array<int64_t>& region, const Array<bool>& hole,
                                       const Array<int32_t>& labels, const Array<int64_t>& rank,
                                       const Array<double>& colors, const Array<float>& rgb,
                                       const Array<float>& alpha, double min_contrast, double max_shift, int reach) {
    SubpixelInput in;
    in.points = (int64_t)points.size() / 2;
    in.outlines = (int64_t)lengths.size();
    in.regions = (int64_t)rank.size();
    if (labels.ndim() != 2) throw std::invalid_argument("refine_outlines: labels must be [H, W]");
    in.height = labels.shape(0);
    in.width = labels.shape(1);
    const int64_t pixels = in.width * in.height;
    int64_t total = 0;
    for (int64_t k = 0; k < in.outlines; ++k) total += lengths.data()[k] >= 0 ? lengths.data()[k] : -1;
    if (points.size() % 2 != 0 || total != in.points || region.size() != in.outlines || hole.size() != in.outlines ||
        colors.size() != 3 * in.regions || rgb.size() != 3 * pixels || alpha.size() != pixels || reach < 0)
        throw std::invalid_argument("refine_outlines: expected points [M, 2] in outlines of the given lengths, "
                                    "region and hole per outline, labels and alpha [H, W], rgb [H, W, 3], rank "
                                    "and colors [R] and [R, 3], reach >= 0");
    for (int64_t k = 0; k < in.outlines; ++k)
        if (region.data()[k] < 0 || region.data()[k] >= in.regions)
            throw std::invalid_argument("refine_outlines: an outline's region is out of range");
    for (int64_t i = 0; i < pixels; ++i)
        if (labels.data()[i] >= in.regions) throw std::invalid_argument("refine_outlines: a label is out of range");
    in.xy = points.data();
    in.lengths = lengths.data();
    in.region = region.data();
    in.hole = reinterpret_cast<const uint8_t*>(hole.data());
    in.labels = labels.data();
    in.rank = rank.data();
    in.colors = colors.data();
    in.rgb = rgb.data();
    in.alpha = alpha.data();
    in.min_contrast = min_contrast;
    in.max_shift = max_shift;
    in.reach = reach;
    std::vector<double> moved;
    {
        py::gil_scoped_release release;
        moved = refine_outlines(in);
    }
    py::array_t<double> out({(py::ssize_t)in.points, (py::ssize_t)2});
    std::copy(moved.begin(), moved.end(), out.mutable_data());
    return out;
}

// Stretches laid end to end (trace/stretches.h): their first points and lengths, checked.
void check_stretches(int64_t points, const Array<int64_t>& first, const Array<int64_t>& lengths, const char* name) {
    if (first.size() != lengths.size())
        throw std::invalid_argument(std::string(name) + ": expected first and lengths of equal size");
    for (py::ssize_t k = 0; k < first.size(); ++k)
        if (lengths.data()[k] < 1 || first.data()[k] < 0 || first.data()[k] + lengths.data()[k] > points)
            throw std::invalid_argument(std::string(name) + ": a stretch reaches outside the points");
}

py::array_t<double> points_array(const std::vector<double>& v) {
    py::array_t<double> out({(py::ssize_t)(v.size() / 2), (py::ssize_t)2});
    std::copy(v.begin(), v.end(), out.mutable_data());
    return out;
}

py::array_t<double> smooth_stretches_py(const Array<double>& points, const Array<int64_t>& first,
                                        const Array<int64_t>& lengths, const Array<double>& kernel) {
    check_stretches((int64_t)points.size() / 2, first, lengths, "smooth_stretches");
    if (kernel.size() % 2 != 1) throw std::invalid_argument("smooth_stretches: the kernel must have 2r + 1 weights");
    std::vector<double> out;
    {
        py::gil_scoped_release release;
        out = smooth_stretches(points.data(), (int64_t)first.size(), first.data(), lengths.data(), kernel.data(),
                               (int64_t)kernel.size());
    }
    return points_array(out);
}

py::array_t<double> stretch_tangents_py(const Array<double>& points, const Array<int64_t>& first,
                                        const Array<int64_t>& lengths, int64_t window) {
    check_stretches((int64_t)points.size() / 2, first, lengths, "stretch_tangents");
    if (window < 0) throw std::invalid_argument("stretch_tangents: window must not be negative");
    std::vector<double> out;
    {
        py::gil_scoped_release release;
        out = stretch_tangents(points.data(), (int64_t)first.size(), first.data(), lengths.data(), window);
    }
    return points_array(out);
}

py::array_t<double> smooth_loops_py(const Array<double>& points, const Array<int64_t>& first,
                                    const Array<int64_t>& lengths, const Array<int64_t>& reach,
                                    const Array<double>& kernels, const Array<int64_t>& kernel_at) {
    check_stretches((int64_t)points.size() / 2, first, lengths, "smooth_loops");
    if (reach.size() != first.size()) throw std::invalid_argument("smooth_loops: expected a reach per loop");
    for (py::ssize_t k = 0; k < reach.size(); ++k) {
        const int64_t r = reach.data()[k];
        if (r > 0 && (r >= kernel_at.size() || kernel_at.data()[r] < 0 ||
                      kernel_at.data()[r] + 2 * r + 1 > (int64_t)kernels.size()))
            throw std::invalid_argument("smooth_loops: a loop's reach has no kernel");
    }
    std::vector<double> out;
    {
        py::gil_scoped_release release;
        out = smooth_loops(points.data(), (int64_t)first.size(), first.data(), lengths.data(), reach.data(),
                           kernels.data(), kernel_at.data());
    }
    return points_array(out);
}

py::array_t<double> loop_window_min_py(const Array<double>& values, const Array<int64_t>& first,
                                       const Array<int64_t>& lengths, int64_t window) {
    check_stretches((int64_t)values.size(), first, lengths, "loop_window_min");
    if (window < 0) throw std::invalid_argument("loop_window_min: window must not be negative");
    std::vector<double> out;
    {
        py::gil_scoped_release release;
        out = loop_window_min(values.data(), (int64_t)first.size(), first.data(), lengths.data(), window);
    }
    py::array_t<double> a((py::ssize_t)out.size());
    std::copy(out.begin(), out.end(), a.mutable_data());
    return a;
}

py::array_t<double> group_medians_py(const Array<double>& values, const Array<int64_t>& group,
                                     const Array<bool>& valid, const Array<bool>& wanted) {
    const int64_t n = (int64_t)values.size(), groups = (int64_t)wanted.size();
    if (group.size() != n || valid.size() != n)
        throw std::invalid_argument("group_medians: expected values, group and valid of equal size");
    for (int64_t i = 0; i < n; ++i)
        if (group.data()[i] < 0 || group.data()[i] >= groups)
            throw std::invalid_argument("group_medians: a group is out of range");
    std::vector<double> out = group_medians(values.data(), group.data(), reinterpret_cast<const uint8_t*>(valid.data()),
                                            n, reinterpret_cast<const uint8_t*>(wanted.data()), groups);
    py::array_t<double> a((py::ssize_t)out.size());
    std::copy(out.begin(), out.end(), a.mutable_data());
    return a;
}

// The tracer's greedy region merger (trace/merge.h): (parent, alive) of each region.
py::tuple merge_regions_py(const Array<double>& area, const Array<double>& sums, const Array<bool>& thin,
                           const Array<int64_t>& pairs, double min_area, int64_t budget) {
    MergeInput in;
    in.count = (int64_t)area.size();
    if (sums.size() != 3 * in.count || thin.size() != in.count || pairs.size() % 2 != 0)
        throw std::invalid_argument("merge_regions: expected area [n], sums [n, 3], thin [n] and pairs [m, 2]");
    in.area = area.data();
    in.sums = sums.data();
    in.thin = reinterpret_cast<const uint8_t*>(thin.data());
    in.edges = (int64_t)pairs.size() / 2;
    in.pairs = pairs.data();
    for (int64_t k = 0; k < 2 * in.edges; ++k)
        if (in.pairs[k] < 0 || in.pairs[k] >= in.count)
            throw std::invalid_argument("merge_regions: pairs name a region out of range");
    in.min_area = min_area;
    in.budget = budget;
    MergeResult r;
    {
        py::gil_scoped_release release;
        r = merge_regions(in);
    }
    py::array_t<int64_t> parent(in.count);
    py::array_t<bool> alive(in.count);
    std::copy(r.parent.begin(), r.parent.end(), parent.mutable_data());
    std::copy(r.alive.begin(), r.alive.end(), reinterpret_cast<uint8_t*>(alive.mutable_data()));
    return py::make_tuple(parent, alive);
}

}  // namespace

PYBIND11_MODULE(_core, m) {
    m.doc() = "vecfit's compiled core: geometry and rendering on flat arrays";
    py::class_<RenderOptions>(m, "RenderOptions",
                              "The options of every pass: size, N x N samples, mode ('mc' or 'analytic'), pixel "
                              "filter and radius, seed, threads (0: all), background (RGBA or None), the interior "
                              "samples the Monte Carlo backward pass revisits (0: all), brute_force (every draw at "
                              "every sample: a check of the tiles), premultiplied (the image premultiplied, not "
                              "straight), boundary_budget (the Monte Carlo backward's boundary samples per pixel of the "
                              "image at most, allotted by the pixel adjoints; 0: no bound)")
        .def(py::init(&make_options), py::kw_only(), py::arg("width"), py::arg("height"), py::arg("samples") = 2,
             py::arg("mode") = "mc", py::arg("filter") = "box", py::arg("filter_radius") = 0.5, py::arg("seed") = 0,
             py::arg("threads") = 0, py::arg("background") = py::none(), py::arg("interior_samples") = 0,
             py::arg("brute_force") = false, py::arg("premultiplied") = false, py::arg("boundary_budget") = 0.0)
        .def_readonly("width", &RenderOptions::width)
        .def_readonly("height", &RenderOptions::height)
        .def_readonly("samples", &RenderOptions::samples)
        .def_property_readonly("mode", [](const RenderOptions& o) { return mode_name(o.mode); })
        .def_property_readonly("filter", [](const RenderOptions& o) { return filter_name(o.filter); })
        .def_readonly("filter_radius", &RenderOptions::filter_radius)
        .def_readonly("seed", &RenderOptions::seed)
        .def_readonly("threads", &RenderOptions::threads)
        .def_readonly("interior_samples", &RenderOptions::interior_samples)
        .def_readonly("brute_force", &RenderOptions::brute_force)
        .def_readonly("premultiplied", &RenderOptions::premultiplied)
        .def_readonly("boundary_budget", &RenderOptions::boundary_budget)
        .def_property_readonly("background", [](const RenderOptions& o) -> py::object {
            if (!o.has_background) return py::none();
            return py::make_tuple(o.background[0], o.background[1], o.background[2], o.background[3]);
        });
    m.def("render", &render, "Render the scene arrays (a dict, see vecfit/renderer/pack.py) into [H, W, 4] straight RGBA",
          py::arg("scene"), py::arg("options"), py::arg("device") = -1);
    py::class_<KeptScene>(m, "KeptScene", "A scene prepared by render_keeping, for render_grad's `prepared`");
    m.def("render_keeping", &render_keeping,
          "render, returning (image, the prepared scene) for render_grad of the same arrays",
          py::arg("scene"), py::arg("options"), py::arg("device") = -1);
    m.def("render_grad", &render_grad,
          "Gradients of the scene arrays given the forward image and dL/d(image)",
          py::arg("scene"), py::arg("image"), py::arg("d_image"), py::arg("options"), py::arg("boundary_density"),
          py::arg("device") = -1, py::arg("emulate_gpu_lists") = false, py::arg("prepared") = nullptr);
    m.def("render_batch", &render_batch,
          "Render a list of scene dicts at one size into [B, H, W, 4] straight RGBA, in parallel over the scenes",
          py::arg("scenes"), py::arg("options"), py::arg("seeds"));
    m.def("render_grad_batch", &render_grad_batch,
          "Gradients of a batch rendered by render_batch: a list of dicts, one per scene, as render_grad's",
          py::arg("scenes"), py::arg("images"), py::arg("d_images"), py::arg("options"), py::arg("seeds"),
          py::arg("boundary_density"));
    m.def("render_points", &render_points_py,
          "The scene at points [n, 2] (pixel space), analytical mode with kernel radius filter_radius: [n, 4] "
          "straight RGBA", py::arg("scene"), py::arg("positions"), py::arg("filter_radius"), py::arg("threads"));
    m.def("render_points_grad", &render_points_grad_py,
          "render_points' gradients: (dict of the scene arrays' gradients, dL/d(positions) [n, 2])",
          py::arg("scene"), py::arg("positions"), py::arg("colours"), py::arg("d_colours"),
          py::arg("filter_radius"), py::arg("threads"));
    m.def("filter_radius_grad", &filter_radius_grad,
          "dL/d(filter radius) in Monte Carlo mode, given the premultiplied image (background excluded) and "
          "dL/d(it)", py::arg("scene"), py::arg("pixels"), py::arg("g"), py::arg("options"));
    m.def("footprint", &footprint, "Bytes the core holds for a scene at these options, by part",
          py::arg("scene"), py::arg("options"));
    m.def("layout", &layout,
          "The scene arrays' layout: enums (shape_kinds, draw_kinds, fill_rules, caps, joins, paint_kinds) "
          "and each table's row width (columns)");
    m.def("backward_fallbacks", &backward_fallbacks,
          "Backward passes redone on the CPU so far because a sample needed longer lists than a GPU thread has");
    m.def("phase_seconds", [] {
        py::dict out;
        for (int p = 0; p < PHASE_COUNT; ++p)
            out[phase_name(p)] = phase_nanoseconds()[p].exchange(0) * 1e-9;
        return out;
    }, "Seconds spent in each of the core's phases since the last call (and resets them)");
    m.def("fit_stretches", &fit_stretches_py,
          "The tracer's Bézier fit (vecfit/initial/tracer/bezier.py): (segments [S, 4, 2], stretch of each)",
          py::arg("points"), py::arg("tangents"), py::arg("heading"), py::arg("arc"), py::arg("first"),
          py::arg("lengths"), py::arg("t1"), py::arg("t2"), py::arg("tolerance"), py::arg("max_turn"),
          py::arg("newton_range"), py::arg("newton_steps"));
    m.def("refine_outlines", &refine_outlines_py,
          "The tracer's sub-pixel placement of outline edges (vecfit/initial/tracer/subpixel.py): the points moved",
          py::arg("points"), py::arg("lengths"), py::arg("region"), py::arg("hole"), py::arg("labels"),
          py::arg("rank"), py::arg("colors"), py::arg("rgb"), py::arg("alpha"), py::arg("min_contrast"),
          py::arg("max_shift"), py::arg("reach"));
    m.def("smooth_stretches", &smooth_stretches_py,
          "The tracer's stretches smoothed with a kernel, extended past their ends by point reflection, ends held",
          py::arg("points"), py::arg("first"), py::arg("lengths"), py::arg("kernel"));
    m.def("stretch_tangents", &stretch_tangents_py,
          "Unit forward tangent at each point of the tracer's stretches, from the points `window` away",
          py::arg("points"), py::arg("first"), py::arg("lengths"), py::arg("window"));
    m.def("smooth_loops", &smooth_loops_py,
          "The tracer's closed loops each smoothed with the kernel of its reach, wrapping round",
          py::arg("points"), py::arg("first"), py::arg("lengths"), py::arg("reach"), py::arg("kernels"),
          py::arg("kernel_at"));
    m.def("loop_window_min", &loop_window_min_py,
          "For each point of the loops, the least value within `window` places either side along its loop",
          py::arg("values"), py::arg("first"), py::arg("lengths"), py::arg("window"));
    m.def("group_medians", &group_medians_py,
          "np.median of the valid values of each wanted group, for groups with a valid value",
          py::arg("values"), py::arg("group"), py::arg("valid"), py::arg("wanted"));
    m.def("merge_regions", &merge_regions_py,
          "The tracer's greedy region merging (vecfit/initial/tracer/regions.py): (parent, alive) of each region",
          py::arg("area"), py::arg("sums"), py::arg("thin"), py::arg("pairs"), py::arg("min_area"), py::arg("budget"));
    m.def("hardware_threads", &ThreadPool::hardware_threads);
    m.def("has_cuda", &gpu::compiled, "Whether this build has the CUDA kernels");
    m.def("cuda_device_count", &gpu::device_count, "CUDA devices usable now (0 without a CUDA build)");
    m.def("build_info", [] {
        py::dict info;
        info["compiler"] = std::string(
#if defined(__clang__)
            "clang " __clang_version__
#elif defined(__GNUC__)
            "gcc " __VERSION__
#else
            "unknown"
#endif
        );
        info["cuda"] = gpu::build_info();
#ifdef VECFIT_WITH_CUDA
        info["cuda_archs"] = std::string(VECFIT_CUDA_ARCHS);
#else
        info["cuda_archs"] = std::string();
#endif
        info["hardware_threads"] = ThreadPool::hardware_threads();
        return info;
    });

    register_test_hooks(m);  // python/test_hooks.cpp: what only the tests call
}
