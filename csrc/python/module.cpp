// vecfit._core: each op family binds its own functions (python/bind.h); what describes the
// build itself is here.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "common/thread_pool.h"
#include "gpu/gpu.h"
#include "python/bind.h"
#include "python/test_hooks.h"

namespace py = pybind11;
using namespace vf;

PYBIND11_MODULE(_core, m) {
    m.doc() = "vecfit's compiled core: geometry and rendering on flat arrays";
    bind_render(m);
    bind_points(m);
    bind_trace(m);

    m.def("hardware_threads", &ThreadPool::hardware_threads);
    m.def("has_cuda", &gpu::compiled, "Whether this build has the CUDA kernels");
    m.def("cuda_device_count", &gpu::device_count, "CUDA devices usable now (0 without a CUDA build)");
    m.def("build_info", [] {
        py::dict info;
        info["compiler"] = std::string(
#if defined(__clang__)
            "clang " __clang_version__
#elif defined(__GNUC__)
            "gcc " __VERSION__
#else
            "unknown"
#endif
        );
        info["cuda"] = gpu::build_info();
#ifdef VECFIT_WITH_CUDA
        info["cuda_archs"] = std::string(VECFIT_CUDA_ARCHS);
#else
        info["cuda_archs"] = std::string();
#endif
        info["hardware_threads"] = ThreadPool::hardware_threads();
        return info;
    });

    register_test_hooks(m);  // python/test_hooks.cpp: what only the tests call
}
