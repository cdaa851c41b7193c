// Stretches.smoothed, Stretches.tangents, Loops.smoothed, find_corners' sliding minimum
// and _medians of bezier.py, moved from NumPy (0.08 s of a photo's trace): the same
// double operations in the same order, so traces stay byte-identical (see fit.cpp).
#include "trace/stretches.h"

#include <algorithm>
#include <cmath>

namespace vf {

std::vector<double> smooth_stretches(const double* p, int64_t count, const int64_t* first, const int64_t* lengths,
                                     const double* kernel, int64_t kernel_size) {
    const int64_t r = kernel_size / 2;
    int64_t total = 0;
    for (int64_t k = 0; k < count; ++k) total += lengths[k];
    std::vector<double> out(2 * total);
    std::vector<double> ext;
    for (int64_t k = 0; k < count; ++k) {
        const int64_t m = lengths[k], start = first[k];
        // the stretch extended by r points at each end, by point reflection through its ends
        ext.resize(2 * (m + 2 * r));
        for (int64_t q = -r; q < m + r; ++q) {
            const bool before = q < 0, after = q >= m;
            const int64_t src = std::min(std::max(before ? -q : (after ? 2 * (m - 1) - q : q), (int64_t)0), m - 1);
            for (int c = 0; c < 2; ++c) {
                double v = p[2 * (start + src) + c];
                if (before) v = 2 * p[2 * start + c] - v;
                if (after) v = 2 * p[2 * (start + m - 1) + c] - v;
                ext[2 * (q + r) + c] = v;
            }
        }
        for (int64_t i = 0; i < m; ++i)
            for (int c = 0; c < 2; ++c) {
                double acc = 0.0;
                for (int64_t j = 0; j < kernel_size; ++j) acc += kernel[j] * ext[2 * (i + j) + c];
                out[2 * (start + i) + c] = i == 0 || i == m - 1 ? p[2 * (start + i) + c] : acc;
            }
    }
    return out;
}

std::vector<double> stretch_tangents(const double* s, int64_t count, const int64_t* first, const int64_t* lengths,
                                     int64_t window) {
    int64_t total = 0;
    for (int64_t k = 0; k < count; ++k) total += lengths[k];
    std::vector<double> out(2 * total);
    for (int64_t k = 0; k < count; ++k) {
        const int64_t n = lengths[k], start = first[k];
        for (int64_t i = 0; i < n; ++i) {
            const int64_t ahead = start + std::min(i + window, n - 1), behind = start + std::max(i - window, (int64_t)0);
            const double vx = s[2 * ahead] - s[2 * behind], vy = s[2 * ahead + 1] - s[2 * behind + 1];
            const double norm = std::hypot(vx, vy);
            const bool ok = norm > 1e-12;
            out[2 * (start + i)] = ok ? vx / std::max(norm, 1e-12) : 1.0;
            out[2 * (start + i) + 1] = ok ? vy / std::max(norm, 1e-12) : 0.0;
        }
    }
    return out;
}

std::vector<double> smooth_loops(const double* p, int64_t count, const int64_t* first, const int64_t* lengths,
                                 const int64_t* reach, const double* kernels, const int64_t* kernel_at) {
    int64_t total = 0;
    for (int64_t k = 0; k < count; ++k) total += lengths[k];
    std::vector<double> out(p, p + 2 * total);
    std::vector<double> ext;
    for (int64_t k = 0; k < count; ++k) {
        const int64_t n = lengths[k], start = first[k], r = reach[k];
        if (r <= 0) continue;
        const double* kernel = kernels + kernel_at[r];
        // the loop extended by r points at either end round itself: each window is a run
        ext.resize(2 * (n + 2 * r));
        for (int64_t q = 0; q < n + 2 * r; ++q) {
            const int64_t t = ((q - r) % n + n) % n;
            ext[2 * q] = p[2 * (start + t)];
            ext[2 * q + 1] = p[2 * (start + t) + 1];
        }
        for (int64_t i = 0; i < n; ++i)
            for (int c = 0; c < 2; ++c) {
                double acc = 0.0;
                for (int64_t j = 0; j <= 2 * r; ++j) acc += kernel[j] * ext[2 * (i + j) + c];
                out[2 * (start + i) + c] = acc;
            }
    }
    return out;
}

std::vector<double> loop_window_min(const double* values, int64_t count, const int64_t* first,
                                    const int64_t* lengths, int64_t window) {
    int64_t total = 0;
    for (int64_t k = 0; k < count; ++k) total += lengths[k];
    std::vector<double> out(values, values + total);
    std::vector<double> ext;
    for (int64_t k = 0; k < count; ++k) {
        const int64_t n = lengths[k], start = first[k];
        ext.resize(n + 2 * window);  // the loop extended round itself, as in smooth_loops
        for (int64_t q = 0; q < n + 2 * window; ++q) ext[q] = values[start + ((q - window) % n + n) % n];
        for (int64_t i = 0; i < n; ++i) {
            double m = values[start + i];
            for (int64_t j = 0; j <= 2 * window; ++j) {
                const double v = ext[i + j];
                if (std::isnan(v) || v < m) m = v;  // np.minimum: NaN wins
            }
            out[start + i] = m;
        }
    }
    return out;
}

std::vector<double> group_medians(const double* values, const int64_t* group, const uint8_t* valid, int64_t n,
                                  const uint8_t* wanted, int64_t groups) {
    std::vector<std::vector<double>> by_group(groups);
    for (int64_t i = 0; i < n; ++i)
        if (valid[i] && wanted[group[i]]) by_group[group[i]].push_back(values[i]);
    std::vector<double> out;
    for (auto& v : by_group) {
        if (v.empty()) continue;
        std::sort(v.begin(), v.end());
        const size_t c = v.size();
        const double lo = v[(c - 1) / 2], hi = v[c / 2];
        out.push_back(c % 2 == 1 ? lo : (lo + hi) / 2);
    }
    return out;
}

}  // namespace vf
