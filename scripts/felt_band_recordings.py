#!/usr/bin/env python3
"""Encode → decode → swipe a folder of texture recordings; compare the log-spectral centroid.

docs/encoder.md §2 ("Version 3", "Real recordings") describes the measure:
each recording (.wav, a vibration or sound of a tool or finger dragged over a
surface) is encoded at a nominal swipe speed (`texel encode REC.wav
--swipe-speed 100 --model M`), decoded for the tpad (`texel decode --device
tpad`), swiped at the same speed over one stroke (`texel swipe --speed 100
--rate 44100 --duration 1`),
and the log-spectral centroid of the swiped vibration in 20–1000 Hz (power-
weighted mean of 10·log10 f, dB re 1 Hz; Welch, Hann, 4096-sample segments,
half overlap) is compared with the recording's in the same band. Prints one
row per recording and model, then per model the bias, the median and the 90th
percentile of the |error|, and how many estimates ended at a search bound.

    scripts/felt_band_recordings.py FOLDER [--texel build/apps/texel/texel]
        [--models 2 3] [--speed 100] [--device tpad] [--band 20 1000] [--duration 1] [--target automatic]

No data ships with Texel; the recordings stay where they are (the script
writes only to a temporary directory).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import wave

import numpy as np


def read_wav(path):
    """Samples (float, first channel or the mix of all) and rate of a PCM or float WAV."""
    try:
        with wave.open(path, "rb") as w:
            n, ch, width, rate = w.getnframes(), w.getnchannels(), w.getsampwidth(), w.getframerate()
            raw = w.readframes(n)
        if width == 2:
            x = np.frombuffer(raw, "<i2").astype(float) / 32768.0
        elif width == 4:
            x = np.frombuffer(raw, "<i4").astype(float) / 2147483648.0
        elif width == 3:
            b = np.frombuffer(raw, np.uint8).reshape(-1, 3)
            v = (b[:, 0].astype(np.int32) | (b[:, 1].astype(np.int32) << 8) | (b[:, 2].astype(np.int32) << 16))
            x = np.where(v >= 1 << 23, v - (1 << 24), v).astype(float) / 8388608.0
        else:
            raise ValueError(f"{width}-byte samples")
        return x.reshape(-1, ch).mean(axis=1), rate
    except wave.Error:  # IEEE float WAV (format 3), which the wave module refuses
        from scipy.io import wavfile
        rate, x = wavfile.read(path)
        x = np.asarray(x, float)
        return (x if x.ndim == 1 else x.mean(axis=1)), rate


def log_centroid_db(x, rate, lo, hi, segment=4096):
    """Power-weighted mean of 10·log10 f over [lo, hi] Hz (Welch, Hann, half overlap)."""
    x = np.asarray(x, float) - np.mean(x)
    seg = min(segment, len(x))
    win = np.hanning(seg)
    step = seg // 2
    p = None
    for s in range(0, len(x) - seg + 1, step):
        q = np.abs(np.fft.rfft(x[s:s + seg] * win)) ** 2
        p = q if p is None else p + q
    f = np.fft.rfftfreq(seg, 1.0 / rate)
    m = (f >= lo) & (f <= hi)
    return float(np.sum(p[m] * 10.0 * np.log10(f[m])) / np.sum(p[m]))


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(" ".join(cmd) + ": " + r.stderr.strip())
    return r


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folder")
    ap.add_argument("--texel", default=os.path.join(os.path.dirname(__file__), "..", "build", "apps", "texel", "texel"))
    ap.add_argument("--models", type=int, nargs="+", default=[2, 3])
    ap.add_argument("--speed", type=float, default=100.0)
    ap.add_argument("--device", default="tpad")
    ap.add_argument("--band", type=float, nargs=2, default=[20.0, 1000.0])
    ap.add_argument("--duration", type=float, default=1.0,
                    help="swipe length, s: one stroke (the tpad's 101.76 mm take 1.02 s at 100 mm/s; a longer swipe jumps "
                         "back to the start, and that step lowers the centroid by about 1.5 dB)")
    ap.add_argument("--target", default="automatic", help="texel encode --target: automatic (centroid for .wav), felt, centroid")
    a = ap.parse_args()
    files = sorted(f for f in os.listdir(a.folder) if f.lower().endswith(".wav"))
    if not files:
        sys.exit(f"no .wav files in {a.folder}")
    lo, hi = a.band
    errors = {m: [] for m in a.models}
    bounds = {m: 0 for m in a.models}
    print(f"| recording | model | P dB | I dB | beyond felt band | recording centroid | swiped | error dB |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in files:
            path = os.path.join(a.folder, name)
            x, rate = read_wav(path)
            ref = log_centroid_db(x, rate, lo, hi)
            for m in a.models:
                bit = os.path.join(tmp, "x.texel")
                doc = os.path.join(tmp, "x.texel.json")
                out = os.path.join(tmp, "swipe.wav")
                enc = run([a.texel, "encode", path, "--swipe-speed", str(a.speed), "--model", str(m), "--channel", "mix", "--target", a.target,
                           "-o", bit, "--json"])
                j = json.loads(enc.stdout)
                run([a.texel, "decode", bit, "--device", a.device, "-o", doc])
                run([a.texel, "swipe", doc, "-o", out, "--speed", str(a.speed), "--rate", str(rate), "--duration",
                     str(a.duration), "--wav-format", "float"])
                y, yr = read_wav(out)
                got = log_centroid_db(y, yr, lo, hi)
                e = got - ref
                errors[m].append(e)
                est = j["estimate"]
                at = est["at_bound"]["central_pitch"] or est["at_bound"]["irregularity"]
                bounds[m] += at
                print(f"| {name} | {m} | {est['central_pitch_db']:.2f} | {est['irregularity_db']:.2f}{' (bound)' if at else ''} "
                      f"| {100 * j['felt_band']['power_beyond']:.1f} % | {ref:.2f} | {got:.2f} | {e:+.2f} |", flush=True)
    print()
    print("| model | recordings | bias dB | median abs error dB | p90 dB | at a search bound |")
    print("|---:|---:|---:|---:|---:|---:|")
    for m in a.models:
        e = np.array(errors[m])
        print(f"| {m} | {len(e)} | {np.mean(e):+.2f} | {np.median(np.abs(e)):.2f} | {np.percentile(np.abs(e), 90):.2f} | "
              f"{bounds[m]} |")


if __name__ == "__main__":
    main()
