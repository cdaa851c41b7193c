// Bézier segments of degree 1..3: evaluation, derivatives, splitting, extrema and tight
// bounds, closest points.
#pragma once

#include <cmath>

#include "common/portable.h"
#include "common/roots.h"
#include "common/vec.h"

namespace vf {

// A segment of degree 1..3 given by its control points.
struct Segment {
    int degree = 1;
    Vec2 p[4];
};

VF_HD Vec2 seg_eval(const Segment& s, double t) {
    double u = 1 - t;
    switch (s.degree) {
        case 1: return u * s.p[0] + t * s.p[1];
        case 2: return (u * u) * s.p[0] + (2 * u * t) * s.p[1] + (t * t) * s.p[2];
        default:
            return (u * u * u) * s.p[0] + (3 * u * u * t) * s.p[1] + (3 * u * t * t) * s.p[2] +
                   (t * t * t) * s.p[3];
    }
}

VF_HD Vec2 seg_deriv(const Segment& s, double t) {
    double u = 1 - t;
    switch (s.degree) {
        case 1: return s.p[1] - s.p[0];
        case 2: return (2 * u) * (s.p[1] - s.p[0]) + (2 * t) * (s.p[2] - s.p[1]);
        default:
            return (3 * u * u) * (s.p[1] - s.p[0]) + (6 * u * t) * (s.p[2] - s.p[1]) +
                   (3 * t * t) * (s.p[3] - s.p[2]);
    }
}

VF_HD Vec2 seg_deriv2(const Segment& s, double t) {
    switch (s.degree) {
        case 1: return {0, 0};
        case 2: return 2.0 * (s.p[0] - 2.0 * s.p[1] + s.p[2]);
        default:
            return (6 * (1 - t)) * (s.p[0] - 2.0 * s.p[1] + s.p[2]) + (6 * t) * (s.p[1] - 2.0 * s.p[2] + s.p[3]);
    }
}

VF_HD Vec2 seg_end(const Segment& s) { return s.p[s.degree]; }

// A scalar Bézier of degree n (c[0..n]) at t, and its derivative in t: per-point stroke
// widths along a segment use the segment's own degree and parameter.
VF_HD double bez_scalar(const double* c, int n, double t) {
    double u = 1 - t;
    switch (n) {
        case 1: return u * c[0] + t * c[1];
        case 2: return u * u * c[0] + 2 * u * t * c[1] + t * t * c[2];
        default: return u * u * u * c[0] + 3 * u * u * t * c[1] + 3 * u * t * t * c[2] + t * t * t * c[3];
    }
}
VF_HD double bez_scalar_deriv(const double* c, int n, double t) {
    double u = 1 - t;
    switch (n) {
        case 1: return c[1] - c[0];
        case 2: return 2 * u * (c[1] - c[0]) + 2 * t * (c[2] - c[1]);
        default: return 3 * u * u * (c[1] - c[0]) + 6 * u * t * (c[2] - c[1]) + 3 * t * t * (c[3] - c[2]);
    }
}

// Power-basis coefficients a[k] of the segment relative to an origin o: B(t) - o = sum a[k] t^k.
VF_HD void seg_power_basis(const Segment& s, Vec2 o, Vec2* a) {
    Vec2 p0 = s.p[0] - o;
    if (s.degree == 1) {
        a[0] = p0;
        a[1] = s.p[1] - s.p[0];
    } else if (s.degree == 2) {
        a[0] = p0;
        a[1] = 2.0 * (s.p[1] - s.p[0]);
        a[2] = s.p[0] - 2.0 * s.p[1] + s.p[2];
    } else {
        a[0] = p0;
        a[1] = 3.0 * (s.p[1] - s.p[0]);
        a[2] = 3.0 * (s.p[0] - 2.0 * s.p[1] + s.p[2]);
        a[3] = (s.p[3] - s.p[0]) + 3.0 * (s.p[1] - s.p[2]);
    }
}

// Critical points of |B(t) - p|^2 on [0, 1]: the roots of (B(t) - p) . B'(t), a
// polynomial of degree 2n - 1 (a quintic for cubics). Returns their count.
VF_HD int seg_critical_points(const Segment& s, Vec2 p, double* ts) {
    Vec2 a[4];
    seg_power_basis(s, p, a);
    int n = s.degree;
    double c[6] = {0, 0, 0, 0, 0, 0};
    for (int i = 0; i <= n; ++i)
        for (int j = 1; j <= n; ++j) c[i + j - 1] += j * dot(a[i], a[j]);
    return poly_roots(c, 2 * n - 1, 0.0, 1.0, ts);
}

// Global closest point: the best of the critical points and the two end points.
struct Closest {
    double t = 0, dist = 1e300;
};
VF_HD Closest seg_closest(const Segment& s, Vec2 p) {
    Closest best;
    best.t = 0;
    best.dist = distance(s.p[0], p);
    double d1 = distance(seg_end(s), p);
    if (d1 < best.dist) best = {1.0, d1};
    double ts[5];
    int n = seg_critical_points(s, p, ts);
    for (int i = 0; i < n; ++i) {
        double d = distance(seg_eval(s, ts[i]), p);
        if (d < best.dist) best = {ts[i], d};
    }
    return best;
}

// Split at t with de Casteljau's algorithm: the parts on [0, t] and [t, 1].
VF_HD void seg_split(const Segment& s, double t, Segment& left, Segment& right) {
    int n = s.degree;
    Vec2 w[4];
    for (int i = 0; i <= n; ++i) w[i] = s.p[i];
    left.degree = right.degree = n;
    for (int k = 0; k <= n; ++k) {
        left.p[k] = w[0];
        right.p[n - k] = w[n - k];
        for (int i = 0; i < n - k; ++i) w[i] = (1 - t) * w[i] + t * w[i + 1];
    }
}

// The part of the segment on [t0, t1], as a segment of the same degree.
VF_HD Segment seg_part(const Segment& s, double t0, double t1) {
    Segment l, r, out = s;
    if (t1 < 1) {
        seg_split(s, t1, l, r);
        out = l;
    }
    if (t0 > 0 && t1 > 0) {
        seg_split(out, t0 / t1, l, r);
        out = r;
    }
    return out;
}

// Tangent direction at t = 0 (end = false) or t = 1 (end = true), skipping coincident
// control points; zero for a segment that is a single point.
VF_HD Vec2 seg_end_tangent(const Segment& s, bool end) {
    int n = s.degree;
    if (!end) {
        for (int i = 1; i <= n; ++i) {
            Vec2 d = s.p[i] - s.p[0];
            if (dot(d, d) > 1e-24) return normalized(d);
        }
    } else {
        for (int i = n - 1; i >= 0; --i) {
            Vec2 d = s.p[n] - s.p[i];
            if (dot(d, d) > 1e-24) return normalized(d);
        }
    }
    return {0, 0};
}

// Parameter values in (0, 1) where the coordinate (axis 0: x, 1: y) has an extremum.
VF_HD int seg_extrema(const Segment& s, int axis, double* ts) {
    auto v = [&](int i) { return axis == 0 ? s.p[i].x : s.p[i].y; };
    if (s.degree == 1) return 0;
    double c[3];
    if (s.degree == 2) {  // B' = 2 (p1 - p0) + 2 t (p0 - 2 p1 + p2)
        c[0] = v(1) - v(0);
        c[1] = v(0) - 2 * v(1) + v(2);
        int n = poly_roots(c, 1, 0.0, 1.0, ts);
        int m = 0;
        for (int i = 0; i < n; ++i)
            if (ts[i] > 0 && ts[i] < 1) ts[m++] = ts[i];
        return m;
    }
    double a = v(1) - v(0), b = v(2) - v(1), d = v(3) - v(2);
    c[0] = a;
    c[1] = 2 * (b - a);
    c[2] = a - 2 * b + d;
    int n = poly_roots(c, 2, 0.0, 1.0, ts);
    int m = 0;
    for (int i = 0; i < n; ++i)
        if (ts[i] > 0 && ts[i] < 1) ts[m++] = ts[i];
    return m;
}

// The bounds of the curve's part on [t0, t1]: its ends and its x and y extrema inside
// (tx, ty: the segment's, as seg_extrema gives them). A cubic's control polygon can reach
// far past the curve, which refinement makes common, and every box feeds the tile
// binning. Grown by a hair so that rounding in the extrema never leaves a curve point out.
VF_HD Box seg_bbox(const Segment& s, double t0, double t1, const double* tx, int nx, const double* ty, int ny) {
    Box b;
    expand(b, seg_eval(s, t0));
    expand(b, seg_eval(s, t1));
    for (int i = 0; i < nx; ++i)
        if (tx[i] > t0 && tx[i] < t1) expand(b, seg_eval(s, tx[i]));
    for (int i = 0; i < ny; ++i)
        if (ty[i] > t0 && ty[i] < t1) expand(b, seg_eval(s, ty[i]));
    double size = vmax(vmax(std::fabs(b.x0), std::fabs(b.x1)), vmax(std::fabs(b.y0), std::fabs(b.y1)));
    return grown(b, 1e-9 * (1 + size));
}

// The whole curve's bounds.
VF_HD Box seg_bbox(const Segment& s) {
    double tx[2], ty[2];
    int nx = seg_extrema(s, 0, tx), ny = seg_extrema(s, 1, ty);
    return seg_bbox(s, 0, 1, tx, nx, ty, ny);
}

// Power-basis coefficients of one coordinate of a segment: coord(t) = sum a[k] t^k.
VF_HD void seg_axis_poly(const Segment& s, int axis, double* a) {
    Vec2 v[4];
    seg_power_basis(s, {0, 0}, v);
    for (int k = 0; k < 4; ++k) a[k] = k <= s.degree ? (axis == 0 ? v[k].x : v[k].y) : 0.0;
}

// t in [t0, t1] with sum a[k] t^k = value (cubic at most), for a polynomial monotone on
// that interval whose values at the ends, f0 and f1 (minus value), bracket zero. Newton
// from the secant guess, kept inside the bracket; stops at a residual far below a pixel.
VF_HD double monotone_root(const double* a, double value, double t0, double t1, double f0, double f1) {
    if (f0 == 0) return t0;
    if (f1 == 0) return t1;
    double lo = t0, hi = t1;
    double t = t0 + (t1 - t0) * f0 / (f0 - f1);
    double tol = 1e-11 * (std::fabs(a[0]) + std::fabs(a[1]) + std::fabs(a[2]) + std::fabs(a[3]) + std::fabs(value) + 1);
    for (int it = 0; it < 40; ++it) {
        double f = ((a[3] * t + a[2]) * t + a[1]) * t + a[0] - value;
        if (std::fabs(f) <= tol) return t;
        if ((f < 0) == (f0 < 0)) lo = t; else hi = t;
        double df = (3 * a[3] * t + 2 * a[2]) * t + a[1];
        double next = df != 0 ? t - f / df : 0.5 * (lo + hi);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        if (hi - lo <= 1e-14) return next;
        t = next;
    }
    return t;
}


// Whether the crossing of a piece monotone in y (as in monotone_root: f0 and f1, the
// values of y - value at t0 and t1, bracket zero) with the line y = value lies in
// (x_lo, x_hi]; ax, ay: the power-basis coefficients of x(t) and y(t).
// Why not monotone_root, then x: a Monte Carlo sample only needs the side of the
// crossing, and samples lie pixels away from it far more often than within 1e-9 px of
// it. The root is bracketed from both sides (Newton steps, each with two probes just
// around its result), and x over the bracket [lo, hi] lies between x(lo) and x(hi) give
// or take (hi - lo)^2 / 8 max|x''|; once that range lies on one side the answer is
// known (typically after one or two steps, where the full solve took 4-5). Near the
// crossing the answer is the solved root's, as before.
VF_HD bool monotone_crossing_within(const double* ax, const double* ay, double value, double t0, double t1,
                                    double f0, double f1, double x_lo, double x_hi) {
    auto X = [&](double t) { return ((ax[3] * t + ax[2]) * t + ax[1]) * t + ax[0]; };
    auto inside = [&](double x) { return x > x_lo && x <= x_hi; };
    if (f0 == 0) return inside(X(t0));
    if (f1 == 0) return inside(X(t1));
    const double curve = 0.125 * vmax(std::fabs(2 * ax[2]), std::fabs(2 * ax[2] + 6 * ax[3]));
    const double tol =
        1e-11 * (std::fabs(ay[0]) + std::fabs(ay[1]) + std::fabs(ay[2]) + std::fabs(ay[3]) + std::fabs(value) + 1);
    double lo = t0, hi = t1, f_lo = f0, x_at_lo = X(t0), x_at_hi = X(t1);
    // Narrows the bracket to s (inside it); false where s is the root itself.
    auto narrow = [&](double s, double fs) {
        if (fs == 0) return false;
        if ((fs < 0) == (f_lo < 0)) {
            lo = s;
            f_lo = fs;
            x_at_lo = X(s);
        } else {
            hi = s;
            x_at_hi = X(s);
        }
        return true;
    };
    double t = t0 + (t1 - t0) * f0 / (f0 - f1);
    for (int it = 0; it < 40; ++it) {
        double w = hi - lo, dev = curve * w * w;
        double x_min = vmin(x_at_lo, x_at_hi) - dev, x_max = vmax(x_at_lo, x_at_hi) + dev;
        if (x_min > x_lo && x_max <= x_hi) return true;
        if (x_max <= x_lo || x_min > x_hi) return false;
        double f = ((ay[3] * t + ay[2]) * t + ay[1]) * t + ay[0] - value;
        if (std::fabs(f) <= tol || w <= 1e-14 || !narrow(t, f)) return inside(X(t));
        double df = (3 * ay[3] * t + 2 * ay[2]) * t + ay[1];
        double step = df != 0 ? -f / df : 0;
        double next = t + step;
        if (!(next > lo && next < hi)) {
            t = 0.5 * (lo + hi);
            continue;
        }
        // Probes an eighth of the step either side of the Newton point: once Newton
        // converges they straddle the root, and the bracket shrinks to a quarter step.
        double eta = 0.125 * std::fabs(step), a = next - eta, b = next + eta;
        if (a > lo && b < hi) {
            double fa = ((ay[3] * a + ay[2]) * a + ay[1]) * a + ay[0] - value;
            if (!narrow(a, fa)) return inside(X(a));
            if (b < hi) {
                double fb = ((ay[3] * b + ay[2]) * b + ay[1]) * b + ay[0] - value;
                if (!narrow(b, fb)) return inside(X(b));
            }
        }
        t = next > lo && next < hi ? next : 0.5 * (lo + hi);
    }
    return inside(X(t));
}

}  // namespace vf
