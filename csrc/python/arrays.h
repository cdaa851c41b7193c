// numpy arrays as the bindings take them: C-contiguous (converted on the way in if need
// be), and read as tables of rows of a given width.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <stdexcept>
#include <string>

namespace vf::python {

template <typename T>
using Array = pybind11::array_t<T, pybind11::array::c_style | pybind11::array::forcecast>;

// A table of rows `cols` wide: its row count n and data. A table of two or more dimensions
// must have rows of that width; a flat one must hold whole rows.
template <typename T>
const T* rows(const Array<T>& a, int cols, int& n, const char* name) {
    if (a.size() == 0) {
        n = 0;
        return nullptr;
    }
    if ((a.ndim() >= 2 && a.shape(a.ndim() - 1) != cols) || a.size() % cols != 0) {
        std::string shape;
        for (pybind11::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
        throw std::invalid_argument(std::string("vecfit core: ") + name + " has the wrong shape: rows of " +
                                    std::to_string(cols) + " expected, not [" + shape + "]");
    }
    n = (int)(a.size() / cols);
    return a.data();
}

}  // namespace vf::python
