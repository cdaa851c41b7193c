// The renderer's bindings: the options as one typed RenderOptions, the forward and backward
// passes of api/passes.h (single scenes and batches) run while Python can still take a
// Ctrl-C (python/interrupt.h), and what describes the scene arrays and the passes: the
// layout, the footprint, the phases' clocks, the fallbacks.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "api/passes.h"
#include "common/phase_clock.h"
#include "forward/forward.h"
#include "python/bind.h"
#include "python/interrupt.h"
#include "python/scene_arrays.h"
#include "python/test_hooks.h"
#include "scene/scene.h"

namespace py = pybind11;
using namespace vf;
using namespace vf::python;

namespace {

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

const char* mode_name(int mode) { return mode == MODE_ANALYTIC ? "analytic" : "mc"; }

const char* filter_name(int filter) { return filter >= 0 && filter < 5 ? FILTER_NAMES[filter] : "box"; }

// vecfit._core.RenderOptions(...): the options of every pass, checked once here. (Every
// draw tested at every sample, a check of the tiles, is the tests' switch: test_hooks.h.)
RenderOptions make_options(int width, int height, int samples, const std::string& mode, const std::string& filter,
                           double filter_radius, uint64_t seed, int threads, py::object background,
                           int interior_samples, bool premultiplied, double boundary_budget) {
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
    o.brute_force = test_switches().brute_force;
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
                     double boundary_density, int device, const KeptScene* kept) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    check_image(image, options, 1, "image");
    check_image(d_image, options, 1, "its gradient");
    // (the CPU lanes with a GPU thread's lists first: the tests' switch, test_hooks.h)
    const bool emulate_gpu_lists = test_switches().emulate_gpu_lists;
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

}  // namespace

void bind_render(py::module_& m) {
    py::class_<RenderOptions>(m, "RenderOptions",
                              "The options of every pass: size, N x N samples, mode ('mc' or 'analytic'), pixel "
                              "filter and radius, seed, threads (0: all), background (RGBA or None), the interior "
                              "samples the Monte Carlo backward pass revisits (0: all), premultiplied (the image "
                              "premultiplied, not straight), boundary_budget (the Monte Carlo backward's boundary "
                              "samples per pixel of the image at most, allotted by the pixel adjoints; 0: no bound)")
        .def(py::init(&make_options), py::kw_only(), py::arg("width"), py::arg("height"), py::arg("samples") = 2,
             py::arg("mode") = "mc", py::arg("filter") = "box", py::arg("filter_radius") = 0.5, py::arg("seed") = 0,
             py::arg("threads") = 0, py::arg("background") = py::none(), py::arg("interior_samples") = 0,
             py::arg("premultiplied") = false, py::arg("boundary_budget") = 0.0)
        .def_readonly("width", &RenderOptions::width)
        .def_readonly("height", &RenderOptions::height)
        .def_readonly("samples", &RenderOptions::samples)
        .def_property_readonly("mode", [](const RenderOptions& o) { return mode_name(o.mode); })
        .def_property_readonly("filter", [](const RenderOptions& o) { return filter_name(o.filter); })
        .def_readonly("filter_radius", &RenderOptions::filter_radius)
        .def_readonly("seed", &RenderOptions::seed)
        .def_readonly("threads", &RenderOptions::threads)
        .def_readonly("interior_samples", &RenderOptions::interior_samples)
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
          py::arg("device") = -1, py::arg("prepared") = nullptr);
    m.def("render_batch", &render_batch,
          "Render a list of scene dicts at one size into [B, H, W, 4] straight RGBA, in parallel over the scenes",
          py::arg("scenes"), py::arg("options"), py::arg("seeds"));
    m.def("render_grad_batch", &render_grad_batch,
          "Gradients of a batch rendered by render_batch: a list of dicts, one per scene, as render_grad's",
          py::arg("scenes"), py::arg("images"), py::arg("d_images"), py::arg("options"), py::arg("seeds"),
          py::arg("boundary_density"));
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
}
