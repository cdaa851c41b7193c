// Ellipses given by centre and axes: their frame, closest points and the inside test.
#pragma once

#include <cmath>

#include "common/portable.h"
#include "common/vec.h"

namespace vf {

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
    if (e0 == e1) {  // a circle: along the radius (the bisection below takes ~60 steps a sample)
        double len = std::hypot(u, v);
        x0 = len > 0 ? e0 * (u / len) : e0;  // (the centre: the quadrant solver's answer)
        x1 = len > 0 ? e0 * (v / len) : 0.0;
        closest = f.c + Vec2{f.cs * x0 - f.sn * x1, f.sn * x0 + f.cs * x1};
        return std::fabs(len - e0);
    }
    dist = ellipse_closest_quadrant(e0, e1, std::fabs(u), std::fabs(v), x0, x1);
    x0 = std::copysign(x0, u);
    x1 = std::copysign(x1, v);
    closest = f.c + Vec2{f.cs * x0 - f.sn * x1, f.sn * x0 + f.cs * x1};
    return dist;
}

// Bounds on the distance from p to the ellipse, without solving for the closest point:
// scaling by (1/r0, 1/r1) maps the ellipse to the unit circle and stretches distances by
// between 1/r0 and 1/r1, so the distance lies in [r1, r0] times |rho - 1|, rho being p's
// radius in the scaled frame. Most samples of a large ellipse lie far from it, where the
// bounds decide a test that the bisection would take ~60 steps to. False for a degenerate
// ellipse (no bounds).
VF_HD bool ellipse_distance_bounds(const EllipseFrame& f, Vec2 p, double& lo, double& hi) {
    if (f.r0 <= 0 || f.r1 <= 0) return false;
    Vec2 d = p - f.c;
    double u = (f.cs * d.x + f.sn * d.y) / f.r0, v = (-f.sn * d.x + f.cs * d.y) / f.r1;
    double off = std::fabs(std::hypot(u, v) - 1);
    lo = vmin(f.r0, f.r1) * off;
    hi = vmax(f.r0, f.r1) * off;
    return true;
}

VF_HD bool ellipse_contains(const EllipseFrame& f, Vec2 p) {
    if (f.r0 <= 0 || f.r1 <= 0) return false;
    Vec2 d = p - f.c;
    double u = (f.cs * d.x + f.sn * d.y) / f.r0, v = (-f.sn * d.x + f.cs * d.y) / f.r1;
    return u * u + v * v <= 1;
}

}  // namespace vf
