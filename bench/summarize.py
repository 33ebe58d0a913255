#!/usr/bin/python3
"""Prints texel_bench results as a table: case, ns/sample, samples/s, and the
ratio to the std::fill baseline of the same buffer measured in the same run;
then the reference synthesis cases (reference/<synthesis>/<name>/<L>mm) as
time per preparation against length, with two ratios to the 100 mm chirp-z
case of the same run: time per N·log2(N) (flat for O(N log N) growth) and the
time against version 2's direct sum at the same length.

usage: summarize.py [build/bench.json]

Uses the median of the repetitions when the run reported aggregates, the
single result otherwise. Stdlib only (Debian's /usr/bin/python3).
"""
import json
import math
import sys


def rows(benchmarks):
    """{case name: (ns/sample, samples/s)}, preferring median aggregates."""
    picked = {}
    for b in benchmarks:
        name = b.get("run_name", b["name"]).split("/min_time:")[0].split("/iterations:")[0].split("/repeats:")[0]
        is_median = b.get("run_type") == "aggregate" and b.get("aggregate_name") == "median"
        is_plain = b.get("run_type", "iteration") == "iteration"
        if not (is_median or is_plain):
            continue
        if name in picked and not is_median:
            continue
        rate = b.get("samples/s") or b.get("items_per_second")
        if rate and "samples" in b:  # reference synthesis: also the sample and harmonic counts
            picked[name] = (1e9 / rate, rate, int(b["samples"]), int(b.get("harmonics", 0)))
        elif rate:
            picked[name] = (1e9 / rate, rate)
        elif "ns/texel" in b:
            picked[name] = (b["ns/texel"], None)
    return picked


def references(table):
    """The reference synthesis table: O(N log N) shows as a flat t/(N log2 N)."""
    cases = {name: row for name, row in table.items() if name.startswith("reference/") and len(row) == 4}
    if not cases:
        return
    base = cases.get("reference/chirp-z/white/100mm")
    print("\nreference synthesis (prepare: draw components, synthesise every sample, scale)")
    print(f"{'case':<32} {'samples':>9} {'harmonics':>10} {'ms':>9} {'ns/sample':>10} {'t/NlogN':>8} {'x direct':>9}")
    for name, (ns, _rate, n, k) in cases.items():
        ms = ns * n / 1e6
        per_nlogn = ns / math.log2(n)
        flat = f"{per_nlogn / (base[0] / math.log2(base[2])):.2f}" if base else ""
        parts = name.split("/")
        direct = cases.get("/".join([parts[0], "direct"] + parts[2:]))
        vs_direct = f"{ns / direct[0]:.4f}" if direct and parts[1] != "direct" else ""
        print(f"{name:<32} {n:>9} {k:>10} {ms:>9.1f} {ns:>10.1f} {flat:>8} {vs_direct:>9}")
    print("t/NlogN: time per N·log2(N) relative to the 100 mm chirp-z case (flat = O(N log N));"
          " x direct: time relative to version 2's direct sum at the same length")


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "build/bench.json"
    try:
        with open(path) as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"summarize.py: cannot read {path}: {e}")
    table = rows(data.get("benchmarks", []))
    if not table:
        sys.exit(f"summarize.py: no benchmark results in {path}")
    print(f"{'case':<24} {'ns/sample':>10} {'samples/s':>12} {'x fill':>8}")
    for name, (ns, rate, *_) in table.items():
        if name.startswith("reference/"):
            continue
        if rate is None:  # prepare: per texel, no fill baseline
            print(f"{name:<24} {ns:>10.1f} {'(ns/texel)':>12} {'':>8}")
            continue
        parts = name.split("/")
        baseline = table.get("/".join(["fill"] + parts[1:2] + [parts[-1].split("-")[0]])) if parts[0] == "render" else None
        ratio = f"{ns / baseline[0]:.1f}" if baseline else ""
        print(f"{name:<24} {ns:>10.3f} {rate:>12.3e} {ratio:>8}")
    references(table)
    ctx = data.get("context", {})
    print(f"\n{ctx.get('num_cpus', '?')} CPUs at {ctx.get('mhz_per_cpu', '?')} MHz, load average "
          f"{', '.join(f'{x:.2f}' for x in ctx.get('load_avg', []))} at start; medians of repetitions")


if __name__ == "__main__":
    main()
