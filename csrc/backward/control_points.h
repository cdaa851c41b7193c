// What a prepared piece of geometry owes to the input control points, for both routes to
// the gradients (boundary sampling and the analytical prefilter's chain rule): Bernstein
// weights, the control points (and per-point widths) of a stroke item, the whole segment
// a stroke item is a piece of, and the frame at a segment's end.
#pragma once

#include "common/bezier.h"
#include "common/portable.h"
#include "scene/scene.h"
#include "scene/stroke.h"

namespace vf {

VF_HD double bernstein(int n, int i, double t) {
    static const double binom[4][4] = {{1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
    double u = 1 - t, v = binom[n][i];
    for (int k = 0; k < i; ++k) v *= t;
    for (int k = i; k < n; ++k) v *= u;
    return v;
}

// d/dt of bernstein(n, i, t): n (b_{i-1}^{n-1} - b_i^{n-1}).
VF_HD double bernstein_deriv(int n, int i, double t) {
    if (n == 0) return 0;
    double a = i >= 1 ? bernstein(n - 1, i - 1, t) : 0.0, b = i <= n - 1 ? bernstein(n - 1, i, t) : 0.0;
    return n * (a - b);
}

// Per-point widths: whether point k's width takes gradients. A negative input is clamped
// to 0 (no gradient, as the clamp has none); 0 itself does, so a width can grow from 0.
VF_HD bool width_free(const SceneView& sc, int32_t k) { return k >= 0 && (size_t)k < sc.point_hw.size() && sc.point_hw[k] >= 0; }

// Pixel-space control-point indices of a stroke item (its straightened form uses the ends).
VF_HD void stroke_item_indices(const SceneView& sc, const StrokeSegment& s, int32_t idx[4]) {
    const SegmentSource& src = sc.segments[s.source];
    for (int i = 0; i < 4; ++i) idx[i] = -1;
    if (s.seg.degree == src.seg.degree) {
        for (int i = 0; i <= s.seg.degree; ++i) idx[i] = src.point_index[i];
    } else {
        idx[0] = src.point_index[0];
        idx[s.seg.degree] = src.point_index[src.seg.degree];
    }
}

// The whole stroke-space segment a stroke item is a piece of (as preparation made it).
VF_HD Segment whole_segment(const SceneView& sc, const PreparedDraw& d, const StrokeSegment& s) {
    Segment w = sc.segments[s.source].seg;
    if (!d.metric_identity) w = transformed(w, d.metric);
    return straightened(w, d.varying);
}

// A piece's parameter t as a parameter of the whole segment.
VF_HD double whole_t(const StrokeSegment& s, double t) { return s.t0 + t * (s.t1 - s.t0); }

// The frame of a stroke item's end: unit tangent (direction of travel) and the two
// control points it comes from (head - tail), with their distance, in stroke space.
struct EndFrame {
    Vec2 t;
    int head = 0, tail = 0;  // control point numbers within the segment
    double length = 0;
};

VF_HD EndFrame end_frame(const Segment& s, bool end) {
    EndFrame f;
    int n = s.degree;
    if (end) {
        f.head = n;
        for (int i = n - 1; i >= 0; --i)
            if (dot(s.p[n] - s.p[i], s.p[n] - s.p[i]) > 1e-24) { f.tail = i; break; }
    } else {
        f.tail = 0;
        for (int i = 1; i <= n; ++i)
            if (dot(s.p[i] - s.p[0], s.p[i] - s.p[0]) > 1e-24) { f.head = i; break; }
    }
    Vec2 d = s.p[f.head] - s.p[f.tail];
    f.length = length(d);
    f.t = f.length > 0 ? (1 / f.length) * d : Vec2{1, 0};
    return f;
}

}  // namespace vf
