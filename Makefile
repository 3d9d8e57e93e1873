# implc — the two commands a newcomer needs: `make demo` and `make test`.
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.implc-installed
OUT := out
# Debian packages: glslangValidator, headless EGL/Mesa for moderngl (llvmpipe),
# Vulkan loader + lavapipe for wgpu, Debian's PoCL (its LLVM 15 builds for CPUs the PoCL wheel
# cannot name, e.g. AMD Zen 5: see implc/render/cl_runner.py device()), Chromium for the
# browser tests (WebGL2 and WebGPU on SwiftShader, driven by Playwright for Python from the
# test extras).
APT_PACKAGES := glslang-tools spirv-cross libegl1 libegl-mesa0 libgl1-mesa-dri mesa-vulkan-drivers libvulkan1 \
  pocl-opencl-icd chromium
# three.js, an ISF renderer, the WESL linker and Godot 4's web build for the browser tests,
# pinned in tests/browser/package-lock.json (npm ci; no install scripts: none of them
# needs one, and the Godot package's would copy its build into the project's root).
NPM_DIR := tests/browser
NPM_STAMP := $(NPM_DIR)/node_modules/.implc-installed
VIEW_SURFACE := torus
# Slang's compiler (slangc), the second HLSL front end of the Unity and Unreal host tests
# (tests/host_harness.py): the slangtorch wheel ships it, installed with --no-deps (its
# torch is not needed for the compiler).
SLANGTORCH := 1.3.22

.PHONY: setup demo view test golden lint bench bench-baseline forms clean system-packages fuzz corpus \
  compile-times startup docs

setup: system-packages $(STAMP) $(NPM_STAMP)

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
	$(PY) -m pip install -q -e '.[test,plots]'
	$(PY) -m pip install -q --no-deps 'slangtorch==$(SLANGTORCH)'
	touch $(STAMP)

$(NPM_STAMP): $(NPM_DIR)/package.json $(NPM_DIR)/package-lock.json
	@command -v npm >/dev/null || { echo "installing Debian packages: nodejs npm"; \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq nodejs npm >/dev/null; }
	cd $(NPM_DIR) && npm ci --no-audit --no-fund --ignore-scripts --loglevel=error
	touch $@

demo: setup
	@mkdir -p $(OUT)
	$(PY) -m implc compile cross-cap -t glsl -m exact --validate -o $(OUT)/cross-cap-exact.frag
	$(PY) -m implc render cross-cap -m exact --size 512 -o $(OUT)/cross-cap-exact.png
	@echo "demo: look at $(CURDIR)/$(OUT)/cross-cap-exact.png (shader: $(OUT)/cross-cap-exact.frag)"

# The live viewer (after `make demo`): one self-contained HTML page; open it in a browser.
view: setup
	@mkdir -p $(OUT)
	$(PY) -m implc view $(VIEW_SURFACE) -o $(OUT)/$(VIEW_SURFACE).html
	@echo "view: open file://$(CURDIR)/$(OUT)/$(VIEW_SURFACE).html in a browser (drag to turn, sliders move the parameters)"

test: lint
	$(PY) -m pytest

# The documentation site (mkdocs.yml, pages under docs/) into site/, strictly: a broken
# link or anchor, a page missing from the nav or a missing included file fails the build.
# Offline: the theme comes from the `docs` extra, no plugin fetches, no web font.
docs: setup
	NO_MKDOCS_2_WARNING=1 $(PY) -m mkdocs build --strict --quiet -d site

# The command line's reference page, written from the parser (tests/test_docs.py fails
# when the committed page is stale).
.PHONY: cli-reference
cli-reference: setup
	$(PY) scripts/cli_reference.py docs/reference

# Rewrite every golden shader (every target of implc/targets.py) from the current output;
# review the diff.
# Each new text is validated by its real compiler before it is written (an invalid one is
# refused), emitted twice (same bytes), and every golden file is validated again after.
golden: setup
	$(PY) -m pytest tests/test_golden.py --update-golden

# ruff; mypy --strict over the public API (implc/__init__.py, implc/api/); and node's parser over the viewer's script (templates/view/viewer.js, which
# viewer.html.j2 includes), so a syntax error there fails here, not in a user's browser.
JS_SOURCES := $(sort $(wildcard templates/*/*.js templates/*/*.mjs))
lint: setup
	$(PY) -m ruff check implc tests
	$(PY) -m mypy --strict --follow-imports=silent --ignore-missing-imports --no-error-summary \
	  implc/__init__.py implc/version.py implc/api
	@for f in $(JS_SOURCES); do node --check $$f || exit 1; done

# The paper's Table 1 into results/, and its tables into docs/RESULTS.md in place. 1024x1024 like the paper: on this
# 2-core llvmpipe machine the costliest cell (curvature at b = 0.002) takes ~1.3 s a
# frame, and the whole run (3 surfaces x 4 configurations, 6 frames per cell) ~2 min.
BENCH_SIZE := 1024
bench: setup
	$(PY) -m implc bench cross-cap miter steiner --size $(BENCH_SIZE) --frames 5 -o results/
	$(PY) scripts/docs_section.py bench results/table.md --write docs/RESULTS.md

# Generated against the hand-written GLSL of templates/baseline/ (Cross-Cap, taylor and
# hessian), frames taken in turns: paper = taylor b 0.01 and hessian b 0.002, equal = both
# at b 0.01; at 512^2 and 1024^2 (issue 10's bar: generated >= 0.95x hand-written).
bench-baseline: setup
	for size in 512 1024; do \
	  $(PY) -m implc bench cross-cap --baseline --methods taylor hessian exact \
	    --configs paper,equal --equal-step 0.01 --size $$size --frames 5 \
	    -o results/baseline-$$size/ || exit 1; \
	done

# Point versus ray-poly evaluation (accuracy, speed), and the degree sweep (exact against
# taylor and hessian, degree 2-20, docs/RESULTS.md, "The degree sweep") with its plot: ~50 minutes.
forms: setup
	$(PY) scripts/eval_forms.py accuracy --size 512 cross-cap miter steiner roman torus tooth \
	  sphere kummer cayley clebsch ding-dong whitney-umbrella barth-sextic heart
	@mkdir -p results
	$(PY) scripts/eval_forms.py sweep --size 512 --frames 5 --degrees 2-20 --plot docs/cost-growth.png \
	  > results/forms-sweep.md
	$(PY) scripts/docs_section.py forms-sweep results/forms-sweep.md --write docs/RESULTS.md \
	  --command "make forms"

# exact in float32 on every float32 renderer (issue 48): wrong pixels against the certified
# reference on gl, wgpu, cl, hlsl-spirv and Chromium's webgl2 and webgpu, Chmutov T_2..T_20
# and the gallery's rows at 512^2, written into docs/results-float32.md. The references are
# cached in results/reference-cache/: about 2 hours the first time, 15 minutes after.
.PHONY: float32-renderers
float32-renderers: setup
	$(PY) scripts/float32_renderers.py --size 512 --degrees 2-20 --gallery \
	  --write docs/results-float32.md

# What AMD's compiler makes of the degree sweep (issue 49): RADV's ACO statistics on null
# devices (no GPU needed) of Chmutov T_2..T_20's programs, every method, float and double,
# written into docs/results-gpu.md, "What a GPU's compiler says" (scripts/gpu_stats_table.py). About 2 minutes.
.PHONY: gpu-stats-table gpu-bench
gpu-stats-table: setup
	$(PY) scripts/gpu_stats_table.py --write docs/results-gpu.md

# implc's exact against Yuksel's first-root solver written by hand, spill-free (issue 49):
# Chmutov T4, T10, T16, T20 and Barth's decic at 512^2 in turns, counts against the
# certified reference (smaller at T16 and T20, whose reference takes hours at 512^2), ACO
# statistics; written into docs/results-gpu.md. About 15 minutes.
.PHONY: yuksel-baseline
yuksel-baseline: setup
	$(PY) scripts/yuksel_baseline.py --size 512 --frames 5 --degrees 4,10,16,20 \
	  --count-size 512,16=128,20=96 barth-decic --write docs/results-gpu.md

# For a machine with a real GPU: the frame table of every method over Chmutov T_2..T_20
# and the hand-written baselines at 1024^2 and 2048^2, the device named
# (scripts/gpu_bench.py; GPU_BACKEND=wgpu for Vulkan/Metal/D3D12 through wgpu).
GPU_BACKEND := gl
gpu-bench: setup
	$(PY) scripts/gpu_bench.py --backend $(GPU_BACKEND) --sizes 1024,2048 --degrees 2-20 --frames 10

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

# -m interval over the corpus's non-polynomial rows that compile today with the default
# method: compiled for glsl, wgsl and opencl and validated, or refused with the reason; the
# summary also as Markdown in out/corpus-interval.md. 1-2 minutes with 2 workers (53-130 s measured).
.PHONY: corpus-interval
corpus-interval: setup
	@mkdir -p $(OUT)
	$(PY) scripts/corpus_interval.py -j 2 -o $(OUT)/corpus-interval.md

# Compile time of every corpus row as a user meets it (`implc compile -e ROW`, default
# method, GLSL, a fresh process each, two at a time): the distribution and the slowest
# ten (docs/RESULTS.md, "Compile time on the corpus"). About 2 minutes on 2 cores.
compile-times: setup
	$(PY) scripts/compile_times.py -j 2

# Start-up time of `import implc` beside `implc --help`, of `COMMAND --help` and `--version`
# (goal: under 0.15 s; no sympy or numpy is imported for them) and of `list` and `show`
# for comparison: medians of 7 fresh processes each, as a table. About 30 s.
startup: setup
	$(PY) scripts/startup.py

# The docs' gallery pictures (docs/gallery-examples.png, docs/gallery-corpus.png):
# `implc gallery` of the bundled examples and of 24 corpus rows at 96 pixels. About 20 s.
.PHONY: gallery-pictures
gallery-pictures: setup
	$(PY) scripts/gallery_pictures.py

# The docs' notebook figure (docs/notebook-widget.png): tests/test_jupyterlab.py's
# screenshot of the tour's widget cell in JupyterLab. About 30 s.
.PHONY: notebook-picture
notebook-picture: setup
	IMPLC_SCREENSHOTS=docs $(PY) -m pytest tests/test_jupyterlab.py -q

.PHONY: three-picture
three-picture: setup
	IMPLC_SCREENSHOTS=docs $(PY) -m pytest tests/test_host_three.py -q -k "torus and webgpu and not webgl2"

clean:
	rm -rf $(OUT) site build dist *.egg-info .pytest_cache .ruff_cache $(NPM_DIR)/node_modules
