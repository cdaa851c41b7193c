// The scene at arbitrary points (pydiffvg's eval_positions): each point shaded as the one
// sample of a pixel centred on it, in the analytical mode (the kernel of radius r around
// the point itself), and the adjoint of that with respect to the scene and the points.
// One call for all the points: one 1 x 1 render per point cost ~1 ms of set-up each.
#pragma once

#include "backward/grads.h"
#include "forward/forward.h"
#include "scene/scene.h"

namespace vf {

// xy: n points (x, y) in pixel space; out: n x 4 straight RGBA (no background).
void render_points(const PreparedScene& scene, const RenderOptions& options, const double* xy, int n, float* out);

// colours: render_points' output; d_colours: dL/d(colours). Adds dL/d(scene floats) into
// `out` (sized like the arrays) and writes dL/d(xy) into d_xy (n x 2).
void render_points_backward(const PreparedScene& scene, const SceneArrays& arrays, const RenderOptions& options,
                            const double* xy, int n, const float* colours, const float* d_colours, SceneGrads& out,
                            double* d_xy);

}  // namespace vf
