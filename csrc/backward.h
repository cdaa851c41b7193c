// Backward pass: gradients of a loss with respect to the core's float inputs, given the
// loss's gradient with respect to the rendered (straight RGBA) image.
#pragma once

#include "grads.h"
#include "paint.h"
#include "render.h"
#include "scene.h"

namespace vf {

// image: the forward output; d_image: dL/d(image), both height x width x 4 straight RGBA.
// boundary_density: boundary samples per pixel of boundary length (Monte Carlo mode; the
// analytical prefilter has no boundary term).
void render_backward(const PreparedScene& scene, const SceneArrays& arrays, const RenderOptions& options,
                     const float* image, const float* d_image, double boundary_density, SceneGrads& out);

}  // namespace vf
