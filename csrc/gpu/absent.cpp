// gpu.h for a build without CUDA (the default): nothing compiled, no devices.
#ifndef VECFIT_WITH_CUDA
#include <stdexcept>

#include "gpu/gpu.h"

namespace vf {
namespace gpu {

bool compiled() { return false; }
int device_count() { return 0; }
std::string build_info() { return "CUDA: not compiled (rebuild with VECFIT_CUDA=1 to compile it)"; }

void render_forward(const PreparedScene&, const RenderOptions&, int, float*) {
    throw std::runtime_error("this vecfit was built without CUDA (rebuild with VECFIT_CUDA=1)");
}

bool render_backward(const PreparedScene&, const SceneArrays&, const RenderOptions&, const float*, const float*,
                     double, int, SceneGrads&) {
    throw std::runtime_error("this vecfit was built without CUDA (rebuild with VECFIT_CUDA=1)");
}

}  // namespace gpu
}  // namespace vf
#endif
