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

VF_HD void sample_position(uint64_t seed, uint64_t pixel, int s, int n, double& x, double& y) {
    double u, v;
    sample_uniform2(seed, pixel, (uint64_t)s, u, v);
    int sx = s % n, sy = s / n;
    uint64_t key = mix64(seed ^ mix64(pixel + 0x5851f42d4c957f2dull));
    uint32_t px = permute_index(sx, n, key), py = permute_index(sy, n, key ^ 0xa511e9b3ull);
    x = (sx + (py + u) / n) / n;
    y = (sy + (px + v) / n) / n;
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

}  // namespace vf
