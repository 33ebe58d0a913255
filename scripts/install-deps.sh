#!/usr/bin/env bash
# Installs the Debian 12 packages Texel builds, tests and benchmarks with.
# Idempotent: packages already present are skipped, so a warm machine pays
# only one dpkg query. Runs as root (CI, containers) or through sudo.
#
#   scripts/install-deps.sh          packages for the libraries, CLI, Python, tests
#   scripts/install-deps.sh --web    the same, and Node.js >= 20 must be present
set -euo pipefail

want_web=0
for arg in "$@"; do
  case "$arg" in
    --web) want_web=1 ;;
    *) echo "install-deps: unknown option '$arg'; allowed: --web" >&2; exit 2 ;;
  esac
done

# Exactly what is used, grouped by who uses it; the library components'
# own lists are in cmake/TexelDependencies.cmake.
packages=(
  # toolchain: the release preset (GCC), the asan and clang presets, libFuzzer
  # and the determinism check (clang + its sanitizer runtimes), `make format`
  build-essential cmake ninja-build pkg-config git
  g++ clang libclang-rt-14-dev clang-format
  # libraries, per component: core (nlohmann-json), spectrum (kissfft),
  # plot (cairo), surface2d (libpng), player (sndfile, portaudio), io (matio, sndfile),
  # codec (sndfile, zstd), experiment (sqlite, Boost.Math), studio (Boost.Beast)
  nlohmann-json3-dev libkissfft-dev libcairo2-dev libsndfile1-dev portaudio19-dev
  # surface2d (friction bitmaps, coarse-profile images)
  libpng-dev
  libmatio-dev libzstd-dev libsqlite3-dev libboost-dev
  # experiment: the PostgreSQL store's client library (libpq); the server
  # itself for the tests and `make bench` (initdb + pg_ctl in a temporary
  # directory, scripts/pg-test-server.sh)
  libpq-dev postgresql
  # the texel command line
  libcli11-dev
  # tests and benchmarks
  libgtest-dev librapidcheck-dev libbenchmark-dev
  # the paced player benchmark: a JACK server with its dummy driver, and
  # stress-ng to busy every core (bench/bench_player_paced.cpp)
  jackd2 libjack-jackd2-dev stress-ng
  # the Python package and the Python-side checks (pytest, the statistics
  # oracle, the protocol schema and the MPEG-I Haptics schemas with RFC 3339
  # date-time checking, reading .mat v5/v7.3 files); pip, setuptools,
  # wheel and venv build and install it as a Python package, offline
  # (python/README.md)
  pybind11-dev python3-dev python3-numpy python3-pytest python3-scipy python3-jsonschema python3-rfc3339 python3-h5py
  python3-pip python3-setuptools python3-wheel python3-venv
  # Texel Studio's browser tests
  chromium firefox-esr
  # the terminal runner's participant-screen test drives a pseudo-terminal (tests/cli)
  tmux
  # GNU Octave runs examples/matlab/*.m in the examples.matlab_* ctests: a
  # test-only tool (GPL, never linked); 74 MB download, 243 MB installed.
  octave
  # mkoctfile builds the MEX functions (matlab/*.c) for the capi.mex ctest: test only
  octave-dev
)

# Node.js (>= 20, for Texel Studio's front end only) is not a Debian 12
# package new enough, so it is checked, not installed: with --web a missing
# one stops here (exit 2); without, a note says what is left out.
if [ "$want_web" = 1 ]; then
  bash "$(dirname "$0")/check-node.sh" || exit 2
else
  bash "$(dirname "$0")/check-node.sh" --note
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 2; }
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
