// The tracer's loops in the core (csrc/trace/): the Bézier fit, the sub-pixel placement of
// edges, the smoothing of stretches and loops, the medians, the region merger. Each takes
// numpy arrays, checks their sizes and releases the GIL while it runs; the fit's and the
// placement's settings are one struct each (FitOptions, SubpixelOptions).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "python/bind.h"
#include "python/arrays.h"
#include "trace/fit.h"
#include "trace/merge.h"
#include "trace/stretches.h"
#include "trace/subpixel.h"

namespace py = pybind11;
using namespace vf;
using vf::python::Array;

namespace {

// The tracer's Bézier fit of outline stretches (trace/fit.h): (segments [S, 4, 2], stretch of each).
py::tuple fit_stretches_py(const Array<double>& points, const Array<double>& tangents, const Array<double>& heading,
                           const Array<double>& arc, const Array<int64_t>& first, const Array<int64_t>& lengths,
                           const Array<double>& t1, const Array<double>& t2, const FitOptions& options) {
    FitInput in;
    const int64_t m = (int64_t)heading.size(), k = (int64_t)first.size();
    if (points.size() != 2 * m || tangents.size() != 2 * m || arc.size() != m || lengths.size() != k ||
        t1.size() != 2 * k || t2.size() != 2 * k)
        throw std::invalid_argument("fit_stretches: expected points and tangents [M, 2], heading and arc [M], "
                                    "first and lengths [K], t1 and t2 [K, 2]");
    for (int64_t i = 0; i < k; ++i)
        if (lengths.data()[i] < 1 || first.data()[i] < 0 || first.data()[i] + lengths.data()[i] > m)
            throw std::invalid_argument("fit_stretches: a stretch reaches outside the points");
    if (!(options.tolerance > 0)) throw std::invalid_argument("fit_stretches: tolerance must be positive");
    in.points = points.data();
    in.tangents = tangents.data();
    in.heading = heading.data();
    in.arc = arc.data();
    in.stretches = k;
    in.first = first.data();
    in.lengths = lengths.data();
    in.t1 = t1.data();
    in.t2 = t2.data();
    in.options = options;
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
                                       const Array<float>& alpha, const SubpixelOptions& options) {
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
        colors.size() != 3 * in.regions || rgb.size() != 3 * pixels || alpha.size() != pixels || options.reach < 0)
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
    in.options = options;
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

void bind_trace(py::module_& m) {
    py::class_<FitOptions>(m, "FitOptions",
                           "The tracer's Bézier fit settings (vecfit/initial/tracer/bezier.py): tolerance (px), "
                           "max_turn (radians a piece may turn before it is split), newton_range (pieces within "
                           "this many tolerances are reparameterised), newton_steps")
        .def(py::init([](double tolerance, double max_turn, double newton_range, int newton_steps) {
                 return FitOptions{tolerance, max_turn, newton_range, newton_steps};
             }),
             py::kw_only(), py::arg("tolerance"), py::arg("max_turn"), py::arg("newton_range"),
             py::arg("newton_steps"))
        .def_readwrite("tolerance", &FitOptions::tolerance)
        .def_readwrite("max_turn", &FitOptions::max_turn)
        .def_readwrite("newton_range", &FitOptions::newton_range)
        .def_readwrite("newton_steps", &FitOptions::newton_steps);
    py::class_<SubpixelOptions>(m, "SubpixelOptions",
                                "The tracer's sub-pixel placement settings (vecfit/initial/tracer/subpixel.py): "
                                "min_contrast, max_shift (px), reach (midpoints either side)")
        .def(py::init([](double min_contrast, double max_shift, int reach) {
                 return SubpixelOptions{min_contrast, max_shift, reach};
             }),
             py::kw_only(), py::arg("min_contrast"), py::arg("max_shift"), py::arg("reach"))
        .def_readwrite("min_contrast", &SubpixelOptions::min_contrast)
        .def_readwrite("max_shift", &SubpixelOptions::max_shift)
        .def_readwrite("reach", &SubpixelOptions::reach);
    m.def("fit_stretches", &fit_stretches_py,
          "The tracer's Bézier fit (vecfit/initial/tracer/bezier.py): (segments [S, 4, 2], stretch of each)",
          py::arg("points"), py::arg("tangents"), py::arg("heading"), py::arg("arc"), py::arg("first"),
          py::arg("lengths"), py::arg("t1"), py::arg("t2"), py::arg("options"));
    m.def("refine_outlines", &refine_outlines_py,
          "The tracer's sub-pixel placement of outline edges (vecfit/initial/tracer/subpixel.py): the points moved",
          py::arg("points"), py::arg("lengths"), py::arg("region"), py::arg("hole"), py::arg("labels"),
          py::arg("rank"), py::arg("colors"), py::arg("rgb"), py::arg("alpha"), py::arg("options"));
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
}
