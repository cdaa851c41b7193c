// Test hooks: the core's geometry called directly from the tests (tests/unit/scene/test_geometry.py),
// which check it against brute force and a Python reference renderer; and the switches of
// test_hooks.h (tests/helpers.py turns them on for a block). Registered on vecfit._core by
// the module (module.cpp); nothing in vecfit/ calls them.
#include "python/test_hooks.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <stdexcept>
#include <utility>
#include <vector>

#include "backward/pixel.h"
#include "common/bezier.h"
#include "common/ellipse.h"
#include "common/roots.h"
#include "python/arrays.h"
#include "python/scene_arrays.h"
#include "scene/coverage.h"
#include "scene/field.h"
#include "scene/scene.h"

namespace py = pybind11;
using namespace vf;

using vf::python::Array;

TestSwitches& test_switches() {
    static TestSwitches switches;
    return switches;
}

namespace {

Segment segment_from(const Array<double>& pts) {
    if (pts.ndim() != 2 || pts.shape(1) != 2 || pts.shape(0) < 2 || pts.shape(0) > 4)
        throw std::invalid_argument("points must be an [n, 2] array with n in 2..4");
    Segment s;
    s.degree = (int)pts.shape(0) - 1;
    for (int i = 0; i <= s.degree; ++i) s.p[i] = {pts.at(i, 0), pts.at(i, 1)};
    return s;
}

}  // namespace

void register_test_hooks(py::module_& m) {
    m.def("brute_force", [](bool on) {
        // Every draw tested at every sample by the renders whose options are made while on (a
        // check of the tiles against the plain loop); returns the previous setting.
        bool old = test_switches().brute_force;
        test_switches().brute_force = on;
        return old;
    }, py::arg("on"));

    m.def("emulate_gpu_lists", [](bool on) {
        // While on, the CPU backward pass runs first with a GPU thread's list sizes, so that
        // a CPU run shows what a GPU run would (its fallbacks); returns the previous setting.
        bool old = test_switches().emulate_gpu_lists;
        test_switches().emulate_gpu_lists = on;
        return old;
    }, py::arg("on"));

    m.def("field_min_items", [](int n) {
        // The fewest segments a tile's fill entry lists for the analytical passes to compute
        // it a tile at a time (scene/field.h); returns the previous value. 0: every entry.
        int old = field_min_items_ref();
        field_min_items_ref() = n;
        return old;
    }, py::arg("n"));

    m.def("stroke_bound_gaps", [](const py::dict& scene, Array<double> points) {
        // For every stroke item of the scene (a packed scene dict, pack.py) and every point
        // (pixel space, [n, 2]): its lower bound (scene/field.h, StrokeBound) less its signed
        // distance (stroke_item_sdf with the sweep always measured, the least over limits),
        // in stroke space. Returns the largest gap (> 0: a bound above a distance), the mean
        // and the number of pairs at a finite distance.
        if (points.ndim() != 2 || points.shape(1) != 2) throw std::invalid_argument("points must be [n, 2]");
        python::SceneInput in = python::scene_input(scene);
        const PreparedScene sc = prepare_scene(in.arrays());
        double most = -INFINITY, sum = 0;
        long n = 0;
        for (const PreparedDraw& d : sc.draws) {
            if (d.kind != DRAW_STROKE || d.is_ellipse) continue;
            for (int k = d.first_item; k < d.first_item + d.n_items; ++k) {
                const StrokeSegment& s = sc.stroke_items[k];
                const StrokeBound b = make_stroke_bound(s);
                for (py::ssize_t i = 0; i < points.shape(0); ++i) {
                    const Vec2 q = to_stroke_space(d, {points.at(i, 0), points.at(i, 1)});
                    const double v = stroke_item_sdf(sc.stroke_items.data(), s, q, 1e300);
                    if (!(v < 1e299)) continue;
                    const double gap = stroke_bound_below(b, q) - v;
                    most = std::max(most, gap);
                    sum += gap;
                    ++n;
                }
            }
        }
        return py::make_tuple(most, n > 0 ? sum / n : 0.0, n);
    }, py::arg("scene"), py::arg("points"));

    m.def("boundary_pixels", [](std::pair<double, double> p, std::pair<double, double> n, double R, int W, int H) {
        // The pixels a Monte Carlo boundary sample at p (outward normal n) counts for.
        Vec2 pp{p.first, p.second};
        BoundarySupport s;
        std::vector<std::pair<int, int>> out;
        if (!boundary_support(pp, nudged(pp, EPS_NORMAL, {n.first, n.second}), R, W, H, s)) return out;
        double dx, dy;
        for (int py = s.y0; py <= s.y1; ++py)
            for (int px = s.x0; px <= s.x1; ++px)
                if (s.holds(px, py, dx, dy)) out.push_back({px, py});
        return out;
    }, py::arg("p"), py::arg("n"), py::arg("filter_radius"), py::arg("width"), py::arg("height"));

    m.def("polynomial_roots", [](std::vector<double> coeffs, double lo, double hi) {
        if (coeffs.empty() || coeffs.size() > 6) throw std::invalid_argument("degree must be 0..5");
        double roots[5];
        int n = poly_roots(coeffs.data(), (int)coeffs.size() - 1, lo, hi, roots);
        return std::vector<double>(roots, roots + n);
    }, py::arg("coeffs"), py::arg("lo"), py::arg("hi"));

    m.def("closest_point_on_segment", [](Array<double> pts, std::pair<double, double> p) {
        Closest c = seg_closest(segment_from(pts), {p.first, p.second});
        return py::make_tuple(c.t, c.dist);
    }, py::arg("points"), py::arg("p"));

    m.def("segment_bounds", [](Array<double> pts) {
        Box b = seg_bbox(segment_from(pts));
        return py::make_tuple(b.x0, b.y0, b.x1, b.y1);
    }, py::arg("points"), "Bounds (x0, y0, x1, y1) of a segment's curve, as the tiles use them");

    m.def("closest_point_on_ellipse", [](std::pair<double, double> center, Array<double> axes,
                                         std::pair<double, double> p) {
        if (axes.size() != 4) throw std::invalid_argument("axes must be a 2x2 matrix");
        Mat2 A{axes.data()[0], axes.data()[1], axes.data()[2], axes.data()[3]};
        EllipseFrame f = ellipse_frame({center.first, center.second}, A);
        Vec2 q;
        double d = ellipse_closest(f, {p.first, p.second}, q);
        return py::make_tuple(py::make_tuple(q.x, q.y), d);
    }, py::arg("center"), py::arg("axes"), py::arg("p"));

    m.def("winding_number", [](Array<double> points, Array<int32_t> degrees, Array<int32_t> subpaths,
                               std::pair<double, double> p) {
        // Same layout as scene.Path; every subpath closed for filling.
        const double* P = points.data();
        int np = (int)(points.size() / 2);
        int nb = (int)(subpaths.size() / 3);
        const int32_t* sp = subpaths.data();
        const int32_t* deg = degrees.data();
        int w = 0, base = 0;
        Vec2 q{p.first, p.second};
        for (int b = 0; b < nb; ++b) {
            int first = sp[3 * b], count = sp[3 * b + 1];
            bool closed = sp[3 * b + 2] != 0;
            int n_pts = closed ? 0 : 1;
            for (int g = first; g < first + count; ++g) n_pts += deg[g];
            int k = base;
            auto pt = [&](int i) {
                int j = i - base >= n_pts ? base : i;  // a closed subpath wraps to its start
                if (j >= np) throw std::invalid_argument("points too short for the segments");
                return Vec2{P[2 * j], P[2 * j + 1]};
            };
            for (int g = first; g < first + count; ++g) {
                Segment s;
                s.degree = deg[g];
                for (int i = 0; i <= s.degree; ++i) s.p[i] = pt(k + i);
                k += s.degree;
                w += ray_crossings(prepare_segment(s, nullptr), q);
            }
            if (!closed && count > 0) {
                Segment line;
                line.degree = 1;
                line.p[0] = pt(k);
                line.p[1] = pt(base);
                w += ray_crossings(prepare_segment(line, nullptr), q);
            }
            base += n_pts;
        }
        return w;
    }, py::arg("points"), py::arg("degrees"), py::arg("subpaths"), py::arg("p"));
}
