#!/usr/bin/env bash
# Runs Texel's libFuzzer targets (docs/fuzzing.md) for a fixed wall time each,
# two at a time (they share the machine with builds), and prints one line per
# target: seconds, total executions (libFuzzer's final "#N DONE" line) and
# findings (crash/leak/timeout/oom artifacts).
#
#   scripts/fuzz.sh <build dir> <seconds> [<target>...]
#
# The targets and their seed directories are the one list,
# tests/fuzz/targets.txt; with no target named, every listed one runs.
# Each target starts from a scratch copy of its seed corpus
# (<build dir>/fuzz-work/<target>/corpus): the committed corpus in
# tests/fuzz/corpus/ stays small and reviewed, and a finding is added to it by
# hand, with its unit test, once fixed. Limits: -rss_limit_mb=2048 and
# -malloc_limit_mb=512, so an allocation sized by a declared header counts as
# a finding; -timeout=25 s per input.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "$1" && pwd)
seconds=$2
shift 2
work="$build/fuzz-work"
mkdir -p "$work"

list="$root/tests/fuzz/targets.txt"
if [ "$#" -eq 0 ]; then
  set -- $(awk '/^fuzz_/ {print $1}' "$list")
fi
for t in "$@"; do
  grep -q "^$t[[:space:]]" "$list" || { echo "fuzz.sh: $t is not in $list" >&2; exit 2; }
done

# The seed directory of a target (column 4 of the list; `-` = none).
seeds_of() {
  local s
  s=$(awk -v t="$1" '$1 == t {print $4}' "$list")
  [ "$s" != "-" ] && echo "$root/$s"
}

run_one() {
  local t=$1 dir="$work/$1"
  local bin="$build/bin/$t"
  if [ ! -x "$bin" ]; then
    echo "$t: not built" >"$dir.result"
    return
  fi
  rm -rf "$dir" && mkdir -p "$dir/corpus" "$dir/artifacts"
  local seeds
  seeds=$(seeds_of "$t")
  [ -n "$seeds" ] && [ -d "$seeds" ] && cp "$seeds"/* "$dir/corpus/" 2>/dev/null
  local start end
  start=$(date +%s)
  (cd "$dir" && nice -n 10 "$bin" "$dir/corpus" -max_total_time="$seconds" -max_len=4096 -rss_limit_mb=2048 \
    -malloc_limit_mb=512 -timeout=25 -print_final_stats=1 -artifact_prefix="$dir/artifacts/" >"$dir/log.txt" 2>&1)
  end=$(date +%s)
  local execs findings
  execs=$(grep -a 'DONE' "$dir/log.txt" | tail -1 | sed -E 's/^#([0-9]+).*/\1/')
  findings=$(find "$dir/artifacts" -type f | wc -l)
  echo "$t: $((end - start)) s, ${execs:-?} execs, $findings findings (log: $dir/log.txt)" >"$dir.result"
}

pids=()
for t in "$@"; do
  run_one "$t" &
  pids+=($!)
  if [ "${#pids[@]}" -ge 2 ]; then
    wait "${pids[0]}"
    pids=("${pids[@]:1}")
  fi
done
wait
status=0
for t in "$@"; do
  cat "$work/$t.result"
  grep -q ' 0 findings' "$work/$t.result" || status=1
done
exit $status
