// Device memory for the CUDA passes: buffers that free themselves, and device copies of
// the prepared scene and the tiles, seen through the same views as on the host.
#pragma once

#include <cuda_runtime.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpu/gpu.h"
#include "scene/scene.h"
#include "scene/tiles.h"

namespace vf {
namespace gpu {

inline void check(cudaError_t status, const char* what) {
    if (status != cudaSuccess) throw std::runtime_error(std::string("CUDA error in ") + what + ": " + cudaGetErrorString(status));
}

// Device memory that frees itself.
class DeviceBuffer {
public:
    explicit DeviceBuffer(size_t bytes) { check(cudaMalloc(&ptr_, bytes ? bytes : 1), "cudaMalloc"); }
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;
    ~DeviceBuffer() { cudaFree(ptr_); }
    void* get() const { return ptr_; }

private:
    void* ptr_ = nullptr;
};

// Device copies of host arrays, kept alive together.
class Uploads {
public:
    template <class T>
    Span<T> put(const std::vector<T>& v) {
        if (v.empty()) return {nullptr, 0};
        buffers_.emplace_back(new DeviceBuffer(v.size() * sizeof(T)));
        void* p = buffers_.back()->get();
        check(cudaMemcpy(p, v.data(), v.size() * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy (upload)");
        return {static_cast<const T*>(p), v.size()};
    }

private:
    std::vector<std::unique_ptr<DeviceBuffer>> buffers_;
};

inline SceneView upload_scene(Uploads& up, const PreparedScene& sc) {
    SceneView v;
    v.segments = up.put(sc.segments);
    v.point_hw = up.put(sc.point_hw);
    v.fill_items = up.put(sc.fill_items);
    v.stroke_items = up.put(sc.stroke_items);
    v.draws = up.put(sc.draws);
    v.paints = up.put(sc.paints);
    v.stop_offsets = up.put(sc.stop_offsets);
    v.stop_colors = up.put(sc.stop_colors);
    v.layer_parent = up.put(sc.layer_parent);
    v.layer_opacity = up.put(sc.layer_opacity);
    v.layer_depth = up.put(sc.layer_depth);
    return v;
}

inline TileView upload_bins(Uploads& up, const TileBins& b) {
    return {b.nx, b.ny, b.margin, up.put(b.start), up.put(b.entries), up.put(b.items), up.put(b.crossings)};
}

// Per-thread stack the root finder's recursion needs on top of a kernel's own frame (which
// the compiler counts; the recursion it cannot): for a quintic, 4 levels of poly_roots,
// 15 of isolate and 3 of roots_by_derivative, 7,384 bytes on sm_90 (ptxas -v), rounded up.
constexpr size_t RECURSION_STACK = 10240;

// Makes `device` current for the scope of one pass (and the caller's current device, e.g.
// torch's, current again afterwards), with `stack_bytes` on each thread's stack.
class DeviceScope {
public:
    DeviceScope(int device, size_t stack_bytes) {
        int count = device_count();
        if (device < 0 || device >= count)
            throw std::runtime_error("no CUDA device " + std::to_string(device) + " (found " + std::to_string(count) + ")");
        check(cudaGetDevice(&previous_), "cudaGetDevice");
        check(cudaSetDevice(device), "cudaSetDevice");
        try {
            reserve_stack(stack_bytes);
        } catch (...) {
            cudaSetDevice(previous_);
            throw;
        }
    }
    ~DeviceScope() { cudaSetDevice(previous_); }
    DeviceScope(const DeviceScope&) = delete;
    DeviceScope& operator=(const DeviceScope&) = delete;

private:
    int previous_ = 0;

    static void reserve_stack(size_t stack_bytes) {
        size_t current = 0;
        check(cudaDeviceGetLimit(&current, cudaLimitStackSize), "cudaDeviceGetLimit");
        if (current >= stack_bytes) return;
        // The driver reserves this much for every thread the GPU can hold at once.
        cudaError_t status = cudaDeviceSetLimit(cudaLimitStackSize, stack_bytes);
        if (status == cudaErrorMemoryAllocation) {
            cudaGetLastError();
            throw std::runtime_error("the GPU has too little free memory for a per-thread stack of " +
                                     std::to_string(stack_bytes) + " bytes");
        }
        check(status, "cudaDeviceSetLimit");
    }
};

// One block of TILE x TILE threads per tile, the tiles numbered along x alone (a grid's y
// extent stops at 65,535 blocks, which a tall image would pass).
inline unsigned tile_blocks(const TileView& bins) { return (unsigned)(bins.nx * bins.ny); }
__device__ inline void tile_pixel(const TileView& bins, int& x, int& y) {
    int tile = (int)blockIdx.x;
    x = (tile % bins.nx) * TILE + (int)threadIdx.x;
    y = (tile / bins.nx) * TILE + (int)threadIdx.y;
}

}  // namespace gpu
}  // namespace vf
