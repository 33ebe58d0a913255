#!/usr/bin/env bash
# Determinism across builds (issue #2, item 7): the demo set's device files
# must be byte-identical whether Texel is built with GCC or clang, at -O0 or
# -O3, and with the baseline x86-64 SIMD width or the host's widest
# (-march=native: AVX2/AVX-512 where present). Each configuration builds only
# libtexel and texel-golden (apps/texel-golden), renders the demo set and
# compares SHA-256 digests with the reviewed golden list
# tests/golden/demo.sha256 — which `texel demo` itself is held to by the
# cli.golden_demo_sha256 test of the main build. The render kernel also picks
# its SIMD width at run time (AVX-512, AVX2, SSE2); TEXEL_SIMD forces one so
# every width is compared on this machine.
# References (issue #11 item 6): the same builds render the reviewed reference
# documents tests/golden/references/*.texel.json (version 2: direct synthesis,
# version 3: chirp-z over detfft) as float64 maps — every bit of every
# amplitude — against tests/golden/references.sha256 (also held by the
# reference.golden_sha256 test of the main build).
# Multi-channel documents (issue #40) are in the same set: a version-6
# document (v6-simultaneous-4ch) is written as its channels' maps,
# interleaved [samples, channels], so every channel's draw is compared.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
golden="$root/tests/golden/demo.sha256"
golden_refs="$root/tests/golden/references.sha256"
ref_docs=("$root"/tests/golden/references/*.texel.json)
work="${TEXEL_DET_DIR:-$root/build-det}"  # TEXEL_DET_DIR: another directory, e.g. beside a build in use
jobs=$(nproc 2>/dev/null || echo 2)
mkdir -p "$work"

configs=(
  "gcc-O0:g++:-O0"
  "gcc-O3-native:g++:-O3 -march=native"
  "clang-O0:clang++:-O0"
  "clang-O3:clang++:-O3"
)
# Each configuration builds texel-golden only: that every module (the CLI,
# the studio, the tests) keeps compiling with clang is proven by the sanitizer
# build of `make test-asan` (CMakePresets.json: asan is clang), not here a
# second time (the suite's budget is CI's: docs/testing.md).
fail=0
for c in "${configs[@]}"; do
  IFS=: read -r name cxx flags <<<"$c"
  dir="$work/$name"
  cmake -S "$root" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_CXX_FLAGS="$flags" \
      -DTEXEL_BUILD_TESTS=OFF -DTEXEL_BUILD_BENCH=OFF >/dev/null
  if ! cmake --build "$dir" -j "$jobs" --target texel_golden >"$dir/build.log" 2>&1; then
    echo "determinism: $name ($cxx $flags) failed to build:"
    tail -30 "$dir/build.log"
    echo "0 passed, 1 failed"
    exit 1
  fi
  for simd in auto avx2 sse2; do
    rm -rf "$dir/demo-$simd"
    TEXEL_SIMD=$simd "$dir/bin/texel-golden" "$dir/demo-$simd" "${ref_docs[@]}"
    (cd "$dir/demo-$simd" && sha256sum -- *.bin) >"$dir/demo-$simd.sha256"
    (cd "$dir/demo-$simd/references" && sha256sum -- *.f64) >"$dir/references-$simd.sha256"
    if diff -u "$golden" "$dir/demo-$simd.sha256" >"$dir/diff-$simd.txt" &&
        diff -u "$golden_refs" "$dir/references-$simd.sha256" >>"$dir/diff-$simd.txt"; then
      echo "determinism: $name ($cxx $flags, SIMD $simd): $(wc -l <"$golden") demo files and" \
        "$(wc -l <"$golden_refs") reference maps identical to the golden digests"
    else
      echo "determinism: $name ($cxx $flags, SIMD $simd) DIFFERS from $golden or $golden_refs:"
      cat "$dir/diff-$simd.txt"
      fail=1
    fi
  done
done
if [ "$fail" -ne 0 ]; then
  echo "1 failed: builds disagree"
  exit 1
fi
echo "$((${#configs[@]} * 3)) passed, 0 failed"
