// The test-only functions of vecfit._core (geometry called directly by the tests, and the
// switches below), kept apart from the bindings of the real API.
#pragma once

#include <pybind11/pybind11.h>

void register_test_hooks(pybind11::module_& m);

// What the tests switch on through the hooks (_core.brute_force, _core.emulate_gpu_lists)
// and the render bindings read, so that no production signature carries a test's flag.
struct TestSwitches {
    bool brute_force = false;        // RenderOptions made now test every draw at every sample
    bool emulate_gpu_lists = false;  // render_grad runs the CPU lanes with a GPU thread's lists first
};
TestSwitches& test_switches();
