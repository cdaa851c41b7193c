// The CUDA forward pass: the launch and memory code around pixel_forward
// (forward/pixel.h), the per-pixel function the CPU build runs too. One thread per pixel,
// one block per tile, so a block's threads walk the same tile entries.
#include <cuda_runtime.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "cuda/device_memory.cuh"
#include "forward/pixel.h"
#include "gpu/gpu.h"

namespace vf {
namespace gpu {
namespace {

struct Background {
    double c[4];
};

__global__ void pixel_forward_kernel(SceneView sc, TileView bins, RenderOptions o, Background bg, float* out) {
    int x, y;
    tile_pixel(bins, x, y);
    if (x >= o.width || y >= o.height) return;
    pixel_forward(sc, bins, o, bg.c, x, y, out + 4 * ((size_t)y * o.width + x));
}

// Per-thread stack: the kernel's frame (3.3 KB on sm_80/90, mostly the compositor's layer
// stack) and the root finder's recursion.
constexpr size_t STACK_BYTES = 6144 + RECURSION_STACK;

}  // namespace

bool compiled() { return true; }

int device_count() {
    int n = 0;
    if (cudaGetDeviceCount(&n) != cudaSuccess) {
        cudaGetLastError();  // no driver or no device: clear the error, report none
        return 0;
    }
    return n;
}

std::string build_info() {
    int runtime = 0, driver = 0;
    cudaRuntimeGetVersion(&runtime);
    cudaDriverGetVersion(&driver);
    auto version = [](int v) { return v ? std::to_string(v / 1000) + "." + std::to_string(v % 1000 / 10) : "none"; };
    std::string info = "CUDA: compiled for " VECFIT_CUDA_ARCHS ", runtime " + version(runtime) + ", driver " + version(driver);
    int n = 0;
    cudaError_t status = cudaGetDeviceCount(&n);
    if (status != cudaSuccess) {  // e.g. a driver older than the runtime: say so, not just "0"
        info += std::string(", no devices (") + cudaGetErrorString(status) + ")";
        cudaGetLastError();
        return info;
    }
    info += ", " + std::to_string(n) + " device(s)";
    for (int i = 0; i < n; ++i) {
        cudaDeviceProp prop;
        if (cudaGetDeviceProperties(&prop, i) == cudaSuccess)
            info += std::string("; ") + std::to_string(i) + ": " + prop.name + " (sm_" + std::to_string(prop.major) +
                    std::to_string(prop.minor) + ")";
    }
    return info;
}

void render_forward(const PreparedScene& scene, const RenderOptions& options, int device, float* out) {
    DeviceScope scope(device, STACK_BYTES);
    ForwardPlan plan = plan_forward(scene, options);
    Uploads up;
    SceneView sc = upload_scene(up, scene);
    TileView bins = upload_bins(up, plan.bins);
    size_t bytes = (size_t)options.width * options.height * 4 * sizeof(float);
    DeviceBuffer image(bytes);
    Background bg{{plan.background[0], plan.background[1], plan.background[2], plan.background[3]}};
    pixel_forward_kernel<<<tile_blocks(bins), dim3(TILE, TILE)>>>(sc, bins, plan.options, bg, static_cast<float*>(image.get()));
    check(cudaGetLastError(), "pixel_forward_kernel launch");
    check(cudaMemcpy(out, image.get(), bytes, cudaMemcpyDeviceToHost), "cudaMemcpy (image)");
}

}  // namespace gpu
}  // namespace vf
