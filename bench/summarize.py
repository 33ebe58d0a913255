#!/usr/bin/python3
"""Prints texel_bench results as a table: case, ns/sample, samples/s, and the
ratio to the std::fill baseline of the same buffer measured in the same run.

usage: summarize.py [build/bench.json]

Uses the median of the repetitions when the run reported aggregates, the
single result otherwise. Stdlib only (Debian's /usr/bin/python3).
"""
import json
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
        if rate:
            picked[name] = (1e9 / rate, rate)
        elif "ns/texel" in b:
            picked[name] = (b["ns/texel"], None)
    return picked


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
    for name, (ns, rate) in table.items():
        if rate is None:  # prepare: per texel, no fill baseline
            print(f"{name:<24} {ns:>10.1f} {'(ns/texel)':>12} {'':>8}")
            continue
        parts = name.split("/")
        baseline = table.get("/".join(["fill"] + parts[1:2] + [parts[-1].split("-")[0]])) if parts[0] == "render" else None
        ratio = f"{ns / baseline[0]:.1f}" if baseline else ""
        print(f"{name:<24} {ns:>10.3f} {rate:>12.3e} {ratio:>8}")
    ctx = data.get("context", {})
    print(f"\n{ctx.get('num_cpus', '?')} CPUs at {ctx.get('mhz_per_cpu', '?')} MHz, load average "
          f"{', '.join(f'{x:.2f}' for x in ctx.get('load_avg', []))} at start; medians of repetitions")


if __name__ == "__main__":
    main()
