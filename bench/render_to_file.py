#!/usr/bin/env python3
"""Render-to-file beside dd (issue #11, item 5): whole-process wall time and
peak resident memory of `texel render` writing 10^7 uint16 samples (20 MB) to
a .bin, next to `dd` writing the same number of bytes, measured in the same
run. Texel's file is fsync'ed before it is renamed into place (a file that
appears is on disk), so dd is timed both without and with conv=fsync.
Then reference generation at growing lengths (5 µm samples, uint16), each
beside dd writing the same bytes: peak memory must stay flat with length.

usage: render_to_file.py TEXEL [SAMPLES] [RUNS]
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time


def measure(cmd):
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    err = p.stderr.read().decode()
    p.stderr.close()
    if status != 0:
        sys.exit(f"{' '.join(cmd)} failed: {err}")
    return wall, usage.ru_maxrss / 1024.0  # MiB


def main():
    texel = sys.argv[1]
    samples = int(sys.argv[2]) if len(sys.argv) > 2 else 10_000_000
    runs = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    spacing = 0.0053  # tpad's sample spacing, mm
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "map.bin")
        dd_out = os.path.join(d, "dd.bin")
        mb = samples * 2 // (1 << 20)
        cases = {
            "dd (no fsync)": ["dd", "if=/dev/zero", f"of={dd_out}", "bs=1M", f"count={mb}", "status=none"],
            "dd conv=fsync": ["dd", "if=/dev/zero", f"of={dd_out}", "bs=1M", f"count={mb}", "conv=fsync", "status=none"],
            "texel render": [texel, "render", "--device", "tpad", "--length", f"{samples * spacing:.4f}", "--seed", "3",
                             "-o", out],
            "texel --version (start-up)": [texel, "--version"],
            "true (a do-nothing process)": ["true"],
        }
        results = {name: [measure(cmd) for _ in range(runs)] for name, cmd in cases.items()}
        size = os.path.getsize(out)
    print(f"\nRender to file: {samples:,} uint16 samples ({size:,} bytes), median of {runs} runs")
    print(f"{'':28s} {'wall ms':>9s} {'peak MiB':>9s} {'× dd fsync':>11s}")
    base = statistics.median(w for w, _ in results["dd conv=fsync"])
    for name, rs in results.items():
        wall = statistics.median(w for w, _ in rs)
        peak = max(m for _, m in rs)
        print(f"{name:28s} {wall * 1e3:9.1f} {peak:9.1f} {wall / base:10.1f}×")
    startup = statistics.median(w for w, _ in results["texel --version (start-up)"])
    floor = statistics.median(w for w, _ in results["true (a do-nothing process)"])
    print(f"goal (issue #39): texel --version <= 10 ms: {'met' if startup <= 0.010 else 'NOT met'} "
          f"({startup * 1e3:.1f} ms; a do-nothing process {floor * 1e3:.1f} ms, so {(startup - floor) * 1e3:.1f} ms of Texel's own)")
    render = statistics.median(w for w, _ in results["texel render"])
    peak = max(m for _, m in results["texel render"])
    print("(peak MiB is the child's ru_maxrss, which includes the forking Python's ~12 MiB before exec)")
    print(f"goal: peak < 32 MiB: {'met' if peak < 32 else 'NOT met'} ({peak:.1f}); "
          f"within 4× of dd conv=fsync: {'met' if render <= 4 * base else 'NOT met'} ({render / base:.1f}×)")
    lengths(texel, samples, runs)
    references(texel, max(1, runs // 2))


def lengths(texel, samples, runs):
    """texel render and texel decode at 0.1×, 1× and 10× the samples, beside dd of the same bytes: memory stays flat."""
    spacing = 0.0053
    rows = []
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "map.bin")
        dd_out = os.path.join(d, "dd.bin")
        doc = os.path.join(d, "d.texel.json")
        stream = os.path.join(d, "d.texel")
        subprocess.run([texel, "render", "--central-pitch", "8", "--seed", "3", "--device", "tpad", "-o", doc], check=True,
                       stdout=subprocess.DEVNULL)
        subprocess.run([texel, "encode", doc, "-o", stream], check=True, stdout=subprocess.DEVNULL)
        for n in (samples // 10, samples, samples * 10):
            length = f"{n * spacing:.4f}"
            for name, cmd in (("render", [texel, "render", "--device", "tpad", "--length", length, "--seed", "3", "-o", out]),
                              ("decode", [texel, "decode", stream, "--device", "tpad", "--length", length, "-o", out])):
                # Texel and dd in turn, so both meet the same state of the disk
                # (write-back and freeing of the previous runs' files).
                rs, dd = [], []
                for _ in range(runs):
                    rs.append(measure(cmd))
                    size = os.path.getsize(out)
                    dd.append(measure(["dd", "if=/dev/zero", f"of={dd_out}", "bs=1M", f"count={size}", "iflag=count_bytes",
                                       "conv=fsync", "status=none"]))
                rows.append((name, n, size, statistics.median(w for w, _ in rs), max(m for _, m in rs),
                             statistics.median(w for w, _ in dd)))
    print(f"\nRender and decode at growing lengths (tpad, uint16), median of {runs}")
    print(f"{'command':8s} {'samples':>13s} {'bytes':>13s} {'wall ms':>9s} {'peak MiB':>9s} {'dd fsync ms':>12s} {'× dd':>7s}")
    for name, n, size, wall, peak, dd in rows:
        print(f"{name:8s} {n:13,d} {size:13,d} {wall * 1e3:9.1f} {peak:9.1f} {dd * 1e3:12.1f} {wall / dd:6.1f}×")
    worst = max(r[4] for r in rows)
    print(f"goal: peak < 32 MiB at every length: {'met' if worst < 32 else 'NOT met'} ({worst:.1f} MiB at most)")
    ratio = max(wall / dd for *_, wall, _, dd in rows)
    print(f"goal (issue #11): render and decode within 4× of dd conv=fsync at every length: "
          f"{'met' if ratio <= 4 else 'NOT met'} ({ratio:.1f}× at most)")


def references(texel, runs):
    """texel reference NAME --length L --spacing 0.005 beside dd of the same bytes."""
    spacing = 0.005
    rows = []
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "ref.bin")
        dd_out = os.path.join(d, "dd.bin")
        for name, length in [("white", 400), ("white", 4000), ("white", 20000), ("pink", 4000), ("square", 4000),
                             ("patch-4.6", 4000)]:
            cmd = [texel, "reference", name, "--device", "tpad", "--length", str(length), "--spacing", str(spacing),
                   "-o", out]
            rs = [measure(cmd) for _ in range(runs)]
            size = os.path.getsize(out)
            dd = [measure(["dd", "if=/dev/zero", f"of={dd_out}", "bs=1M", f"count={size}", "iflag=count_bytes", "conv=fsync",
                           "status=none"]) for _ in range(runs)]
            rows.append((name, length, size, statistics.median(w for w, _ in rs), max(m for _, m in rs),
                         statistics.median(w for w, _ in dd)))
    print(f"\nReference generation to .bin (tpad format, {spacing} mm spacing), median of {runs}")
    print(f"{'reference':12s} {'length mm':>10s} {'bytes':>11s} {'wall ms':>9s} {'peak MiB':>9s} {'dd fsync ms':>12s} {'× dd':>7s}")
    for name, length, size, wall, peak, dd in rows:
        print(f"{name:12s} {length:10d} {size:11,d} {wall * 1e3:9.1f} {peak:9.1f} {dd * 1e3:12.1f} {wall / dd:6.1f}×")
    worst = max(r[4] for r in rows)
    print(f"goal: peak < 32 MiB at every length: {'met' if worst < 32 else 'NOT met'} ({worst:.1f} MiB at most)")
    ratio = max(wall / dd for *_, wall, _, dd in rows)
    print(f"goal (issue #11): within 4× of dd conv=fsync: {'met' if ratio <= 4 else 'NOT met'} ({ratio:.1f}× at most; "
          "noise is a chirp-z sum over the whole length, docs/algorithm.md)")
    white = [(length, wall) for name, length, _, wall, _, _ in rows if name == "white"]
    for (l0, w0), (l1, w1) in zip(white, white[1:]):
        print(f"white {l0} → {l1} mm: length ×{l1 / l0:.0f}, time ×{w1 / w0:.1f}")


if __name__ == "__main__":
    main()
