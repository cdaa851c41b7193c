#!/bin/sh
# The GPU checks of the CUDA build, for a session that is lent a GPU (the `device` tool).
# Here, first: `make gpu-carry` (puts the svgelements wheel and the shared test data into
# .gpu/). Then run this from the repository root on the device machine, with .gpu
# carried: run(command="sh benchmarks/gpu_session.sh", carry=[".gpu"]). Its image has
# python3 with torch, pybind11, scikit-build-core, scikit-image, OpenCV and pytest.
set -eu
python3 -m pip install -q --no-index --find-links .gpu/wheels svgelements
# One architecture (the lent GPUs are Hopper) keeps the build short.
VECFIT_CUDA=1 python3 -m pip install -q --no-build-isolation --no-deps \
    -C cmake.define.CMAKE_CUDA_ARCHITECTURES=90-real -e .
export VECFIT_SHARED="$PWD/.gpu/shared"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv || echo "(no nvidia-smi)"
python3 -c "from vecfit.device import build_summary; print(build_summary())"
# GPU against CPU: images over the conformance corpus, gradients on the tiger.
python3 -m pytest -q -p no:cacheprovider tests/test_cuda.py -rs
python3 benchmarks/gpu.py --threads 16
