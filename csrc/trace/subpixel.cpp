// subpixel.py's refine_outlines, moved from NumPy (0.06-0.1 s of a photo's trace in
// array operations over every outline point). It computes what the NumPy code
// computed, bit for bit, so traces stay byte-identical: the same operations in the same
// order (built without floating-point contraction: see CMakeLists.txt), float32 where
// NumPy kept float32 (the alpha blend), sums over three channels left to right as
// NumPy's reductions over a short last axis make them.
#include "trace/subpixel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vf {
namespace {

// How much of a pixel is the inside colour rather than the outside one (subpixel.py's coverage).
double coverage(const float* pixel, const double* inside, const double* outside) {
    const double d0 = inside[0] - outside[0], d1 = inside[1] - outside[1], d2 = inside[2] - outside[2];
    const double num = ((double)pixel[0] - outside[0]) * d0 + ((double)pixel[1] - outside[1]) * d1 +
                       ((double)pixel[2] - outside[2]) * d2;
    const double den = d0 * d0 + d1 * d1 + d2 * d2;
    double v = num / std::max(den, 1e-12);
    if (std::isnan(v)) return v;
    v = v > 0 ? v : 0.0;
    return v < 1 ? v : 1.0;
}

bool nan_last_less(double a, double b) { return !std::isnan(a) && (std::isnan(b) || a < b); }

}  // namespace

std::vector<double> refine_outlines(const SubpixelInput& in) {
    const int64_t n = in.points, w = in.width, h = in.height;
    const double* p = in.xy;
    std::vector<int64_t> first(in.outlines + 1, 0), owner(n), prev(n), next(n);
    for (int64_t k = 0; k < in.outlines; ++k) first[k + 1] = first[k] + in.lengths[k];
    for (int64_t k = 0; k < in.outlines; ++k)
        for (int64_t i = first[k]; i < first[k + 1]; ++i) {
            owner[i] = k;
            prev[i] = i == first[k] ? first[k + 1] - 1 : i - 1;
            next[i] = i + 1 == first[k + 1] ? first[k] : i + 1;
        }
    // edge midpoints (the other vertices are corners)
    std::vector<uint8_t> mid(n);
    for (int64_t i = 0; i < n; ++i)
        mid[i] = (((int64_t)std::nearbyint(p[2 * i] * 2) + (int64_t)std::nearbyint(p[2 * i + 1] * 2)) & 1) == 1;
    // each outline's orientation (a hole's outside is the region)
    std::vector<double> area(in.outlines, 0.0);
    for (int64_t i = 0; i < n; ++i)
        area[owner[i]] += p[2 * i] * p[2 * next[i] + 1] - p[2 * i + 1] * p[2 * next[i]];
    // outward normal of each midpoint's edge
    std::vector<double> normal(2 * n, 0.0);
    for (int64_t i = 0; i < n; ++i) {
        if (!mid[i]) continue;
        const bool ccw = (area[owner[i]] > 0) != (in.hole[owner[i]] != 0);
        const double sign = ccw ? 1.0 : -1.0;
        const double dx = p[2 * next[i]] - p[2 * prev[i]], dy = p[2 * next[i] + 1] - p[2 * prev[i] + 1];
        const double nx = dy * sign, ny = -dx * sign;
        const double norm = std::max(std::fabs(nx) + std::fabs(ny), 1e-12);
        normal[2 * i] = nx / norm;
        normal[2 * i + 1] = ny / norm;
    }
    // the pixels just inside and just outside each midpoint, and the offset they read
    std::vector<double> offset(n, 0.0);
    std::vector<uint8_t> valid(n, 0);
    for (int64_t i = 0; i < n; ++i) {
        if (!mid[i]) continue;
        const double x = p[2 * i], y = p[2 * i + 1], nx = normal[2 * i], ny = normal[2 * i + 1];
        int64_t ix = (int64_t)std::floor(x - 0.5 * nx), iy = (int64_t)std::floor(y - 0.5 * ny);
        int64_t ox = (int64_t)std::floor(x + 0.5 * nx), oy = (int64_t)std::floor(y + 0.5 * ny);
        if (std::min(ix, ox) < 0 || std::min(iy, oy) < 0 || std::max(ix, ox) >= w || std::max(iy, oy) >= h) continue;
        const int64_t r = in.region[owner[i]];
        const int64_t lo = in.labels[oy * w + ox];
        if (in.labels[iy * w + ix] != r || lo == r) continue;
        if (lo >= 0 && !(in.rank[lo] < in.rank[r])) continue;  // only edges that show
        valid[i] = 1;
        if (lo < 0) {  // against transparency: the fraction is alpha (in float32, as NumPy had it)
            const float a_out = in.alpha[oy * w + ox], a_in = in.alpha[iy * w + ix];
            offset[i] = (double)(a_out - (1.0f - a_in));
        } else {
            const double* cin = in.colors + 3 * r;
            const double* cout = in.colors + 3 * lo;
            const double e0 = cin[0] - cout[0], e1 = cin[1] - cout[1], e2 = cin[2] - cout[2];
            if (std::sqrt(e0 * e0 + e1 * e1 + e2 * e2) >= in.options.min_contrast) {
                const double f_out = coverage(in.rgb + 3 * (oy * w + ox), cin, cout);
                const double f_in = coverage(in.rgb + 3 * (iy * w + ix), cin, cout);
                offset[i] = f_out - (1 - f_in);
            }
        }
    }
    // robust_offsets: each midpoint's offset the median of the valid ones up to `reach`
    // midpoints either side along its outline that face the same way
    std::vector<int64_t> mids;
    std::vector<int64_t> mid_first(in.outlines + 1, 0);
    for (int64_t k = 0; k < in.outlines; ++k) {
        for (int64_t i = first[k]; i < first[k + 1]; ++i)
            if (mid[i]) mids.push_back(i);
        mid_first[k + 1] = (int64_t)mids.size();
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<int64_t> code(mids.size());
    std::vector<double> vals(mids.size());
    for (size_t j = 0; j < mids.size(); ++j) {
        const int64_t i = mids[j];
        code[j] = (int64_t)std::nearbyint(normal[2 * i] * 1.0 + normal[2 * i + 1] * 3.0);
        vals[j] = valid[i] ? offset[i] : nan;
    }
    std::vector<double> robust(mids.size());
    std::vector<double> window(2 * in.options.reach + 1);
    for (int64_t k = 0; k < in.outlines; ++k) {
        const int64_t f = mid_first[k], len = mid_first[k + 1] - f;
        for (int64_t j = f; j < f + len; ++j) {
            int count = 0;
            for (int d = -in.options.reach; d <= in.options.reach; ++d) {
                const int64_t o = f + (((j - f + d) % len) + len) % len;
                const double v = code[o] == code[j] ? vals[o] : nan;
                window[d + in.options.reach] = v;
                count += !std::isnan(v);
            }
            std::sort(window.begin(), window.end(), nan_last_less);
            const int lo = std::max((count - 1) / 2, 0), hi = std::max(count / 2, 0);
            robust[j] = count > 0 ? 0.5 * (window[lo] + window[hi]) : 0.0;
        }
    }
    for (size_t j = 0; j < mids.size(); ++j) offset[mids[j]] = robust[j];
    // midpoints move along their normals; a corner follows its neighbours: the mean
    // along a straight run, the sum where the outline turns
    std::vector<double> shift(2 * n);
    for (int64_t i = 0; i < n; ++i) {
        const double o = std::min(std::max(offset[i], -in.options.max_shift), in.options.max_shift);
        shift[2 * i] = o * normal[2 * i];
        shift[2 * i + 1] = o * normal[2 * i + 1];
    }
    std::vector<double> out(2 * n);
    for (int64_t i = 0; i < n; ++i) {
        const int64_t a = prev[i], b = next[i];
        for (int c = 0; c < 2; ++c) {
            double s;
            if (mid[i]) {
                s = shift[2 * i + c];
            } else {
                const bool turn = std::fabs(normal[2 * a] * normal[2 * b] + normal[2 * a + 1] * normal[2 * b + 1]) < 0.5;
                s = turn ? shift[2 * a + c] + shift[2 * b + c] : 0.5 * (shift[2 * a + c] + shift[2 * b + c]);
            }
            out[2 * i + c] = p[2 * i + c] + s;
        }
    }
    return out;
}

}  // namespace vf
