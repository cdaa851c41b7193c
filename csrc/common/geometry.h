// Geometry on doubles: vectors, polynomial roots, Bézier segments, closest points.
// Everything here is inline and free of allocation so that a CUDA build can compile the
// same functions for the device.
#pragma once

#include <cmath>

#include "common/portable.h"

namespace vf {

struct Vec2 {
    double x = 0, y = 0;
};
VF_HD Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
VF_HD Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
VF_HD Vec2 operator-(Vec2 a) { return {-a.x, -a.y}; }
VF_HD Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
VF_HD Vec2 operator*(Vec2 a, double s) { return {s * a.x, s * a.y}; }
VF_HD double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
VF_HD double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
VF_HD double length(Vec2 a) { return std::sqrt(dot(a, a)); }
VF_HD double distance(Vec2 a, Vec2 b) { return length(a - b); }
VF_HD Vec2 perp(Vec2 a) { return {-a.y, a.x}; }
VF_HD Vec2 normalized(Vec2 a) {
    double l = length(a);
    return l > 0 ? Vec2{a.x / l, a.y / l} : Vec2{0, 0};
}

// 2x2 linear map, row-major: (a b; c d).
struct Mat2 {
    double a = 1, b = 0, c = 0, d = 1;
};
VF_HD Vec2 operator*(const Mat2& m, Vec2 v) { return {m.a * v.x + m.b * v.y, m.c * v.x + m.d * v.y}; }
VF_HD double det(const Mat2& m) { return m.a * m.d - m.b * m.c; }
VF_HD Mat2 inverse(const Mat2& m) {
    double k = det(m);
    k = k != 0 ? 1.0 / k : 0.0;
    return {m.d * k, -m.b * k, -m.c * k, m.a * k};
}

// 2-D affine map, row-major 2x3: x' = m00 x + m01 y + m02, y' = m10 x + m11 y + m12.
struct Affine {
    double m00 = 1, m01 = 0, m02 = 0, m10 = 0, m11 = 1, m12 = 0;
};
VF_HD Vec2 apply(const Affine& m, Vec2 p) {
    return {m.m00 * p.x + m.m01 * p.y + m.m02, m.m10 * p.x + m.m11 * p.y + m.m12};
}

struct Box {
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
};
VF_HD void expand(Box& b, Vec2 p) {
    b.x0 = vmin(b.x0, p.x);
    b.y0 = vmin(b.y0, p.y);
    b.x1 = vmax(b.x1, p.x);
    b.y1 = vmax(b.y1, p.y);
}
VF_HD Box grown(Box b, double m) { return {b.x0 - m, b.y0 - m, b.x1 + m, b.y1 + m}; }
VF_HD bool overlaps(const Box& a, const Box& b) {
    return a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1;
}
VF_HD bool valid(const Box& b) { return b.x0 <= b.x1 && b.y0 <= b.y1; }
// Squared distance from p to the box (0 inside).
VF_HD double distance2(const Box& b, Vec2 p) {
    double dx = vmax(vmax(b.x0 - p.x, 0.0), p.x - b.x1);
    double dy = vmax(vmax(b.y0 - p.y, 0.0), p.y - b.y1);
    return dx * dx + dy * dy;
}

// ------------------------------------------------------------------ polynomials

VF_HD double poly_eval(const double* c, int n, double t) {  // sum c[i] t^i, i <= n
    double v = c[n];
    for (int i = n - 1; i >= 0; --i) v = v * t + c[i];
    return v;
}

// Root of p in [a, b] where p(a) and p(b) have opposite signs: Newton steps, falling back
// to bisection whenever a step leaves the bracket, so it always converges.
VF_HD double refine_root(const double* c, int n, double a, double b, double pa) {
    double d[5];
    for (int i = 0; i < n; ++i) d[i] = (i + 1) * c[i + 1];
    double t = 0.5 * (a + b);
    for (int it = 0; it < 40; ++it) {
        double p = poly_eval(c, n, t);
        if (p == 0) return t;
        if ((p < 0) == (pa < 0)) {
            a = t;
            pa = p;
        } else {
            b = t;
        }
        double dp = n > 0 ? poly_eval(d, n - 1, t) : 0;
        double next = dp != 0 ? t - p / dp : 0.5 * (a + b);
        if (!(next > a && next < b)) next = 0.5 * (a + b);
        // 1e-12 in t is far below a pixel for any curve of sane size.
        if (std::fabs(next - t) <= 1e-12 * (1 + std::fabs(t)) || b - a <= 1e-12) return next;
        t = next;
    }
    return t;
}

// Real roots of sum c[i] t^i (degree <= 5) in [lo, hi], sorted; returns their count.
// The polynomial is written in the Bernstein basis of [lo, hi]; by Descartes' rule of
// signs, the number of sign changes of its Bernstein coefficients bounds the number of
// roots (with parity). No change: no root (the common case, at once); one change: one
// root, found by refine_root; more: split the interval in two (de Casteljau) and look
// again. A cluster that stays unresolved down to a tiny interval is a multiple root.
namespace detail {

struct RootSink {
    double* roots;
    int count;
    VF_HD void push(double t) {
        // a double root can come back as two roots a rounding error apart
        if (count == 0 || t - roots[count - 1] > 1e-7 * (1 + std::fabs(t))) roots[count++] = t;
    }
};

VF_HD int sign_changes(const double* b, int n, double eps) {
    int changes = 0, last = 0;
    for (int i = 0; i <= n; ++i) {
        int s = b[i] > eps ? 1 : (b[i] < -eps ? -1 : 0);
        if (s != 0) {
            if (last != 0 && s != last) ++changes;
            last = s;
        }
    }
    return changes;
}

// Roots in [t0, t1] by isolating with the derivative's roots (pieces between them are
// monotone); a critical point where p vanishes to rounding is a root of even
// multiplicity, which shows no sign change. Used where roots cluster.
VF_HD void roots_by_derivative(const double* c, int n, double t0, double t1, RootSink& sink);

VF_HD void isolate(const double* c, int n, const double* b, double t0, double t1, double eps, int depth,
                   RootSink& sink) {
    int v = sign_changes(b, n, eps);
    if (v == 0) return;
    if (v == 1 && std::fabs(b[0]) > eps && std::fabs(b[n]) > eps) {
        sink.push(refine_root(c, n, t0, t1, poly_eval(c, n, t0)));
        return;
    }
    if (depth >= 4) {  // roots cluster here: settle them by the derivative
        roots_by_derivative(c, n, t0, t1, sink);
        return;
    }
    // de Casteljau at the midpoint: left half in l[], right half in r[].
    double w[6], l[6], r[6];
    for (int i = 0; i <= n; ++i) w[i] = b[i];
    for (int k = 0; k <= n; ++k) {
        l[k] = w[0];
        r[n - k] = w[n - k];
        for (int i = 0; i < n - k; ++i) w[i] = 0.5 * (w[i] + w[i + 1]);
    }
    double tm = 0.5 * (t0 + t1);
    isolate(c, n, l, t0, tm, eps, depth + 1, sink);
    if (std::fabs(r[0]) <= eps) sink.push(tm);  // a root exactly at the split
    isolate(c, n, r, tm, t1, eps, depth + 1, sink);
}

}  // namespace detail

VF_HD int poly_roots(const double* coeffs, int degree, double lo, double hi, double* roots);

namespace detail {

VF_HD void roots_by_derivative(const double* c, int n, double t0, double t1, RootSink& sink) {
    double d[5];
    for (int i = 0; i < n; ++i) d[i] = (i + 1) * c[i + 1];
    double crit[5];
    int nc = poly_roots(d, n - 1, t0, t1, crit);
    double knots[7];
    int nk = 0;
    knots[nk++] = t0;
    for (int i = 0; i < nc; ++i)
        if (crit[i] > knots[nk - 1]) knots[nk++] = crit[i];
    if (t1 > knots[nk - 1]) knots[nk++] = t1;
    // Rounding bound of Horner's evaluation: a few ulps of sum |c_i| |t|^i.
    auto vanishes = [&](double t, double pt) {
        double bound = 0;
        for (int i = n; i >= 0; --i) bound = bound * std::fabs(t) + std::fabs(c[i]);
        return std::fabs(pt) <= 32 * 2.2e-16 * bound;
    };
    double pk[7];
    for (int k = 0; k < nk; ++k) pk[k] = poly_eval(c, n, knots[k]);
    for (int k = 0; k < nk; ++k) {
        // the ends of [t0, t1] are reported by the caller (or lie strictly inside pieces)
        if (k > 0 && k + 1 < nk && vanishes(knots[k], pk[k])) sink.push(knots[k]);
        if (k + 1 < nk && !vanishes(knots[k], pk[k]) && !vanishes(knots[k + 1], pk[k + 1]) &&
            (pk[k] < 0) != (pk[k + 1] < 0))
            sink.push(refine_root(c, n, knots[k], knots[k + 1], pk[k]));
    }
}

}  // namespace detail

VF_HD int poly_roots(const double* coeffs, int degree, double lo, double hi, double* roots) {
    double c[6];
    double scale = 0;
    for (int i = 0; i <= degree; ++i) {
        c[i] = coeffs[i];
        scale = vmax(scale, std::fabs(c[i]));
    }
    if (scale == 0 || !(hi >= lo)) return 0;
    int n = degree;
    while (n > 0 && std::fabs(c[n]) <= 1e-13 * scale) --n;
    if (n == 0) return 0;
    if (n == 1) {
        double t = -c[0] / c[1];
        if (t >= lo && t <= hi) {
            roots[0] = t;
            return 1;
        }
        return 0;
    }
    if (n == 2) {  // closed form, in the numerically stable arrangement
        double disc = c[1] * c[1] - 4 * c[2] * c[0];
        if (disc < 0) {
            // a double root lost to rounding shows as a slightly negative discriminant
            if (disc < -1e-12 * c[1] * c[1] - 1e-300) return 0;
            disc = 0;
        }
        double q = -0.5 * (c[1] + std::copysign(std::sqrt(disc), c[1]));
        double r0 = q / c[2], r1 = q != 0 ? c[0] / q : r0;
        if (r0 > r1) vswap(r0, r1);
        int count = 0;
        if (r0 >= lo && r0 <= hi) roots[count++] = r0;
        if (r1 >= lo && r1 <= hi && (count == 0 || r1 - roots[0] > 1e-7 * (1 + std::fabs(r1)))) roots[count++] = r1;
        return count;
    }
    // Coefficients of p(lo + (hi - lo) s) in s (Taylor shift and scale), then Bernstein:
    // b_k = sum_{i <= k} C(k, i) / C(n, i) a_i.
    double a[6];
    for (int i = 0; i <= n; ++i) a[i] = c[i];
    for (int i = 0; i < n; ++i)  // Horner-style shift by lo
        for (int j = n - 1; j >= i; --j) a[j] += lo * a[j + 1];
    double h = hi - lo, hp = 1;
    for (int i = 0; i <= n; ++i) {
        a[i] *= hp;
        hp *= h;
    }
    static const double binom[6][6] = {{1, 0, 0, 0, 0, 0}, {1, 1, 0, 0, 0, 0}, {1, 2, 1, 0, 0, 0},
                                       {1, 3, 3, 1, 0, 0}, {1, 4, 6, 4, 1, 0}, {1, 5, 10, 10, 5, 1}};
    double b[6], bscale = 0;
    for (int k = 0; k <= n; ++k) {
        b[k] = 0;
        for (int i = 0; i <= k; ++i) b[k] += binom[k][i] / binom[n][i] * a[i];
        bscale = vmax(bscale, std::fabs(b[k]));
    }
    double eps = 1e-14 * bscale;
    detail::RootSink sink{roots, 0};
    if (std::fabs(b[0]) <= eps) sink.push(lo);
    detail::isolate(c, n, b, lo, hi, eps, 0, sink);
    if (std::fabs(b[n]) <= eps) sink.push(hi);
    return sink.count;
}

// ------------------------------------------------------------- Bézier segments

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

// ---------------------------------------------------------------------- ellipses

// Closest point on the axis-aligned ellipse (x/e0)^2 + (y/e1)^2 = 1 to (y0, y1), for
// e0 >= e1 > 0 and y0, y1 >= 0: Eberly's robust bisection on the Lagrange parameter.
VF_HD double ellipse_closest_quadrant(double e0, double e1, double y0, double y1, double& x0, double& x1) {
    if (y1 > 0) {
        if (y0 > 0) {
            double z0 = y0 / e0, z1 = y1 / e1;
            double g = z0 * z0 + z1 * z1 - 1;
            if (g != 0) {
                // Bisection on t = s + 1 rather than s: near the centre the root has
                // s close to -1, where s + 1 would lose its relative precision.
                double r0 = (e0 / e1) * (e0 / e1);
                double n0 = r0 * z0;
                double t0 = z1;                                    // s0 = z1 - 1
                double t1 = g < 0 ? 1.0 : std::hypot(n0, z1);      // s1 = 0 or |(n0, z1)| - 1
                double t = t0;
                for (int i = 0; i < 200; ++i) {
                    t = 0.5 * (t0 + t1);
                    if (t == t0 || t == t1) break;
                    double q0 = n0 / ((r0 - 1) + t), q1 = z1 / t;
                    double gs = q0 * q0 + q1 * q1 - 1;
                    if (gs > 0) t0 = t;
                    else if (gs < 0) t1 = t;
                    else break;
                }
                x0 = r0 * y0 / ((r0 - 1) + t);
                x1 = y1 / t;
                return std::hypot(x0 - y0, x1 - y1);
            }
            x0 = y0;
            x1 = y1;
            return 0;
        }
        x0 = 0;
        x1 = e1;
        return std::fabs(y1 - e1);
    }
    double numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
    if (numer0 < denom0) {
        double xde0 = numer0 / denom0;
        x0 = e0 * xde0;
        x1 = e1 * std::sqrt(vmax(0.0, 1 - xde0 * xde0));
        return std::hypot(x0 - y0, x1);
    }
    x0 = e0;
    x1 = 0;
    return std::fabs(y0 - e0);
}

// An ellipse {c + A (cos a, sin a)} in principal form: rotation (cs, sn) and semi-axes.
struct EllipseFrame {
    Vec2 c;
    double cs = 1, sn = 0;  // columns of U: (cs, sn) and (-sn, cs)
    double r0 = 0, r1 = 0;  // semi-axes along those directions
};

// SVD of the 2x2 axes matrix: A = U diag(r0, r1) V^T; the ellipse is c + U diag(r) w.
VF_HD EllipseFrame ellipse_frame(Vec2 c, const Mat2& A) {
    // A A^T = U diag(r^2) U^T
    double p = A.a * A.a + A.b * A.b, q = A.a * A.c + A.b * A.d, r = A.c * A.c + A.d * A.d;
    double theta = 0.5 * std::atan2(2 * q, p - r);
    double mid = 0.5 * (p + r), rad = std::hypot(0.5 * (p - r), q);
    EllipseFrame f;
    f.c = c;
    f.cs = std::cos(theta);
    f.sn = std::sin(theta);
    f.r0 = std::sqrt(vmax(0.0, mid + rad));
    f.r1 = std::sqrt(vmax(0.0, mid - rad));
    return f;
}

// Closest point on the ellipse and its distance.
VF_HD double ellipse_closest(const EllipseFrame& f, Vec2 p, Vec2& closest) {
    Vec2 d = p - f.c;
    double u = f.cs * d.x + f.sn * d.y, v = -f.sn * d.x + f.cs * d.y;
    double e0 = f.r0, e1 = f.r1;
    if (e1 <= 0) {  // degenerate: a line segment of half-length e0 along the first axis
        double x = vclamp(u, -e0, e0);
        closest = f.c + Vec2{f.cs * x, f.sn * x};
        return std::hypot(u - x, v);
    }
    // Rotation leaves ~1e-16 where a point lies on an axis; the quadrant solver needs an
    // exact zero there (its on-axis branches), so snap coordinates that are pure rounding.
    double snap = 1e-12 * (e0 + std::fabs(u) + std::fabs(v));
    if (std::fabs(u) <= snap) u = 0;
    if (std::fabs(v) <= snap) v = 0;
    double x0, x1, dist;
    dist = ellipse_closest_quadrant(e0, e1, std::fabs(u), std::fabs(v), x0, x1);
    x0 = std::copysign(x0, u);
    x1 = std::copysign(x1, v);
    closest = f.c + Vec2{f.cs * x0 - f.sn * x1, f.sn * x0 + f.cs * x1};
    return dist;
}

VF_HD bool ellipse_contains(const EllipseFrame& f, Vec2 p) {
    if (f.r0 <= 0 || f.r1 <= 0) return false;
    Vec2 d = p - f.c;
    double u = (f.cs * d.x + f.sn * d.y) / f.r0, v = (-f.sn * d.x + f.cs * d.y) / f.r1;
    return u * u + v * v <= 1;
}

}  // namespace vf
