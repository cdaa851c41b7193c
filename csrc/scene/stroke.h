// Construction of the stroke's join and cap pieces from a vertex, the tangents that meet
// there and the half width; shared by scene preparation and the backward pass (which
// rebuilds them under small changes of the tangents and the width).
#pragma once

#include "common/bezier.h"
#include "scene/scene.h"

namespace vf {

// The join at vertex v between a segment leaving along t_in and one leaving along t_out.
VF_HD StrokeEnd make_join(Vec2 v, Vec2 t_in, Vec2 t_out, int join, double hw, double miter_limit) {
    StrokeEnd e;
    e.hw = hw;
    double c = cross(t_in, t_out), d = dot(t_in, t_out);
    if (std::fabs(c) < 1e-12 && d > 0) return e;  // no turn: the sweeps already meet
    // No width (a per-point width of 0 at the vertex): nothing to join, and a polygon of
    // coincident corners would pass convex_contains everywhere.
    if (!(hw > 0)) return e;
    if (join == JOIN_ROUND) {
        e.kind = StrokeEnd::DISK;
        e.center = v;
        return e;
    }
    // The outer side of the turn is opposite to the direction it turns towards.
    double s = c >= 0 ? 1.0 : -1.0;
    Vec2 n_in = -s * perp(t_in), n_out = -s * perp(t_out);
    e.kind = StrokeEnd::POLYGON;
    double cos_half = std::sqrt(vmax(0.0, 0.5 * (1 + d)));  // cos of half the turn
    // Miter length / stroke width = 1 / sin(interior angle / 2) = 1 / cos(turn / 2).
    if (join == JOIN_MITER && cos_half > 1e-12 && 1.0 / cos_half <= miter_limit) {
        Vec2 dir = normalized(n_in + n_out);
        e.poly[0] = v;
        e.poly[1] = v + hw * n_in;
        e.poly[2] = v + (hw / cos_half) * dir;
        e.poly[3] = v + hw * n_out;
        e.n_poly = 4;
    } else {
        e.poly[0] = v;
        e.poly[1] = v + hw * n_in;
        e.poly[2] = v + hw * n_out;
        e.n_poly = 3;
    }
    return e;
}

VF_HD StrokeEnd make_cap(Vec2 at, Vec2 outward, int cap, double hw) {
    StrokeEnd e;
    e.hw = hw;
    if (cap == CAP_ROUND) {
        e.kind = StrokeEnd::DISK;
        e.center = at;
    } else if (cap == CAP_SQUARE) {
        e.kind = StrokeEnd::SQUARE;
        e.center = at;
        e.axis = outward;
    }
    return e;
}

VF_HD Segment transformed(const Segment& s, const Mat2& m) {
    Segment out = s;
    for (int i = 0; i <= s.degree; ++i) out.p[i] = m * s.p[i];
    return out;
}

// A curve whose control points all lie within sqrt(1e-5) of its length from its chord
// is stroked as that straight line, as Skia and resvg do: the direction at the end of
// such a curve is decided by sub-pixel control-point offsets, and stroking it exactly
// grows visible fins and rounds that those renderers (and users) do not expect.
VF_HD bool nearly_straight(const Segment& s) {
    if (s.degree == 1) return false;
    Vec2 a = s.p[0], b = seg_end(s), d = b - a;
    double l2 = dot(d, d);
    if (l2 <= 0) return false;
    for (int i = 1; i < s.degree; ++i) {
        Vec2 r = s.p[i] - a;
        double along = dot(r, d) / l2, off = cross(d, r);
        if (along < 0 || along > 1 || off * off > 1e-5 * l2 * l2) return false;
    }
    return true;
}

// With per-point widths (keep_degree), the width profile is a Bézier over the curve's
// own parameter, so the straight line keeps the curve's degree and parametrisation: the
// inner control points are projected onto the chord (the same line, the same end
// directions, and the widths of the inner points still count).
VF_HD Segment straightened(const Segment& s, bool keep_degree = false) {
    if (!nearly_straight(s)) return s;
    Vec2 a = s.p[0], b = seg_end(s), d = b - a;
    if (keep_degree) {
        Segment out = s;
        double l2 = dot(d, d);
        for (int i = 1; i < s.degree; ++i) out.p[i] = a + (dot(s.p[i] - a, d) / l2) * d;
        return out;
    }
    Segment line;
    line.degree = 1;
    line.p[0] = a;
    line.p[1] = b;
    return line;
}

}  // namespace vf
