// Deterministic random numbers keyed by (seed, pixel, sample), so that an image does not
// depend on how pixels are split between threads; and the pixel filters.
#pragma once

#include <cmath>
#include <cstdint>

#include "common/portable.h"

namespace vf {

VF_HD uint64_t mix64(uint64_t z) {  // splitmix64 finaliser
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// Two uniform numbers in [0, 1) for one sample.
VF_HD void sample_uniform2(uint64_t seed, uint64_t pixel, uint64_t sample, double& u, double& v) {
    uint64_t h = mix64(seed * 0x100000001b3ull ^ mix64(pixel * 0x9e3779b97f4a7c15ull + sample));
    u = (h >> 11) * (1.0 / 9007199254740992.0);
    h = mix64(h);
    v = (h >> 11) * (1.0 / 9007199254740992.0);
}

// Position of sample s (of n x n) inside the unit square for one pixel: correlated
// multi-jittered sampling (Kensler 2013). Each of the n x n strata holds one sample, and
// the n^2 samples also fall in distinct columns and rows of the fine n^2 x n^2 grid, which
// estimates edge coverage with less noise than plain jittered strata. The two
// permutations are shared by the pixel's rows / columns ("correlated") and drawn per pixel.
VF_HD uint32_t permute_index(uint32_t i, uint32_t n, uint64_t key) {
    // i-th element of a random permutation of 0..n-1 (n <= 64): rank by hashed keys.
    uint64_t ki = mix64(key ^ (i * 0x9e3779b97f4a7c15ull));
    uint32_t rank = 0;
    for (uint32_t j = 0; j < n; ++j) {
        uint64_t kj = mix64(key ^ (j * 0x9e3779b97f4a7c15ull));
        rank += kj < ki || (kj == ki && j < i);
    }
    return rank;
}

VF_HD uint64_t pixel_permutation_key(uint64_t seed, uint64_t pixel) {
    return mix64(seed ^ mix64(pixel + 0x5851f42d4c957f2dull));
}

VF_HD void sample_position(uint64_t seed, uint64_t pixel, int s, int n, double& x, double& y) {
    double u, v;
    sample_uniform2(seed, pixel, (uint64_t)s, u, v);
    int sx = s % n, sy = s / n;
    uint64_t key = pixel_permutation_key(seed, pixel);
    uint32_t px = permute_index(sx, n, key), py = permute_index(sy, n, key ^ 0xa511e9b3ull);
    x = (sx + (py + u) / n) / n;
    y = (sy + (px + v) / n) / n;
}

// All n x n sample positions of a pixel, as sample_position gives them one by one (the
// permutations, O(n^2) hashes each, drawn once per pixel instead of once per sample);
// n <= 64.
inline void pixel_sample_positions(uint64_t seed, uint64_t pixel, int n, double* xs, double* ys) {
    uint64_t key = pixel_permutation_key(seed, pixel);
    uint32_t px[64], py[64];
    for (int i = 0; i < n; ++i) {
        px[i] = permute_index(i, n, key);
        py[i] = permute_index(i, n, key ^ 0xa511e9b3ull);
    }
    for (int s = 0; s < n * n; ++s) {
        double u, v;
        sample_uniform2(seed, pixel, (uint64_t)s, u, v);
        int sx = s % n, sy = s / n;
        xs[s] = (sx + (py[sy] + u) / n) / n;
        ys[s] = (sy + (px[sx] + v) / n) / n;
    }
}

enum FilterKind : int { FILTER_BOX = 0, FILTER_TENT = 1, FILTER_GAUSSIAN = 2, FILTER_PARABOLIC = 3, FILTER_HANN = 4 };

// Unnormalised filter weight at offset (dx, dy) from the pixel centre, support radius r.
VF_HD double filter_weight(int kind, double r, double dx, double dy) {
    switch (kind) {
        case FILTER_TENT: return vmax(0.0, 1 - std::fabs(dx) / r) * vmax(0.0, 1 - std::fabs(dy) / r);
        case FILTER_GAUSSIAN: {
            double s = r / 2;  // truncated at two standard deviations
            return std::exp(-(dx * dx + dy * dy) / (2 * s * s));
        }
        // diffvg's "radial parabolic" (separable despite its name) and Hann windows; their
        // constant factors cancel in the normalisation by the sum of the weights.
        case FILTER_PARABOLIC: return vmax(0.0, 1 - (dx / r) * (dx / r)) * vmax(0.0, 1 - (dy / r) * (dy / r));
        case FILTER_HANN:
            if (std::fabs(dx) >= r || std::fabs(dy) >= r) return 0.0;
            return 0.25 * (1 + std::cos(M_PI * dx / r)) * (1 + std::cos(M_PI * dy / r));
        default: return 1.0;
    }
}

// The integral of filter_weight over its support, [-r, r]^2.
inline double filter_integral(int kind, double r) {
    switch (kind) {
        case FILTER_TENT: case FILTER_HANN: return r * r;
        case FILTER_PARABOLIC: return (4 * r / 3) * (4 * r / 3);
        case FILTER_GAUSSIAN: {
            double sigma = r / 2, one = sigma * std::sqrt(2 * M_PI) * std::erf(r / (sigma * std::sqrt(2.0)));
            return one * one;
        }
        default: return 4 * r * r;
    }
}

// The radius derivative's kernel (Monte Carlo mode). A pixel is I(r) = E[W(u) c(p + r u)] /
// E[W(u)] over u uniform in [-1, 1]^2, with W(u) = filter_weight at (r u_x, r u_y), which
// depends on u alone. Substituting q = p + r u and differentiating under the integral (the
// support grows with r), dI/dr = (E[D(u) c(p + r u)] + 2 E_edge[W c]) / (r E[W]) with
// D = -2 W - grad W . u, E_edge over u uniform on the support's edge, |u|_inf = 1 (zero
// where W vanishes there: tent, parabolic, Hann; not the truncated Gaussian). The two
// expectations of a constant cancel (E[D] = -2 E_edge[W]), so c may be replaced by c - b
// for any b independent of u. Separable W = h(u_x) h(u_y):
// D = -2 h(x) h(y) - x h'(x) h(y) - h(x) y h'(y). 0 for the box (its radius is fixed).
VF_HD double filter_radius_kernel(int kind, double ux, double uy) {
    double hx, hy, xhx, yhy;  // h(x), h(y), x h'(x), y h'(y)
    switch (kind) {
        case FILTER_TENT:
            hx = 1 - std::fabs(ux), hy = 1 - std::fabs(uy);
            xhx = -std::fabs(ux), yhy = -std::fabs(uy);
            break;
        case FILTER_GAUSSIAN:  // h(x) = exp(-2 x^2): filter_weight's sigma r / 2
            hx = std::exp(-2 * ux * ux), hy = std::exp(-2 * uy * uy);
            xhx = -4 * ux * ux * hx, yhy = -4 * uy * uy * hy;
            break;
        case FILTER_PARABOLIC:
            hx = 1 - ux * ux, hy = 1 - uy * uy;
            xhx = -2 * ux * ux, yhy = -2 * uy * uy;
            break;
        case FILTER_HANN:
            hx = 0.5 * (1 + std::cos(M_PI * ux)), hy = 0.5 * (1 + std::cos(M_PI * uy));
            xhx = -0.5 * M_PI * ux * std::sin(M_PI * ux), yhy = -0.5 * M_PI * uy * std::sin(M_PI * uy);
            break;
        default: return 0.0;
    }
    if (hx < 0 || hy < 0) return 0.0;
    return -2 * hx * hy - xhx * hy - hx * yhy;
}

// Point j of 4 n on the edge of [-1, 1]^2, stratified: n per side, jittered by `jitter` in
// [0, 1) (the Gaussian's edge term, see filter_radius_kernel).
VF_HD void support_edge_point(int j, int n, double jitter, double& ux, double& uy) {
    int side = j / n;
    double t = -1 + 2 * ((j % n) + jitter) / n;
    ux = side == 0 ? 1.0 : side == 1 ? -1.0 : t;
    uy = side == 2 ? 1.0 : side == 3 ? -1.0 : t;
}

}  // namespace vf
