// What the render and points bindings share: the scene dict of vecfit/renderer/pack.py as
// the core's SceneArrays, each table checked, and gradients back as a dict.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "backward/grads.h"
#include "python/arrays.h"
#include "scene/scene.h"

namespace vf::python {

// The scene's arrays, kept alive for the duration of a call.
struct SceneInput {
    Array<float> points, point_widths, ellipses, draw_params, paint_params, stop_offsets, stop_colors, layer_opacity;
    Array<int32_t> segments, subpaths, shapes, draws, paints, layer_parents;

    SceneArrays arrays() const;
};

SceneInput scene_input(const pybind11::dict& s);

// The gradients of a scene's float arrays, as numpy arrays by the names the scene dict uses.
pybind11::dict grads_dict(const SceneGrads& g);

}  // namespace vf::python
