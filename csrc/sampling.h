// Deterministic random numbers keyed by (seed, pixel, sample), so that an image does not
// depend on how pixels are split between threads; and the pixel filters.
#pragma once

#include <cmath>
#include <cstdint>

namespace vf {

inline uint64_t mix64(uint64_t z) {  // splitmix64 finaliser
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// Two uniform numbers in [0, 1) for one sample.
inline void sample_uniform2(uint64_t seed, uint64_t pixel, uint64_t sample, double& u, double& v) {
    uint64_t h = mix64(seed * 0x100000001b3ull ^ mix64(pixel * 0x9e3779b97f4a7c15ull + sample));
    u = (h >> 11) * (1.0 / 9007199254740992.0);
    h = mix64(h);
    v = (h >> 11) * (1.0 / 9007199254740992.0);
}

enum FilterKind : int { FILTER_BOX = 0, FILTER_TENT = 1, FILTER_GAUSSIAN = 2 };

// Unnormalised filter weight at offset (dx, dy) from the pixel centre, support radius r.
inline double filter_weight(int kind, double r, double dx, double dy) {
    switch (kind) {
        case FILTER_TENT: return std::max(0.0, 1 - std::fabs(dx) / r) * std::max(0.0, 1 - std::fabs(dy) / r);
        case FILTER_GAUSSIAN: {
            double s = r / 2;  // truncated at two standard deviations
            return std::exp(-(dx * dx + dy * dy) / (2 * s * s));
        }
        default: return 1.0;
    }
}

}  // namespace vf
