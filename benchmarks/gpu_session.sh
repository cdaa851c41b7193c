#!/bin/sh
# The GPU checks of the CUDA build, for a session that is lent a GPU (the `device` tool).
# Here, first: `make gpu-carry` (puts the svgelements wheel and the shared test data into
# .gpu/). Then, from the repository root on the device machine, with .gpu carried:
#     run(command="sh benchmarks/gpu_session.sh", carry=[".gpu"])
# or, should the two together run past one call's time limit, as two calls:
#     sh benchmarks/gpu_session.sh test      and      sh benchmarks/gpu_session.sh bench
# (each builds the core first unless a CUDA build is already installed there). The device
# image has python3 with torch, pybind11, scikit-build-core, CMake, ninja, numpy, Pillow,
# click, scikit-image, OpenCV and pytest; svgelements comes from .gpu/wheels.
set -u
phase=${1:-all}
python3 -m pip install -q --no-index --find-links .gpu/wheels svgelements || exit 1
if ! python3 -c "import sys, vecfit; sys.exit(0 if vecfit.has_cuda() else 1)" 2>/dev/null; then
    # One architecture (the lent GPUs are Hopper) keeps the build short.
    VECFIT_CUDA=1 python3 -m pip install -q --no-build-isolation --no-deps \
        -C cmake.define.CMAKE_CUDA_ARCHITECTURES=90-real -e . || exit 1
fi
export VECFIT_SHARED="$PWD/.gpu/shared"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv || echo "(no nvidia-smi)"
# A CUDA build that sees no device would skip every GPU test: stop here instead, saying why.
python3 -c "
import sys, vecfit
from vecfit.renderer.device import build_summary
print(build_summary())
sys.exit(0 if vecfit.cuda_device_count() > 0 else 'no CUDA device is visible to vecfit')" || exit 1
status=0
if [ "$phase" = all ] || [ "$phase" = test ]; then
    # GPU against CPU: images over the conformance corpus, gradients on the tiger, and the
    # GPU list sizes. (The nvcc compile checks run in CI; they are skipped here.)
    python3 -m pytest -q -p no:cacheprovider tests/oracles/test_cuda.py -rs -k "not compiles" || status=1
fi
if [ "$phase" = all ] || [ "$phase" = bench ]; then
    python3 benchmarks/gpu.py --threads 16 || status=1
fi
exit $status
