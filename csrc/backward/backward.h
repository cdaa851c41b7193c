// Backward pass: gradients of a loss with respect to the core's float inputs, given the
// loss's gradient with respect to the rendered (straight RGBA) image.
#pragma once

#include <vector>

#include "backward/boundary.h"
#include "backward/grads.h"
#include "backward/pixel.h"
#include "forward/forward.h"
#include "scene/scene.h"
#include "scene/tiles.h"

namespace vf {

// The lists a sample's work keeps: the draws hit at a point, and the compositing tape.
struct ListSizes {
    int hits, ops;
};
// What a GPU thread holds (csrc/cuda/backward.cu). A sample that needs more flags an
// overflow, and the host redoes the pass on the CPU, whose lists are sized to the scene.
constexpr ListSizes GPU_LISTS{32, 96};

// image: the forward output; d_image: dL/d(image), both height x width x 4 straight RGBA.
// boundary_density: boundary samples per pixel of boundary length (Monte Carlo mode; the
// analytical prefilter has no boundary term).
// fixed: null to size the lists to the scene (they cannot overflow), or fixed sizes, as
// a GPU thread has them (to check on the CPU what a GPU run would do). Returns false, with
// `out` unset, when a sample overflowed them.
bool render_backward(const PreparedScene& scene, const SceneArrays& arrays, const RenderOptions& options,
                     const float* image, const float* d_image, double boundary_density, SceneGrads& out,
                     const ListSizes* fixed = nullptr);

// What the per-sample work needs besides the scene, made on the host for the CPU lanes
// and the CUDA kernels alike.
struct BackwardPlan {
    RenderOptions options;          // filter radius settled, samples >= 1
    TileBins bins;
    std::vector<double> gpix;       // dL/d(premultiplied colour) of each pixel
    std::vector<Piece> pieces;      // Monte Carlo: the boundary pieces, with their sample counts
    BoundaryContext boundary;       // (its gpix points into this plan's)
    int max_hits = 1, max_ops = 1;  // list sizes no sample can exceed
};
BackwardPlan plan_backward(const PreparedScene& scene, const RenderOptions& options, const float* image,
                           const float* d_image, double boundary_density);

}  // namespace vf
