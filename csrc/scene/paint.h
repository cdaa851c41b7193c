// Paints, the colour sources of fills and strokes: solid colours and linear / radial
// gradients (pad spread), evaluated at a point, premultiplied. The adjoint is
// backward/paint.h.
#pragma once

#include "common/vec.h"
#include "scene/scene.h"

namespace vf {

// Colour of the stops at t (straight RGBA interpolated, as SVG does), premultiplied.
VF_HD void stop_color(const SceneView& sc, const PreparedPaint& p, double t, double out[4]) {
    const double* off = sc.stop_offsets.data() + p.first_stop;
    const double* col = sc.stop_colors.data() + 4 * p.first_stop;
    int n = p.n_stops;
    double c[4];
    if (!(t > off[0])) {  // also catches NaN
        for (int i = 0; i < 4; ++i) c[i] = col[i];
    } else if (t >= off[n - 1]) {
        for (int i = 0; i < 4; ++i) c[i] = col[4 * (n - 1) + i];
    } else {
        int k = 0;
        while (k + 2 < n && t >= off[k + 1]) ++k;
        double span = off[k + 1] - off[k];
        double u = span > 0 ? (t - off[k]) / span : 1.0;
        for (int i = 0; i < 4; ++i) c[i] = (1 - u) * col[4 * k + i] + u * col[4 * (k + 1) + i];
    }
    double a = vclamp(c[3], 0.0, 1.0);
    for (int i = 0; i < 3; ++i) out[i] = vclamp(c[i], 0.0, 1.0) * a;
    out[3] = a;
}

// Gradient parameter of a radial gradient with focal point f and circle (c, r), as SVG 2
// defines it (a two-point cone from a circle of radius 0 at f to the circle (c, r)): the
// largest t with t r >= 0 for which q lies on the circle of centre f + t (c - f) and
// radius t r. Returns false where no such t exists: outside the cone, when the focal
// point lies outside the circle; that area is not painted.
VF_HD bool radial_t(Vec2 q, Vec2 c, double r, Vec2 f, double& t) {
    Vec2 d = c - f, e = q - f;
    double a = dot(d, d) - r * r, b = dot(e, d), cc = dot(e, e);
    if (std::fabs(a) <= 1e-9 * r * r) {  // focal point on the circle: a linear equation
        if (b <= 0) return false;
        t = cc / (2 * b);
        return true;
    }
    double disc = b * b - a * cc;
    if (disc < 0) return false;
    t = a < 0 ? (b - std::sqrt(disc)) / a : (b + std::sqrt(disc)) / a;
    return t >= 0;
}

VF_HD void paint_color(const SceneView& sc, const PreparedPaint& p, Vec2 pixel, double out[4]) {
    if (p.kind == PAINT_SOLID) {
        double a = vclamp(p.rgba[3], 0.0, 1.0);
        for (int i = 0; i < 3; ++i) out[i] = vclamp(p.rgba[i], 0.0, 1.0) * a;
        out[3] = a;
        return;
    }
    Vec2 q = apply(p.to_paint, pixel);
    double t;
    if (p.kind == PAINT_LINEAR) {
        Vec2 a{p.g[0], p.g[1]}, d = Vec2{p.g[2], p.g[3]} - a;
        double l2 = dot(d, d);
        t = l2 > 0 ? dot(q - a, d) / l2 : 1.0;  // degenerate: the last stop's colour
    } else {
        double r = p.g[2];
        t = 1.0;  // a zero radius paints with the last stop
        if (r > 0 && !radial_t(q, {p.g[0], p.g[1]}, r, {p.g[3], p.g[4]}, t)) {
            out[0] = out[1] = out[2] = out[3] = 0;
            return;
        }
    }
    stop_color(sc, p, t, out);
}

}  // namespace vf
