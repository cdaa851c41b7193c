// The core's passes as its callers use them (see passes.h).
#include "api/passes.h"

#include <atomic>
#include <exception>

#include "backward/backward.h"
#include "common/phase_clock.h"
#include "common/thread_pool.h"
#include "gpu/gpu.h"

namespace vf {

namespace {

std::atomic<long> fallbacks{0};

// Runs task(b) for every scene of a batch on up to `threads` threads, one scene per
// thread at a time; the first error (in scene order) is raised after all have run.
template <class Task>
void for_each_scene(int n, int threads, Task task) {
    std::vector<std::exception_ptr> errors(n);
    ThreadPool::instance().parallel_for(n, threads, [&](int b, int) {
        try {
            task(b);
        } catch (...) {
            errors[b] = std::current_exception();
        }
    });
    for (auto& e : errors)
        if (e) std::rethrow_exception(e);
}

// One scene of a batch: one thread (the batch is parallel over the scenes), its own seed.
RenderOptions scene_options(const RenderOptions& options, uint64_t seed) {
    RenderOptions o = options;
    o.threads = 1;
    o.seed = seed;
    return o;
}

}  // namespace

std::shared_ptr<const PreparedScene> prepare_timed(const SceneArrays& arrays) {
    PhaseTimer timer(PHASE_PREPARE);
    return std::make_shared<const PreparedScene>(prepare_scene(arrays));
}

void forward_on(const PreparedScene& scene, const RenderOptions& options, int device, float* out) {
    if (device >= 0) gpu::render_forward(scene, options, device, out);
    else render_forward(scene, options, out);
}

void backward_on(const PreparedScene& scene, const SceneArrays& arrays, const RenderOptions& options,
                 const float* image, const float* d_image, double boundary_density, int device,
                 bool emulate_gpu_lists, SceneGrads& out) {
    bool limited = device >= 0 || emulate_gpu_lists, done = false;
    if (device >= 0)
        done = gpu::render_backward(scene, arrays, options, image, d_image, boundary_density, device, out);
    else if (emulate_gpu_lists)
        done = render_backward(scene, arrays, options, image, d_image, boundary_density, out, &GPU_LISTS);
    if (limited && !done) ++fallbacks;
    if (!done) render_backward(scene, arrays, options, image, d_image, boundary_density, out);
}

long backward_fallbacks() { return fallbacks.load(); }

void forward_batch(const std::vector<SceneArrays>& scenes, const RenderOptions& options,
                   const std::vector<uint64_t>& seeds, float* out) {
    const size_t pixels = (size_t)options.width * options.height;
    for_each_scene((int)scenes.size(), options.threads, [&](int b) {
        render_forward(*prepare_timed(scenes[b]), scene_options(options, seeds[b]), out + 4 * pixels * b);
    });
}

void backward_batch(const std::vector<SceneArrays>& scenes, const RenderOptions& options,
                    const std::vector<uint64_t>& seeds, const float* images, const float* d_images,
                    double boundary_density, std::vector<SceneGrads>& out) {
    const size_t pixels = (size_t)options.width * options.height;
    out.assign(scenes.size(), SceneGrads());
    for_each_scene((int)scenes.size(), options.threads, [&](int b) {
        render_backward(*prepare_timed(scenes[b]), scenes[b], scene_options(options, seeds[b]),
                        images + 4 * pixels * b, d_images + 4 * pixels * b, boundary_density, out[b]);
    });
}

}  // namespace vf
