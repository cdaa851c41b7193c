// The CUDA forward pass: the launch and memory code around shade_pixel (shade.h), the
// per-pixel function the CPU build runs too. One thread per pixel, one block per tile, so
// a block's threads walk the same tile entries.
#include <cuda_runtime.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "../gpu.h"
#include "../shade.h"
#include "device_memory.cuh"

namespace vf {
namespace gpu {
namespace {

struct Background {
    double c[4];
};

__global__ void shade_kernel(SceneView sc, TileView bins, RenderOptions o, Background bg, float* out) {
    int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= o.width || y >= o.height) return;
    shade_pixel(sc, bins, o, bg.c, x, y, out + 4 * ((size_t)y * o.width + x));
}

// Per-thread stack for the compositor's layer stack and the root finder's recursion.
constexpr size_t STACK_BYTES = 8192;

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
    int n = device_count();
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
    use_device(device, STACK_BYTES);
    ForwardPlan plan = plan_forward(scene, options);
    Uploads up;
    SceneView sc = upload_scene(up, scene);
    TileView bins = upload_bins(up, plan.bins);
    size_t bytes = (size_t)options.width * options.height * 4 * sizeof(float);
    DeviceBuffer image(bytes);
    Background bg{{plan.background[0], plan.background[1], plan.background[2], plan.background[3]}};
    dim3 block(TILE, TILE), grid((options.width + TILE - 1) / TILE, (options.height + TILE - 1) / TILE);
    shade_kernel<<<grid, block>>>(sc, bins, plan.options, bg, static_cast<float*>(image.get()));
    check(cudaGetLastError(), "shade_kernel launch");
    check(cudaMemcpy(out, image.get(), bytes, cudaMemcpyDeviceToHost), "cudaMemcpy (image)");
}

}  // namespace gpu
}  // namespace vf
