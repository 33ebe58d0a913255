# Texel's front door. `make demo` and `make test` each do the whole set-up on
# a fresh Debian 12 machine: install missing packages, configure, build, run.
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BUILD := build
PY := /usr/bin/python3

.PHONY: all deps deps-web configure build cli python wheel web web-test demo test test-unit test-browser test-asan test-determinism bench fuzz tidy format clean

all: build

# Debian packages. The library, the CLI and the Python package need no
# Node.js; `deps-web` also requires Node.js >= 20 with npm, for Texel Studio's
# front end (web, demo, test, bench), and says so when it is missing.
deps:
	@bash scripts/install-deps.sh

deps-web: deps
	@bash scripts/check-node.sh

configure: deps
	@cmake --preset release >/dev/null

# Every target: libraries, CLI, tests, benchmarks, examples, Python package.
build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# The texel command alone (and the libraries it links): what `make demo` runs.
cli: configure
	@cmake --build $(BUILD) -j $(JOBS) --target texel_cli

# The Python package texel (python/README.md): build/python/texel, for
# PYTHONPATH=build/python /usr/bin/python3.
python: configure
	@cmake --build $(BUILD) -j $(JOBS) --target texel_python

# A wheel of the package (python/setup.py), in build/wheel/, from the
# extension `make python` built: install it with
#   pip install --no-build-isolation build/wheel/texel-*.whl
# Offline: Debian's pip, setuptools and wheel, no build isolation, no index.
wheel: python
	rm -f $(BUILD)/wheel/texel-*.whl
	TEXEL_CMAKE_BUILD_DIR=$(CURDIR)/$(BUILD) $(PY) -m pip wheel --no-build-isolation --no-index --no-deps -q -w $(BUILD)/wheel ./python
	@ls -l $(BUILD)/wheel/texel-*.whl

# Texel Studio's front end (web/, TypeScript + Vite + uPlot), built once into
# build/web and rebuilt only when its sources or lockfile change. `npm ci`
# installs exactly the committed lockfile from the npm registry; nothing else
# is downloaded (the browser tests drive Debian's chromium).
WEB_OUT := $(BUILD)/web
WEB_SRC := $(shell find web -path web/node_modules -prune -o -path web/tests -prune -o -path web/src/generated -prune -o -type f -print 2>/dev/null)

web: $(WEB_OUT)/index.html

web/node_modules/.package-lock.json: web/package-lock.json | deps-web
	cd web && npm ci --no-audit --no-fund --loglevel=error

$(WEB_OUT)/index.html: web/node_modules/.package-lock.json $(WEB_SRC) docs/schema/studio-messages.schema.json docs/schema/texel-protocol.schema.json
	cd web && TEXEL_WEB_OUT=$(CURDIR)/$(WEB_OUT) npm run --silent build

# The test build: the same front end plus the browser tests' hooks
# (window.__texelStats); only the browser tests and the latency bench serve it.
WEB_TEST_OUT := $(BUILD)/web-test
web-test: $(WEB_TEST_OUT)/index.html
$(WEB_TEST_OUT)/index.html: web/node_modules/.package-lock.json $(WEB_SRC) docs/schema/studio-messages.schema.json docs/schema/texel-protocol.schema.json
	cd web && TEXEL_WEB_OUT=$(CURDIR)/$(WEB_TEST_OUT) npm run --silent build:test

# The studies (issue #8): a simulated cohort of 8 participants through every
# shipped protocol (free exploration before the quantization test that uses
# its matches), then each study's summaries and figures. The 2-D
# direction-independence study runs short: two simulated participants (~10 s).
PROTOCOLS := $(addprefix examples/protocols/,free-exploration.json quantization.json parameter-mapping.json \
  guided-exploration.json coarse-features.json working-memory.json working-memory-components.json \
  distributed-irregularity.json)
# Texel length is a between-groups study: each group has its own participants.
TEXEL_LENGTH_GROUPS := N:texel-length W:texel-length-wide V:texel-length-visual-practice

# The demo builds only what it runs: the texel command and the studio's
# bundle (not the tests, benchmarks, examples or Python package; `make test`
# builds those later in the same build/, reusing what the demo compiled).
demo: deps-web cli web
	$(BUILD)/bin/texel demo --out out/demo
	$(BUILD)/bin/texel atlas --out out/demo/references
	rm -rf out/demo/experiments && mkdir -p out/demo/experiments
	$(BUILD)/bin/texel experiment cohort $(PROTOCOLS) --participants 8 --db out/demo/experiments/cohort.db
	for g in $(TEXEL_LENGTH_GROUPS); do $(BUILD)/bin/texel experiment cohort examples/protocols/$${g#*:}.json \
	  --participants 8 --prefix $${g%%:*} --db out/demo/experiments/cohort.db || exit 1; done
	$(BUILD)/bin/texel experiment cohort examples/protocols/direction-independence.json --participants 2 --prefix D \
	  --db out/demo/experiments/cohort.db
	$(BUILD)/bin/texel experiment export --db out/demo/experiments/cohort.db -o out/demo/experiments/trials.csv
	$(BUILD)/bin/texel experiment analyze --db out/demo/experiments/cohort.db -o out/demo/experiments > out/demo/experiments/summary.txt
	@cat out/demo/experiments/summary.txt
	@echo "Texel Studio is built: $(BUILD)/bin/texel studio --port 8080  (then open http://127.0.0.1:8080/)"

# Every test: unit and CLI tests (release build, GCC), the same under
# AddressSanitizer + UndefinedBehaviorSanitizer (clang, without the `slow`
# label), and byte-identity of the demo set across GCC/clang, -O0/-O3 and SIMD
# widths. What each phase proves and costs: docs/testing.md.
test: deps-web test-unit test-browser test-asan test-determinism

# The glTF-Validator test (tests/interchange) runs Khronos' validator from
# web/node_modules: the same one `npm ci` as the web build.
# Third-party test data (MPEG-I Haptics schemas and reference-software files)
# is read from $(TEXEL_THIRD_PARTY) when given (.ci/run sets it); the tests
# that need it are skipped, saying so, without it.
test-unit: build web/node_modules/.package-lock.json
	TEXEL_THIRD_PARTY="$(TEXEL_THIRD_PARTY)" ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

# End-to-end browser tests of Texel Studio: headless Debian chromium driven by
# playwright-core against `texel studio` on loopback. Screenshots and the
# measured latencies land in build/browser-artifacts/.
BROWSER_ENV = TEXEL_BIN=$(CURDIR)/$(BUILD)/bin/texel TEXEL_WEB=$(CURDIR)/$(WEB_TEST_OUT) TEXEL_WEB_PROD=$(CURDIR)/$(WEB_OUT) \
  TEXEL_ARTIFACTS=$(CURDIR)/$(BUILD)/browser-artifacts TEXEL_PROTOCOLS=$(CURDIR)/examples/protocols

test-browser: build web web-test
	cd web && $(BROWSER_ENV) npm test --silent

test-asan: deps-web web/node_modules/.package-lock.json
	@cmake --preset asan >/dev/null
	@cmake --build build-asan -j $(JOBS)
	ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitizers/lsan.supp \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 TEXEL_THIRD_PARTY="$(TEXEL_THIRD_PARTY)" \
	  ctest --test-dir build-asan --output-on-failure -j $(JOBS) -LE slow

test-determinism: build
	bash tests/determinism/cross_build.sh

bench: deps-web build web web-test
	$(BUILD)/bin/texel_bench --benchmark_out=$(BUILD)/bench.json --benchmark_out_format=json
	$(PY) bench/summarize.py $(BUILD)/bench.json
	$(BUILD)/bin/texel_bench_player 1000000 --json $(BUILD)/bench_player.json
	$(BUILD)/bin/texel_bench_player_paced --json $(BUILD)/bench_player_paced.json
	$(BUILD)/bin/texel_bench_multichannel_paced --seconds 10 --runs 2
	$(BUILD)/bin/texel_bench_match --json $(BUILD)/bench_match.json
	$(BUILD)/bin/texel_bench_design 40 --json $(BUILD)/bench_design.json
	$(BUILD)/bin/texel_bench_encode --json $(BUILD)/bench_encode.json
	$(PY) bench/render_to_file.py $(BUILD)/bin/texel
	$(BUILD)/bin/texel_bench_bitmap_2d $(BUILD) 8192 tile
	$(BUILD)/bin/texel_bench_bitmap_2d $(BUILD) 8192 spectral
	$(BUILD)/bin/texel_bench_bitmap_2d $(BUILD) 8192 cells
	$(BUILD)/bin/texel_bench_presenter_2d examples/protocols/direction-independence.json --json $(BUILD)/bench_presenter_2d.json
	cd web && $(BROWSER_ENV) node --test tests/e2e/latency.test.mjs >/dev/null
	$(PY) bench/studio_latency.py $(BUILD)/browser-artifacts/latency.json
	TEXEL_PG_EXTRA_OPTS="-c track_commit_timestamp=on" scripts/pg-test-server.sh start $(BUILD)/bench-pg.env >/dev/null
	$(BUILD)/bin/texel_bench_store_pg --env $(BUILD)/bench-pg.env --stations 50 --trials 1000 --json $(BUILD)/bench_store_pg.json; \
	  rc=$$?; scripts/pg-test-server.sh stop $(BUILD)/bench-pg.env; exit $$rc

# The libFuzzer targets of every parser of outside input (docs/fuzzing.md),
# as tests/fuzz/targets.txt lists them: a clang build in build-fuzz with the
# whole library instrumented, then each target for FUZZ_SECONDS of wall time,
# two at a time. Their seed corpora are replayed by `make test` (ctest
# fuzz.*.replay) under any compiler. `make fuzz FUZZ_TARGETS=fuzz_npy` runs one.
FUZZ_SECONDS ?= 600
FUZZ_TARGETS ?= $(shell awk '/^fuzz_/ {print $$1}' tests/fuzz/targets.txt)

fuzz: deps
	@cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTEXEL_FUZZ=ON \
	  -DTEXEL_BUILD_BENCH=OFF -DTEXEL_WITH_PYTHON=OFF >/dev/null
	@cmake --build build-fuzz -j $(JOBS) --target $(FUZZ_TARGETS)
	bash scripts/fuzz.sh build-fuzz $(FUZZ_SECONDS) $(FUZZ_TARGETS)

# clang-tidy with .clang-tidy's checks over the C++ sources changed against
# main (scripts/tidy.sh; `make tidy TIDY_BASE=HEAD~3` for another base);
# every finding fails. docs/testing.md says why it is not a `make test` phase.
TIDY_BASE ?= main
tidy: configure
	bash scripts/tidy.sh --build $(BUILD) --base $(TIDY_BASE)

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf build build-asan build-debug build-clang build-det build-fuzz out
