// The test-only functions of vecfit._core (geometry called directly by the tests), kept
// apart from the bindings of the real API.
#pragma once

#include <pybind11/pybind11.h>

void register_test_hooks(pybind11::module_& m);
