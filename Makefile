# implc — the two commands a newcomer needs: `make demo` and `make test`.
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.implc-installed
OUT := out
# Debian packages: glslangValidator, headless EGL/Mesa for moderngl (llvmpipe),
# Vulkan loader + lavapipe for wgpu, Debian's PoCL (its LLVM 15 builds for CPUs the PoCL wheel
# cannot name, e.g. AMD Zen 5: see implc/render/cl_runner.py device()).
APT_PACKAGES := glslang-tools libegl1 libegl-mesa0 libgl1-mesa-dri mesa-vulkan-drivers libvulkan1 \
  pocl-opencl-icd

.PHONY: setup demo test golden lint bench clean system-packages fuzz corpus

setup: system-packages $(STAMP)

system-packages:
	@missing=""; for p in $(APT_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing >/dev/null; \
	fi

$(STAMP): pyproject.toml
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[test]'
	touch $(STAMP)

demo: setup
	@mkdir -p $(OUT)
	$(PY) -m implc compile cross-cap -t glsl -m hessian --validate -o $(OUT)/cross-cap-hessian.frag
	$(PY) -m implc render cross-cap -m hessian --size 512 -o $(OUT)/cross-cap-hessian.png
	@echo "demo: look at $(CURDIR)/$(OUT)/cross-cap-hessian.png (shader: $(OUT)/cross-cap-hessian.frag)"

test: setup
	$(PY) -m ruff check implc tests
	$(PY) -m pytest

# Rewrite every golden shader (GLSL, WGSL, OpenCL) from the current output; review the diff.
# Each new text is validated by its real compiler before it is written (an invalid one is
# refused), emitted twice (same bytes), and every golden file is validated again after.
golden: setup
	$(PY) -m pytest tests/test_golden.py tests/test_wgsl.py tests/test_opencl.py \
	  -k "golden" --update-golden

lint: setup
	$(PY) -m ruff check implc tests

# The paper's Table 1 into results/ (docs/RESULTS.md). 1024x1024 like the paper: on this
# 2-core llvmpipe machine one cross-cap hessian frame takes ~6 s (~38 M march steps/s), the
# costliest cell (curvature at b = 0.002) ~20 s a frame, and the whole run (3 surfaces x
# 3 configurations, 4 frames per cell) measured 7.5-11 min, within the ~20 min budget.
BENCH_SIZE := 1024
bench: setup
	$(PY) -m implc bench cross-cap miter steiner --size $(BENCH_SIZE) --frames 3 -o results/

# Fuzzing (tests/test_fuzz.py) at FUZZ_SCALE times the short pass that `make test` runs
# (FUZZ_PATH_SCALE for the slower whole-path tests), a fresh seed each run: 100,000+
# parser cases (grammar + mutation) and ~4,600 whole-path cases (parse, derive, CSE,
# GLSL; 500 shaders validated by glslangValidator). It prints its counts and time.
FUZZ_SCALE := 100
FUZZ_PATH_SCALE := 20
fuzz: setup
	IMPLC_FUZZ_SCALE=$(FUZZ_SCALE) IMPLC_FUZZ_PATH_SCALE=$(FUZZ_PATH_SCALE) \
	  $(PY) -m pytest tests/test_fuzz.py -p no:cacheprovider -q -s \
	  -W ignore::hypothesis.errors.HypothesisWarning

# The corpus report (docs/CORPUS.md) from ../shared/corpus/ (40-70 s with 2 workers).
corpus: setup
	$(PY) -m implc corpus -j 2 -o docs/CORPUS.md

clean:
	rm -rf $(OUT) build dist *.egg-info .pytest_cache .ruff_cache
