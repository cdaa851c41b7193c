// Ctrl-C during the core's work: the work runs on another thread while this one, every
// 50 ms, lets Python run its signal handlers. A Ctrl-C cancels the work (the thread pool
// skips the tasks not started, see common/cancel.h) and raises KeyboardInterrupt here,
// instead of waiting, deaf, for a render that may take minutes. Called with the GIL held;
// releases it while waiting.
#pragma once

#include <pybind11/pybind11.h>

#include <chrono>
#include <future>
#include <utility>

#include "common/cancel.h"

namespace vf {

template <class Work>
void interruptible(Work&& work) {
    namespace py = pybind11;
    std::future<void> done = std::async(std::launch::async, std::forward<Work>(work));
    py::gil_scoped_release release;
    while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) {
            cancel_requested().store(true);
            done.wait();
            cancel_requested().store(false);
            throw py::error_already_set();
        }
    }
    done.get();  // the core's exceptions, rethrown here
}

}  // namespace vf
