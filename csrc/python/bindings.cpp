// Python bindings of the core's API: numpy buffers in and out, the GIL released while
// the core works. The hooks only the tests call are in test_hooks.cpp.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <exception>
#include <future>
#include <memory>
#include <vector>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>

#include "backward/backward.h"
#include "backward/points.h"
#include "common/cancel.h"
#include "common/phase_clock.h"
#include "common/thread_pool.h"
#include "forward/forward.h"
#include "gpu/gpu.h"
#include "python/test_hooks.h"
#include "scene/scene.h"

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

int parse_filter(const std::string& f) {
    if (f == "box") return 0;
    if (f == "tent") return 1;
    if (f == "gaussian") return 2;
    if (f == "parabolic") return 3;
    if (f == "hann") return 4;
    throw std::invalid_argument("filter must be 'box', 'tent', 'gaussian', 'parabolic' or 'hann', not '" + f + "'");
}

// The scene's arrays, kept alive for the duration of a call.
struct SceneInput {
    Array<float> points, point_widths, ellipses, draw_params, brush_params, stop_offsets, stop_colors, layer_opacity;
    Array<int32_t> segments, subpaths, shapes, draws, brushes, layer_parents;

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
        a.brushes = rows(brushes, BRUSH_COLS, a.n_brushes, "brushes");
        a.brush_params = rows(brush_params, BRUSH_FCOLS, n, "brush_params");
        if (n != a.n_brushes) throw std::invalid_argument("vecfit core: brush_params does not match brushes");
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
    in.brushes = s["brushes"].cast<Array<int32_t>>();
    in.brush_params = s["brush_params"].cast<Array<float>>();
    in.stop_offsets = s["stop_offsets"].cast<Array<float>>();
    in.stop_colors = s["stop_colors"].cast<Array<float>>();
    in.layer_parents = s["layer_parents"].cast<Array<int32_t>>();
    in.layer_opacity = s["layer_opacity"].cast<Array<float>>();
    return in;
}

RenderOptions render_options(int width, int height, int samples, const std::string& mode, const std::string& filter,
                             double filter_radius, uint64_t seed, int threads, py::object background) {
    if (width <= 0 || height <= 0) throw std::invalid_argument("width and height must be positive");
    if (samples <= 0) throw std::invalid_argument("samples must be positive");
    RenderOptions o;
    o.width = width;
    o.height = height;
    o.samples = samples;
    o.mode = parse_mode(mode);
    o.filter = parse_filter(filter);
    o.filter_radius = filter_radius;
    o.seed = seed;
    o.threads = threads;
    if (!background.is_none()) {
        auto bg = background.cast<std::vector<double>>();
        if (bg.size() != 4) throw std::invalid_argument("background must be 4 numbers (RGBA)");
        o.has_background = true;
        for (int i = 0; i < 4; ++i) o.background[i] = bg[i];
    }
    return o;
}

// Runs the core's work on another thread and, every 50 ms, lets Python run its signal
// handlers: a Ctrl-C cancels the work (the thread pool skips the tasks not started, see
// common/cancel.h) and raises KeyboardInterrupt here, instead of waiting, deaf, for a
// render that may take minutes. Called with the GIL held; releases it while waiting.
template <class Work>
void interruptible(Work&& work) {
    std::future<void> done = std::async(std::launch::async, std::forward<Work>(work));
    py::gil_scoped_release release;
    while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) {
            cancel_requested().store(true);
            done.wait();
            cancel_requested().store(false);
            throw py::error_already_set();
        }
    }
    done.get();  // the core's exceptions, rethrown here
}

PreparedScene timed_prepare(const SceneArrays& a) {
    PhaseTimer timer(PHASE_PREPARE);
    return prepare_scene(a);
}

// A scene prepared by a forward pass, handed to Python (render_keeping) so that the
// backward pass of the same arrays (render_grad's `prepared`) need not prepare it again.
struct KeptScene {
    std::shared_ptr<const PreparedScene> scene;
};

py::array_t<float> render_into(const py::dict& scene, int width, int height, int samples, const std::string& mode,
                               const std::string& filter, double filter_radius, uint64_t seed, int threads,
                               py::object background, bool brute_force, int device, KeptScene* keep) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    RenderOptions o = render_options(width, height, samples, mode, filter, filter_radius, seed, threads, background);
    o.brute_force = brute_force;
    py::array_t<float> image({height, width, 4});
    float* out = image.mutable_data();
    interruptible([&] {
        auto prepared = std::make_shared<const PreparedScene>(timed_prepare(a));
        if (device >= 0) gpu::render_forward(*prepared, o, device, out);
        else render_forward(*prepared, o, out);
        if (keep) keep->scene = prepared;
    });
    return image;
}

py::array_t<float> render(const py::dict& scene, int width, int height, int samples, const std::string& mode,
                          const std::string& filter, double filter_radius, uint64_t seed, int threads,
                          py::object background, bool brute_force, int device) {
    return render_into(scene, width, height, samples, mode, filter, filter_radius, seed, threads, background,
                       brute_force, device, nullptr);
}

py::tuple render_keeping(const py::dict& scene, int width, int height, int samples, const std::string& mode,
                         const std::string& filter, double filter_radius, uint64_t seed, int threads,
                         py::object background, int device) {
    KeptScene keep;
    py::array_t<float> image = render_into(scene, width, height, samples, mode, filter, filter_radius, seed,
                                           threads, background, false, device, &keep);
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
    r["brush_params"] = out(g.brush_params, BRUSH_FCOLS);
    r["stop_offsets"] = out(g.stop_offsets, 1);
    r["stop_colors"] = out(g.stop_colors, STOP_COLOR_COLS);
    r["layer_opacity"] = out(g.layer_opacity, 1);
    return r;
}

// dL/d(filter radius), Monte Carlo mode: g is dL/d(the filtered premultiplied colour of
// each pixel, background excluded), height x width x 4. On the CPU.
double filter_radius_grad(const py::dict& scene, Array<float> g, int width, int height, int samples,
                          const std::string& filter, double filter_radius, uint64_t seed, int threads) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    RenderOptions o = render_options(width, height, samples, "mc", filter, filter_radius, seed, threads, py::none());
    if (g.size() != (py::ssize_t)width * height * 4) throw std::invalid_argument("g must be height x width x 4");
    py::gil_scoped_release release;
    PreparedScene prepared = timed_prepare(a);
    return filter_radius_gradient(prepared, o, g.data());
}

// Backward passes redone on the CPU because a sample overflowed a GPU thread's lists.
std::atomic<long> backward_fallbacks{0};

py::dict render_grad(const py::dict& scene, Array<float> image, Array<float> d_image, int width, int height,
                     int samples, const std::string& mode, const std::string& filter, double filter_radius,
                     uint64_t seed, int threads, py::object background, double boundary_density, int device,
                     bool emulate_gpu_lists, int interior_samples, const KeptScene* kept) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    RenderOptions o = render_options(width, height, samples, mode, filter, filter_radius, seed, threads, background);
    if (interior_samples < 0) throw std::invalid_argument("interior_samples must be >= 0");
    o.interior_samples = interior_samples;
    if (image.size() != (py::ssize_t)width * height * 4 || d_image.size() != image.size())
        throw std::invalid_argument("image and its gradient must be height x width x 4");
    SceneGrads g;
    interruptible([&] {
        // (kept: the forward pass's preparation of these same arrays)
        std::shared_ptr<const PreparedScene> own;
        if (!kept || !kept->scene) own = std::make_shared<const PreparedScene>(timed_prepare(a));
        const PreparedScene& prepared = own ? *own : *kept->scene;
        // On the GPU when asked, unless a sample there needs longer lists than a thread
        // holds: then on the CPU. emulate_gpu_lists runs the CPU lanes with a GPU thread's
        // lists first, to see on the CPU what a GPU run would do.
        bool fixed = device >= 0 || emulate_gpu_lists, done = false;
        if (device >= 0)
            done = gpu::render_backward(prepared, a, o, image.data(), d_image.data(), boundary_density, device, g);
        else if (emulate_gpu_lists)
            done = render_backward(prepared, a, o, image.data(), d_image.data(), boundary_density, g, &GPU_LISTS);
        if (fixed && !done) ++backward_fallbacks;
        if (!done) render_backward(prepared, a, o, image.data(), d_image.data(), boundary_density, g);
    });
    return grads_dict(g);
}

// The scene at n points (pixel space, [n, 2]) in the analytical mode with kernel radius
// filter_radius: [n, 4] straight RGBA (pydiffvg's eval_positions).
RenderOptions points_options(double filter_radius, int threads) {
    return render_options(1, 1, 1, "analytic", "tent", filter_radius, 0, threads, py::none());
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
    interruptible([&] { render_points(timed_prepare(a), o, xy, n, px); });
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
        render_points_backward(timed_prepare(a), a, o, xy, n, colours.data(), d_colours.data(), g, dp);
    });
    return py::make_tuple(grads_dict(g), d_xy);
}

// Runs task(b) for every scene of a batch on up to `threads` threads, one scene per
// thread at a time; the first error (in scene order) is raised after all have run.
template <class Task>
void for_each_scene(int n, int threads, Task task) {
    std::vector<std::exception_ptr> errors(n);
    ThreadPool::instance().parallel_for(n, threads, [&](int b, int) {
        try {
            task(b);
        } catch (...) {
            errors[b] = std::current_exception();
        }
    });
    for (auto& e : errors)
        if (e) std::rethrow_exception(e);
}

std::vector<SceneInput> batch_inputs(const py::list& scenes, const std::vector<uint64_t>& seeds) {
    if (seeds.size() != scenes.size()) throw std::invalid_argument("a batch needs one seed per scene");
    std::vector<SceneInput> inputs;
    inputs.reserve(scenes.size());
    for (const py::handle& s : scenes) inputs.push_back(scene_input(s.cast<py::dict>()));
    return inputs;
}

// A batch of scenes rendered at one size with one set of options (each its own seed), in
// one call: parallel over the scenes, each scene on one thread. For training loops that
// render many small scenes a step, where one call per scene would cost more than its pixels.
py::array_t<float> render_batch(const py::list& scenes, int width, int height, int samples, const std::string& mode,
                                const std::string& filter, double filter_radius, const std::vector<uint64_t>& seeds,
                                int threads, py::object background) {
    std::vector<SceneInput> inputs = batch_inputs(scenes, seeds);
    RenderOptions o = render_options(width, height, samples, mode, filter, filter_radius, 0, 1, background);
    const int n = (int)inputs.size();
    const size_t pixels = (size_t)width * height;
    py::array_t<float> images({(py::ssize_t)n, (py::ssize_t)height, (py::ssize_t)width, (py::ssize_t)4});
    float* out = images.mutable_data();
    interruptible([&] {
        for_each_scene(n, threads, [&](int b) {
            SceneArrays a = inputs[b].arrays();
            RenderOptions ob = o;
            ob.seed = seeds[b];
            render_forward(timed_prepare(a), ob, out + 4 * pixels * b);
        });
    });
    return images;
}

// Gradients of a batch rendered by render_batch: one dict per scene, as render_grad's.
py::list render_grad_batch(const py::list& scenes, Array<float> images, Array<float> d_images, int width, int height,
                           int samples, const std::string& mode, const std::string& filter, double filter_radius,
                           const std::vector<uint64_t>& seeds, int threads, py::object background,
                           double boundary_density, int interior_samples) {
    std::vector<SceneInput> inputs = batch_inputs(scenes, seeds);
    RenderOptions o = render_options(width, height, samples, mode, filter, filter_radius, 0, 1, background);
    if (interior_samples < 0) throw std::invalid_argument("interior_samples must be >= 0");
    o.interior_samples = interior_samples;
    const int n = (int)inputs.size();
    const size_t pixels = (size_t)width * height;
    if (images.size() != (py::ssize_t)(4 * pixels * n) || d_images.size() != images.size())
        throw std::invalid_argument("images and their gradients must be batch x height x width x 4");
    std::vector<SceneGrads> grads(n);
    interruptible([&] {
        for_each_scene(n, threads, [&](int b) {
            SceneArrays a = inputs[b].arrays();
            RenderOptions ob = o;
            ob.seed = seeds[b];
            render_backward(timed_prepare(a), a, ob, images.data() + 4 * pixels * b, d_images.data() + 4 * pixels * b,
                            boundary_density, grads[b]);
        });
    });
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
    l["brush_kinds"] = named({{"solid", BRUSH_SOLID}, {"linear", BRUSH_LINEAR}, {"radial", BRUSH_RADIAL}});
    l["columns"] = named({{"points", POINT_COLS},
                          {"point_widths", 1},
                          {"segments", SEGMENT_COLS},
                          {"subpaths", SUBPATH_COLS},
                          {"shapes", SHAPE_COLS},
                          {"ellipses", ELLIPSE_COLS},
                          {"draws", DRAW_COLS},
                          {"draw_params", DRAW_FCOLS},
                          {"brushes", BRUSH_COLS},
                          {"brush_params", BRUSH_FCOLS},
                          {"stop_offsets", 1},
                          {"stop_colors", STOP_COLOR_COLS},
                          {"layer_parents", 1},
                          {"layer_opacity", 1}});
    return l;
}

}  // namespace

PYBIND11_MODULE(_core, m) {
    m.doc() = "vecfit's compiled core: geometry and rendering on flat arrays";
    m.def("render", &render, "Render the scene arrays (a dict, see vecfit/renderer/pack.py) into [H, W, 4] straight RGBA",
          py::arg("scene"), py::arg("width"), py::arg("height"), py::arg("samples"), py::arg("mode"),
          py::arg("filter"), py::arg("filter_radius"), py::arg("seed"), py::arg("threads"), py::arg("background"),
          py::arg("brute_force") = false, py::arg("device") = -1);
    py::class_<KeptScene>(m, "KeptScene", "A scene prepared by render_keeping, for render_grad's `prepared`");
    m.def("render_keeping", &render_keeping,
          "render, returning (image, the prepared scene) for render_grad of the same arrays",
          py::arg("scene"), py::arg("width"), py::arg("height"), py::arg("samples"), py::arg("mode"),
          py::arg("filter"), py::arg("filter_radius"), py::arg("seed"), py::arg("threads"), py::arg("background"),
          py::arg("device") = -1);
    m.def("render_grad", &render_grad,
          "Gradients of the scene arrays given the forward image and dL/d(image)",
          py::arg("scene"), py::arg("image"), py::arg("d_image"), py::arg("width"), py::arg("height"),
          py::arg("samples"), py::arg("mode"), py::arg("filter"), py::arg("filter_radius"), py::arg("seed"),
          py::arg("threads"), py::arg("background"), py::arg("boundary_density"), py::arg("device") = -1,
          py::arg("emulate_gpu_lists") = false, py::arg("interior_samples") = 0,
          py::arg("prepared") = nullptr);
    m.def("render_batch", &render_batch,
          "Render a list of scene dicts at one size into [B, H, W, 4] straight RGBA, in parallel over the scenes",
          py::arg("scenes"), py::arg("width"), py::arg("height"), py::arg("samples"), py::arg("mode"),
          py::arg("filter"), py::arg("filter_radius"), py::arg("seeds"), py::arg("threads"), py::arg("background"));
    m.def("render_grad_batch", &render_grad_batch,
          "Gradients of a batch rendered by render_batch: a list of dicts, one per scene, as render_grad's",
          py::arg("scenes"), py::arg("images"), py::arg("d_images"), py::arg("width"), py::arg("height"),
          py::arg("samples"), py::arg("mode"), py::arg("filter"), py::arg("filter_radius"), py::arg("seeds"),
          py::arg("threads"), py::arg("background"), py::arg("boundary_density"), py::arg("interior_samples") = 0);
    m.def("render_points", &render_points_py,
          "The scene at points [n, 2] (pixel space), analytical mode with kernel radius filter_radius: [n, 4] "
          "straight RGBA", py::arg("scene"), py::arg("positions"), py::arg("filter_radius"), py::arg("threads"));
    m.def("render_points_grad", &render_points_grad_py,
          "render_points' gradients: (dict of the scene arrays' gradients, dL/d(positions) [n, 2])",
          py::arg("scene"), py::arg("positions"), py::arg("colours"), py::arg("d_colours"),
          py::arg("filter_radius"), py::arg("threads"));
    m.def("filter_radius_grad", &filter_radius_grad,
          "dL/d(filter radius) in Monte Carlo mode, given dL/d(premultiplied colour) per pixel",
          py::arg("scene"), py::arg("g"), py::arg("width"), py::arg("height"), py::arg("samples"),
          py::arg("filter"), py::arg("filter_radius"), py::arg("seed"), py::arg("threads"));
    m.def("layout", &layout,
          "The scene arrays' layout: enums (shape_kinds, draw_kinds, fill_rules, caps, joins, brush_kinds) "
          "and each table's row width (columns)");
    m.def("backward_fallbacks", [] { return backward_fallbacks.load(); },
          "Backward passes redone on the CPU so far because a sample needed longer lists than a GPU thread has");
    m.def("phase_seconds", [] {
        py::dict out;
        for (int p = 0; p < PHASE_COUNT; ++p)
            out[phase_name(p)] = phase_nanoseconds()[p].exchange(0) * 1e-9;
        return out;
    }, "Seconds spent in each of the core's phases since the last call (and resets them)");
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
