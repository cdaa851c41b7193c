// The scene at arbitrary points (backward/points.h; pydiffvg's eval_positions) and its
// adjoint: positions [n, 2] in pixel space, the analytical mode with a tent kernel of the
// given radius.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <stdexcept>

#include "api/passes.h"
#include "backward/points.h"
#include "common/sampling.h"
#include "forward/forward.h"
#include "python/bind.h"
#include "python/interrupt.h"
#include "python/scene_arrays.h"

namespace py = pybind11;
using namespace vf;
using namespace vf::python;

namespace {

// A 1 x 1 analytical render's options with kernel radius filter_radius (the struct's other
// defaults: seed 0, no background, straight colours).
RenderOptions points_options(double filter_radius, int threads) {
    RenderOptions o;
    o.width = o.height = o.samples = 1;
    o.mode = MODE_ANALYTIC;
    o.filter = FILTER_TENT;
    o.filter_radius = filter_radius;
    o.threads = threads;
    return o;
}

py::array_t<float> render_points_py(const py::dict& scene, Array<double> positions, double filter_radius, int threads) {
    SceneInput in = scene_input(scene);
    SceneArrays a = in.arrays();
    RenderOptions o = points_options(filter_radius, threads);
    int n = 0;
    const double* xy = rows(positions, 2, n, "positions");
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
    const double* xy = rows(positions, 2, n, "positions");
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

}  // namespace

void bind_points(py::module_& m) {
    m.def("render_points", &render_points_py,
          "The scene at points [n, 2] (pixel space), analytical mode with kernel radius filter_radius: [n, 4] "
          "straight RGBA", py::arg("scene"), py::arg("positions"), py::arg("filter_radius"), py::arg("threads"));
    m.def("render_points_grad", &render_points_grad_py,
          "render_points' gradients: (dict of the scene arrays' gradients, dL/d(positions) [n, 2])",
          py::arg("scene"), py::arg("positions"), py::arg("colours"), py::arg("d_colours"),
          py::arg("filter_radius"), py::arg("threads"));
}
