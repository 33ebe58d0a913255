# Texel's front door. `make demo` and `make test` each do the whole set-up on
# a fresh Debian 12 machine: install missing packages, configure, build, run.
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BUILD := build
PY := /usr/bin/python3

.PHONY: all deps configure build demo test test-unit test-asan test-determinism bench format clean

all: build

deps:
	@bash scripts/install-deps.sh

configure: deps
	@cmake --preset release >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

demo: build
	$(BUILD)/bin/texel demo --out out/demo
	$(BUILD)/bin/texel atlas --out out/demo/references

# Every test: unit and CLI tests (release build), the same under
# AddressSanitizer + UndefinedBehaviorSanitizer, and byte-identity of the demo
# set across GCC/clang, -O0/-O3 and SIMD widths.
test: test-unit test-asan test-determinism

test-unit: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

test-asan: deps
	@cmake --preset asan >/dev/null
	@cmake --build build-asan -j $(JOBS)
	ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitizers/lsan.supp \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --test-dir build-asan --output-on-failure -j $(JOBS) -LE slow

test-determinism: build
	bash tests/determinism/cross_build.sh

bench: build
	$(BUILD)/bin/texel_bench --benchmark_out=$(BUILD)/bench.json --benchmark_out_format=json
	$(PY) bench/summarize.py $(BUILD)/bench.json
	$(BUILD)/bin/texel_bench_player 1000000 --json $(BUILD)/bench_player.json
	$(BUILD)/bin/texel_bench_match --json $(BUILD)/bench_match.json

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf build build-asan build-debug build-clang build-det out
