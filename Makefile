# Set-up and the two everyday jobs. Everything runs in a local virtual environment.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.vecfit-installed
# A CPU build of torch: an unpinned torch would pull gigabytes of CUDA packages.
TORCH := torch==2.13.0

.PHONY: install demo test test-fast fuzz sanitize bench gpu-carry clean

install: $(STAMP)

# Everything under csrc/, subfolders included (a folder too: adding, removing or renaming
# a file in it changes its time).
CSRC := $(shell find csrc)

$(STAMP): pyproject.toml CMakeLists.txt $(CSRC)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q $(TORCH)
	$(PY) -m pip install -q -e ".[dev]"
	touch $@

demo: install
	$(VENV)/bin/vecfit trace examples/chelsea.png -o out/chelsea.svg

test: install
	$(PY) -m pytest -q

# The tests marked slow left out (whole fits and traces, batches, the wheel, interruptions,
# the fuzzer's quick run, the shared data, oracle sweeps past a few cases): under a minute.
# Bytecode is cached even where the shell says not to (PYTHONDONTWRITEBYTECODE): the loop a
# developer reruns then compiles nothing twice (8 s of its minute).
test-fast: install
	PYTHONDONTWRITEBYTECODE= $(PY) -m pytest -q -m "not slow"

# A long fuzzing campaign (tests/fuzz/fuzzing.py): N cases from SEED, a summary table; failures
# are kept under tests/failures/fuzz/.
N ?= 2000
SEED ?= 1
fuzz: install
	$(PY) tests/fuzz/fuzzing.py -n $(N) --seed $(SEED)

# The core built with AddressSanitizer and UndefinedBehaviorSanitizer in its own folder,
# then the core's tests, the conformance corpus and the fuzzer's quick run through it
# (tests/sanitize/sitecustomize.py loads that build in place of the installed one; ASan
# must be preloaded into Python, and leak checking is off: Python itself "leaks").
SANITIZE_BUILD := build/sanitize
SANITIZE_TESTS := tests/unit/renderer/test_render_basics.py tests/unit/renderer/test_degenerate.py \
	tests/oracles/test_render_vs_reference.py tests/oracles/test_gradients.py \
	tests/unit/renderer/test_point_widths.py tests/oracles/test_golden.py tests/oracles/test_conformance.py \
	tests/fuzz/test_hostile.py tests/fuzz/test_fuzz.py tests/unit/renderer/test_long_paths.py \
	tests/unit/pydiffvg/test_pydiffvg_scripts.py tests/unit/initial/test_tracer_merge.py \
	tests/unit/initial/test_tracer_fit.py tests/unit/initial/test_tracer_subpixel.py \
	tests/oracles/test_fig9.py tests/oracles/test_filter_radius.py
sanitize: install
	$(PY) -m pip install -q pybind11
	cmake -S . -B $(SANITIZE_BUILD) -DVECFIT_SANITIZE=ON -DCMAKE_BUILD_TYPE=Release \
		-DPython_EXECUTABLE=$(abspath $(PY)) -Dpybind11_DIR=$$($(PY) -m pybind11 --cmakedir)
	cmake --build $(SANITIZE_BUILD) -j
	LD_PRELOAD="$$(gcc -print-file-name=libasan.so) $$(gcc -print-file-name=libubsan.so)" \
	ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 PYTHONPATH=tests/sanitize \
	VECFIT_CORE="$$(ls $(abspath $(SANITIZE_BUILD))/_core*.so)" $(PY) -m pytest -q -p no:cacheprovider $(SANITIZE_TESTS)

bench: install
	$(PY) benchmarks/render.py
	$(PY) benchmarks/gradients.py
	$(PY) benchmarks/refine.py
	$(PY) benchmarks/trace.py
	$(PY) benchmarks/paint.py
	$(PY) benchmarks/edit.py
	$(PY) benchmarks/retarget.py

# A GPU session (the `device` tool): the device machine reaches no registry and does not
# see ../shared, so what it needs travels in .gpu/ (carry [".gpu"]); there, run
# benchmarks/gpu_session.sh.
SHARED ?= $(or $(VECFIT_SHARED),../shared)
gpu-carry: install
	rm -rf .gpu && mkdir -p .gpu/wheels .gpu/shared/data
	$(PY) -m pip download -q --no-deps -d .gpu/wheels svgelements
	cp -r $(SHARED)/conformance .gpu/shared/
	cp -r $(SHARED)/data/scenes .gpu/shared/data/

clean:
	rm -rf build out tests/failures .gpu
