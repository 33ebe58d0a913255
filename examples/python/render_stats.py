"""Render a Texel texture with the library and describe it in numbers.

Run after `make python`:
    PYTHONPATH=build/python /usr/bin/python3 examples/python/render_stats.py
"""
import numpy as np

import texel

device = texel.device("tpad")
# The device's native samples (uint16 on tpad: the bytes of `texel render -o map.bin`)...
native = texel.render(central_pitch_db=10, irregularity_db=-5, texel_length_mm=0.25, seed=7, device=device)
# ...and the same map as amplitudes in [0, 1].
doc = texel.document(central_pitch_db=10, irregularity_db=-5, texel_length_mm=0.25, seed=7, device=device)
amplitude = doc.render(dtype="float64")

print(f"device {device.name}: {device.samples} samples every {device.spacing_mm:.6f} mm ({device.length_mm:.2f} mm)")
print(f"native map: {native.dtype}, {native.shape[0]} samples, {native.nbytes} bytes")
print(f"amplitude: mean {amplitude.mean():.4f}, min {amplitude.min():.4f}, max {amplitude.max():.4f}")

texels = texel.texels(doc)
f = texels["frequency_cpm"]
print(f"texels: {len(f)}, frequency mean {f.mean():.3f} cpm, SD {f.std(ddof=1):.3f} cpm, "
      f"median {10 * np.log10(np.median(f)):.2f} dB re 1 cpm")

report = texel.analyse_spectrum(amplitude, device.spacing_mm)
s = report["summary"]
print(f"spectrum: centroid {s['centroid_cpm']:.3f} cpm ({s['log_centroid_db']:.2f} dB), "
      f"spread {s['log_spread_db']:.2f} dB, {len(report['peaks'])} peaks")

# What a finger would feel at 100 mm/s: the vibration a swipe produces.
out, positions = texel.swipe(doc, speed_mm_s=100, duration_s=0.5)
print(f"swipe: {len(out)} samples at 48 kHz, RMS {np.sqrt(np.mean(out.astype(np.float64) ** 2)):.4f}")

# The encoder finds the parameters back from the map alone.
r = texel.encode(native, device=device)
print(f"encoded: {len(r.bytes)} bytes, Central Pitch {r.central_pitch_db:.2f} dB, Irregularity {r.irregularity_db:.2f} dB")
