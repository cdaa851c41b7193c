// Real roots of polynomials of degree <= 5 on an interval: what closest points, curve
// extrema and ray crossings are solved with.
#pragma once

#include <cmath>

#include "common/portable.h"

namespace vf {

VF_HD double poly_eval(const double* c, int n, double t) {  // sum c[i] t^i, i <= n
    double v = c[n];
    for (int i = n - 1; i >= 0; --i) v = v * t + c[i];
    return v;
}

// Root of p in [a, b] where p(a) and p(b) have opposite signs: Newton steps, falling back
// to bisection whenever a step leaves the bracket, so it always converges. Where Newton
// lands on the root itself, that point becomes a bracket end, and every later step (which
// points at it) is a bisection towards it: the 40 steps can run out 2e-8 short of it
// (6e-6 - 2t^5 on [0, 3]). So the point of least |p| seen is returned then.
VF_HD double refine_root(const double* c, int n, double a, double b, double pa) {
    double d[5];
    for (int i = 0; i < n; ++i) d[i] = (i + 1) * c[i + 1];
    double t = 0.5 * (a + b);
    double best = t, best_p = INFINITY;
    for (int it = 0; it < 40; ++it) {
        double p = poly_eval(c, n, t);
        if (p == 0) return t;
        if (std::fabs(p) < best_p) {
            best = t;
            best_p = std::fabs(p);
        }
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
    return std::fabs(poly_eval(c, n, t)) < best_p ? t : best;
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

}  // namespace vf
