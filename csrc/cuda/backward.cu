// The CUDA backward pass: the launch and memory code around pixel_backward and
// boundary_sample (backward/pixel.h), the per-sample functions the CPU lanes run too.
// The plan (tiles, pixel adjoints, boundary pieces) is made on the host; the interior
// term runs one thread per pixel, one block per tile; the boundary term one thread per
// boundary sample. Threads add into shared gradient arrays atomically.
#include <cuda_runtime.h>

#include <vector>

#include "backward/backward.h"
#include "cuda/device_memory.cuh"
#include "gpu/gpu.h"

namespace vf {
namespace gpu {
namespace {

// Per-thread list sizes (backward.h): past them a thread flags an overflow and the host
// redoes the pass on the CPU, whose lists are sized to the scene.
constexpr int GPU_HITS = GPU_LISTS.hits, GPU_OPS = GPU_LISTS.ops;
// Per-thread stack: pixel_backward_kernel's frame (17.3 KB on sm_80/90: those lists and the
// compositor's layer stacks; the boundary kernel's is 8.6 KB) and the root finder's
// recursion.
constexpr size_t STACK_BYTES = 20480 + RECURSION_STACK;

__global__ void pixel_backward_kernel(SceneView sc, TileView bins, RenderOptions o, const double* gpix, GradView g,
                                int* overflow) {
    int x, y;
    tile_pixel(bins, x, y);
    if (x >= o.width || y >= o.height) return;
    Hit hits[GPU_HITS];
    TapeOp ops[GPU_OPS];
    Quad g_hits[GPU_HITS];
    SampleScratch w{{hits, GPU_HITS}, {{ops, GPU_OPS}}, {g_hits, GPU_HITS}};
    pixel_backward(sc, bins, o, gpix + 4 * ((size_t)y * o.width + x), x, y, w, g);
    if (w.overflow()) *overflow = 1;
}

// Sample s of all pieces' samples: piece k holds samples first[k] .. first[k + 1] - 1.
__global__ void boundary_kernel(SceneView sc, TileView bins, BoundarySampler pass, const Piece* pieces,
                                const long long* first, int n_pieces, BoundaryContext bc, GradView g,
                                int* overflow) {
    long long s = (long long)blockIdx.x * blockDim.x + threadIdx.x;
    if (s >= first[n_pieces]) return;
    int lo = 0, hi = n_pieces - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (first[mid] <= s) lo = mid;
        else hi = mid - 1;
    }
    Hit hits[GPU_HITS];
    Buffer<Hit> list{hits, GPU_HITS};
    boundary_sample(sc, bins, pass, pieces[lo], (int)(s - first[lo]), (uint64_t)lo, bc, list, g);
    if (list.overflow) *overflow = 1;
}

// Device gradient arrays shaped like a host SceneGrads, zeroed.
struct DeviceGrads {
    std::vector<std::unique_ptr<DeviceBuffer>> buffers;
    GradView view;
    GradPtr zeroed(const std::vector<double>& like) {
        buffers.emplace_back(new DeviceBuffer(like.size() * sizeof(double)));
        void* p = buffers.back()->get();
        check(cudaMemset(p, 0, like.size() * sizeof(double)), "cudaMemset");
        return {static_cast<double*>(p)};
    }
    explicit DeviceGrads(const SceneGrads& host) {
        view = {zeroed(host.points),       zeroed(host.point_widths), zeroed(host.ellipses),
                zeroed(host.draw_params),  zeroed(host.paint_params), zeroed(host.stop_offsets),
                zeroed(host.stop_colors),  zeroed(host.layer_opacity)};
    }
    static void fetch(GradPtr from, std::vector<double>& to) {
        if (!to.empty())
            check(cudaMemcpy(to.data(), from.p, to.size() * sizeof(double), cudaMemcpyDeviceToHost),
                  "cudaMemcpy (gradients)");
    }
    void fetch(SceneGrads& out) const {
        fetch(view.points, out.points);
        fetch(view.point_widths, out.point_widths);
        fetch(view.ellipses, out.ellipses);
        fetch(view.draw_params, out.draw_params);
        fetch(view.paint_params, out.paint_params);
        fetch(view.stop_offsets, out.stop_offsets);
        fetch(view.stop_colors, out.stop_colors);
        fetch(view.layer_opacity, out.layer_opacity);
    }
};

}  // namespace

bool render_backward(const PreparedScene& scene, const SceneArrays& arrays, const RenderOptions& options,
                     const float* image, const float* d_image, double boundary_density, int device,
                     SceneGrads& out) {
    DeviceScope scope(device, STACK_BYTES);
    BackwardPlan plan = plan_backward(scene, options, image, d_image, boundary_density);
    Uploads up;
    SceneView sc = upload_scene(up, scene);
    TileView bins = upload_bins(up, plan.bins);
    const double* gpix = up.put(plan.gpix).data();
    out.resize_like(arrays);
    DeviceGrads grads(out);
    DeviceBuffer overflow_flag(sizeof(int));
    int* overflow = static_cast<int*>(overflow_flag.get());
    check(cudaMemset(overflow, 0, sizeof(int)), "cudaMemset");

    pixel_backward_kernel<<<tile_blocks(bins), dim3(TILE, TILE)>>>(sc, bins, plan.options, gpix, grads.view, overflow);
    check(cudaGetLastError(), "pixel_backward_kernel launch");

    if (!plan.pieces.empty()) {
        std::vector<long long> first(plan.pieces.size() + 1, 0);
        for (size_t k = 0; k < plan.pieces.size(); ++k) first[k + 1] = first[k] + plan.pieces[k].count;
        BoundaryContext bc = plan.boundary;
        bc.gpix = gpix;
        BoundarySampler pass{sc, options.seed};
        const int threads = 128;
        long long blocks = (first.back() + threads - 1) / threads;
        if (blocks > 0) {  // (none where every piece lies off the canvas)
            boundary_kernel<<<(unsigned)blocks, threads>>>(sc, bins, pass, up.put(plan.pieces).data(),
                                                           up.put(first).data(), (int)plan.pieces.size(), bc,
                                                           grads.view, overflow);
            check(cudaGetLastError(), "boundary_kernel launch");
        }
    }
    check(cudaDeviceSynchronize(), "the backward kernels");
    int overflowed = 0;
    check(cudaMemcpy(&overflowed, overflow, sizeof(int), cudaMemcpyDeviceToHost), "cudaMemcpy (flag)");
    if (overflowed) return false;
    grads.fetch(out);
    return true;
}

}  // namespace gpu
}  // namespace vf
