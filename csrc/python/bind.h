// The module vecfit._core (module.cpp) is bound op family by op family, each in its own
// file: the renderer (bind_render.cpp), the scene at points (bind_points.cpp), the tracer
// (bind_trace.cpp), and what only the tests call (test_hooks.cpp).
#pragma once

#include <pybind11/pybind11.h>

void bind_render(pybind11::module_& m);
void bind_points(pybind11::module_& m);
void bind_trace(pybind11::module_& m);
