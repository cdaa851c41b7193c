// Small linear algebra on doubles: 2-D vectors, 2x2 and affine maps, boxes. As in the
// rest of the geometry (roots.h, bezier.h, ellipse.h), everything is inline and free of
// allocation, so that a CUDA build compiles the same functions for the device.
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

}  // namespace vf
