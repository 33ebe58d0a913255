#!/usr/bin/env bash
# clang-tidy with the checks of .clang-tidy over the C++ sources a change
# touched (docs/contributing.md §8): every finding is an error.
#
#   scripts/tidy.sh [--base REF] [--build DIR] [FILE...]
#
# Without FILEs: the .cpp files under src/, apps/, python/src, bench/ and
# tests/ that differ from the merge-base with REF (default: main, else
# HEAD~1), plus the sources beside any header that changed. DIR (default
# build) holds compile_commands.json (every preset writes one). Files the
# build does not compile (another configuration's) are skipped, saying so.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
base=main
build=build
files=()
while [ $# -gt 0 ]; do
  case "$1" in
    --base) base=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    -*) echo "tidy: unknown option '$1'; allowed: --base REF, --build DIR" >&2; exit 2 ;;
    *) files+=("$1"); shift ;;
  esac
done
command -v clang-tidy >/dev/null || { echo "tidy: clang-tidy is not installed (apt-get install clang-tidy)" >&2; exit 2; }
db="$build/compile_commands.json"
[ -f "$db" ] || { echo "tidy: no $db; configure first (cmake --preset release)" >&2; exit 2; }

if [ ${#files[@]} -eq 0 ]; then
  from=$(git merge-base HEAD "$base" 2>/dev/null || git rev-parse HEAD~1)
  changed=$( (git diff --name-only --diff-filter=ACMR "$from"; git diff --name-only --diff-filter=ACMR) | sort -u)
  for f in $changed; do
    case "$f" in
      src/*.cpp | apps/*.cpp | python/src/*.cpp | bench/*.cpp | tests/*.cpp) files+=("$f") ;;
      # A changed header: tidy the sources beside it, which compile it.
      src/*.hpp | apps/*.hpp | tests/*.hpp) for s in "$(dirname "$f")"/*.cpp; do [ -f "$s" ] && files+=("$s"); done ;;
    esac
  done
fi
mapfile -t files < <(printf '%s\n' "${files[@]}" | sort -u | grep -v '^$')
if [ ${#files[@]} -eq 0 ]; then
  echo "tidy: no changed C++ sources"
  exit 0
fi

status=0
checked=0
for f in "${files[@]}"; do
  if ! grep -q "\"file\": \"$root/$f\"" "$db"; then
    echo "tidy: $f is not compiled by $build (skipped)"
    continue
  fi
  # GCC-only warning flags of the release build are unknown to clang.
  out=$(clang-tidy -p "$build" --quiet --extra-arg=-Wno-unknown-warning-option "$f" 2>/dev/null)
  checked=$((checked + 1))
  if echo "$out" | grep -q "warning:\|error:"; then
    echo "$out"
    status=1
  fi
done
echo "tidy: $checked file(s) checked, $( [ $status = 0 ] && echo 'no findings' || echo 'findings above')"
exit $status
