// The core's passes as its callers use them: the scene prepared (and timed), the forward
// and backward passes on a chosen device, with the CPU taking over a backward pass that
// outgrows a GPU thread's lists, and batches of scenes run in parallel over the scenes.
// What the Python bindings call; nothing here knows Python.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "backward/grads.h"
#include "forward/forward.h"
#include "scene/scene.h"

namespace vf {

// The scene prepared for the passes (timed as the prepare phase).
std::shared_ptr<const PreparedScene> prepare_timed(const SceneArrays& arrays);

// The forward pass on CUDA device `device`, or on the CPU for device < 0.
void forward_on(const PreparedScene& scene, const RenderOptions& options, int device, float* out);

// The backward pass on CUDA device `device`, or on the CPU for device < 0. Where a sample
// needs longer lists than a GPU thread holds, the pass is redone on the CPU and counted
// (backward_fallbacks). emulate_gpu_lists runs the CPU lanes with a GPU thread's lists
// first, to see on the CPU what a GPU run would do.
void backward_on(const PreparedScene& scene, const SceneArrays& arrays, const RenderOptions& options,
                 const float* image, const float* d_image, double boundary_density, int device,
                 bool emulate_gpu_lists, SceneGrads& out);

// Backward passes redone on the CPU so far.
long backward_fallbacks();

// A batch of scenes at one size and one set of options, each with its own seed: the
// scenes in parallel on up to options.threads threads, one scene per thread at a time.
// For training loops that render many small scenes a step, where one call per scene
// would cost more than its pixels. The first error (in scene order) is raised after all
// have run. out: n images of height x width x 4, one after the other.
void forward_batch(const std::vector<SceneArrays>& scenes, const RenderOptions& options,
                   const std::vector<uint64_t>& seeds, float* out);

// The gradients of a batch made by forward_batch (images, d_images: n x height x width x 4).
void backward_batch(const std::vector<SceneArrays>& scenes, const RenderOptions& options,
                    const std::vector<uint64_t>& seeds, const float* images, const float* d_images,
                    double boundary_density, std::vector<SceneGrads>& out);

}  // namespace vf
