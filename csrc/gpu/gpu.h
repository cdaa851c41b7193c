// The CUDA build's entry points, declared for every build: a CPU-only build defines them
// in gpu/absent.cpp (they report that CUDA was not compiled in), a CUDA build in
// csrc/cuda/. Nothing here needs CUDA's headers, so the bindings stay plain C++.
#pragma once

#include <string>

#include "backward/grads.h"
#include "forward/forward.h"
#include "scene/scene.h"

namespace vf {
namespace gpu {

bool compiled();            // was this build made with VECFIT_CUDA
int device_count();         // CUDA devices this process can use (0 without CUDA)
std::string build_info();   // architectures and CUDA versions, for `vecfit info --build`

// As render_forward, on CUDA device `device`: the scene is prepared and binned on the
// host, uploaded, and every pixel shaded by the same pixel_forward as on the CPU.
void render_forward(const PreparedScene& scene, const RenderOptions& options, int device, float* out);

// As render_backward (backward.h), on CUDA device `device`. Returns false, with `out`
// unset, when a sample needed longer lists than a GPU thread holds: the caller redoes the
// pass on the CPU.
bool render_backward(const PreparedScene& scene, const SceneArrays& arrays, const RenderOptions& options,
                     const float* image, const float* d_image, double boundary_density, int device,
                     SceneGrads& out);

}  // namespace gpu
}  // namespace vf
