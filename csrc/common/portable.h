// What lets one source serve the CPU and a CUDA build: VF_HD marks the per-sample
// functions (scene evaluation, coverage, boundary sampling, their derivatives) for both
// the host and the device, and Span is the read-only view of an array they index, which
// on the host points into a std::vector and on the device into device memory.
#pragma once

#include <cstddef>

#ifdef __CUDACC__
#define VF_HD __host__ __device__ inline
#else
#define VF_HD inline
#endif

namespace vf {

template <class T>
struct Span {
    const T* ptr = nullptr;
    size_t n = 0;
    VF_HD const T& operator[](size_t i) const { return ptr[i]; }
    VF_HD const T* data() const { return ptr; }
    VF_HD size_t size() const { return n; }
};

template <class Vector>
Span<typename Vector::value_type> span_of(const Vector& v) {
    return {v.data(), v.size()};
}

// A list in storage someone else owns, with a fixed capacity: per-thread arrays on a
// GPU, vectors sized to the scene's worst case on the CPU. A push past the capacity is
// dropped and flagged, so that the caller can redo the work where there is room.
template <class T>
struct Buffer {
    T* items = nullptr;
    int capacity = 0;
    int n = 0;
    bool overflow = false;
    VF_HD void clear() { n = 0; }
    VF_HD void push_back(const T& t) {
        if (n < capacity) items[n++] = t;
        else overflow = true;
    }
    VF_HD int size() const { return n; }
    VF_HD bool empty() const { return n == 0; }
    VF_HD T& operator[](int i) { return items[i]; }
    VF_HD const T& operator[](int i) const { return items[i]; }
};

// min / max / clamp / swap for device code too (std::swap is not constexpr before C++20,
// and std::min / max / clamp need nvcc's relaxed-constexpr mode on the device).
template <class T>
VF_HD T vmin(T a, T b) { return b < a ? b : a; }
template <class T>
VF_HD T vmax(T a, T b) { return a < b ? b : a; }
template <class T>
VF_HD T vclamp(T v, T lo, T hi) { return v < lo ? lo : (hi < v ? hi : v); }
// A double as an int in [lo, hi]: converting a double outside int's range is undefined
// (x86 gives INT_MIN), and scenes may hold coordinates of 1e30 pixels. NaN gives lo.
VF_HD int clamp_to_int(double v, int lo, int hi) {
    if (!(v > lo)) return lo;
    if (!(v < hi)) return hi;
    return (int)v;
}
template <class T>
VF_HD void vswap(T& a, T& b) {
    T t = a;
    a = b;
    b = t;
}

// a + b c with the product and the sum each rounded, on the host and the device alike:
// nvcc contracts a + b * c into one fused multiply-add (rounded once), so a point
// computed that way can differ from the host's in the last bit, and a decision taken on
// it (which pixel, which side of an edge) with it. (The host build has no -march, so gcc
// emits no FMA there.)
VF_HD double mul_add_rn(double a, double b, double c) {
#ifdef __CUDA_ARCH__
    return __dadd_rn(a, __dmul_rn(b, c));
#else
    return a + b * c;
#endif
}

}  // namespace vf
