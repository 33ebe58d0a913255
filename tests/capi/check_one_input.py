"""One input, one answer (issue 39): the same array through the CLI (a .npy
file), the Python package (an array) and the C ABI (texel_encode, through
ctypes) gives the same .texel bitstream, or the same refusal — in range, out
of range (a map x100 or x-1: scaled to full range by the library's one rule,
never clamped), constant out of range and non-finite (refused by all three).
The MEX texel_encode goes through the same C function (matlab/tests/test_mex.m).

Environment: TEXEL_BIN (the CLI), TEXEL_C_LIBRARY (libtexel.so), PYTHONPATH
with the built package, TEXEL_WORK (a scratch folder).
"""
import ctypes
import os
import subprocess
import sys

import numpy as np
import texel

CLI = os.environ["TEXEL_BIN"]
WORK = os.environ["TEXEL_WORK"]
os.makedirs(WORK, exist_ok=True)

lib = ctypes.CDLL(os.environ["TEXEL_C_LIBRARY"])
lib.texel_encode.restype = ctypes.c_int
lib.texel_encode.argtypes = [ctypes.POINTER(ctypes.c_double), ctypes.c_size_t, ctypes.c_double, ctypes.POINTER(ctypes.c_void_p)]
lib.texel_encode_result_bytes.restype = ctypes.c_int
lib.texel_encode_result_bytes.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t, ctypes.POINTER(ctypes.c_size_t)]
lib.texel_encode_result_destroy.argtypes = [ctypes.c_void_p]
lib.texel_last_error.restype = ctypes.c_char_p
TEXEL_OK, TEXEL_INVALID_ARGUMENT = 0, 1


def via_cli(name, a, spacing):
    """('ok', bytes) or ('refused', message): `texel encode NAME.npy --spacing S`."""
    npy, out = os.path.join(WORK, name + ".npy"), os.path.join(WORK, name + ".texel")
    np.save(npy, a)
    if os.path.exists(out):
        os.remove(out)
    r = subprocess.run([CLI, "encode", npy, "--spacing", repr(spacing), "-o", out], capture_output=True, text=True)
    if r.returncode == 0:
        with open(out, "rb") as f:
            return "ok", f.read()
    assert r.returncode == 2, f"texel encode exited {r.returncode}: {r.stderr}"
    assert not os.path.exists(out), "a refused encode left an output file"
    return "refused", r.stderr.strip()


def via_python(a, spacing):
    # device="generic": a flat display in the model, as the CLI without
    # --device and texel_encode (an array in Python defaults to the tpad's).
    try:
        return "ok", texel.encode(a, device="generic", spacing_mm=spacing).bytes
    except texel.Error as e:
        return "refused", str(e)


def via_c(a, spacing):
    a = np.ascontiguousarray(a, dtype=np.float64)
    result = ctypes.c_void_p()
    st = lib.texel_encode(a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), a.size, spacing, ctypes.byref(result))
    if st != TEXEL_OK:
        assert st == TEXEL_INVALID_ARGUMENT, f"texel_encode returned {st}"
        assert not result.value, "a failed texel_encode wrote a handle"
        return "refused", lib.texel_last_error().decode()
    try:
        needed = ctypes.c_size_t()
        assert lib.texel_encode_result_bytes(result, None, 0, ctypes.byref(needed)) == TEXEL_OK
        buf = ctypes.create_string_buffer(needed.value)
        assert lib.texel_encode_result_bytes(result, buf, needed.value, None) == TEXEL_OK
        return "ok", buf.raw
    finally:
        lib.texel_encode_result_destroy(result)


def main():
    # The seed-7 map on the tpad (19,200 samples), as `texel render` writes it.
    base = os.path.join(WORK, "seed7.npy")
    subprocess.run([CLI, "render", "--central-pitch", "10", "--irregularity", "-5", "--texel-length", "0.25", "--seed", "7",
                    "--device", "tpad", "-o", base], check=True)
    m = np.load(base)
    spacing = 0.0053  # the tpad's: 101.76 mm / 19,200 samples
    nan = m.copy()
    nan[100] = np.nan
    cases = [
        ("in_range", m, "ok", None),
        ("times_100", m * 100, "ok", None),
        ("times_minus_1", m * -1, "ok", None),
        ("constant_2", np.full(m.size, 2.0), "refused", "constant: it holds no texture"),
        ("non_finite", nan, "refused", "non-finite"),
    ]
    answers = {}
    failures = 0
    for name, a, want, words in cases:
        got = {"CLI": via_cli(name, a, spacing), "Python": via_python(a, spacing), "C": via_c(a, spacing)}
        kinds = {door: g[0] for door, g in got.items()}
        if set(kinds.values()) != {want}:
            print(f"FAIL {name}: expected {want} from every front door, got {kinds}: {got}")
            failures += 1
            continue
        if want == "ok":
            bitstreams = {door: g[1] for door, g in got.items()}
            if len(set(bitstreams.values())) != 1:
                print(f"FAIL {name}: different bitstreams: " + ", ".join(f"{d} {b.hex()}" for d, b in bitstreams.items()))
                failures += 1
                continue
            answers[name] = got["C"][1]
            print(f"{name}: one bitstream from CLI, Python and C ({len(got['C'][1])} bytes, {got['C'][1].hex()})")
        else:
            missing = {door: msg for door, msg in ((d, g[1]) for d, g in got.items()) if words not in msg}
            if missing:
                print(f"FAIL {name}: refusals without '{words}': {missing}")
                failures += 1
                continue
            print(f"{name}: refused by CLI, Python and C: " + " | ".join(g[1] for g in got.values()))
    # Scaled, not clamped: x100 clamped would be a map of ones (no texture)
    # and x-1 one of zeros; scaled, x-1 is the map mirrored, a texture of its own.
    if "times_100" in answers and "in_range" in answers and "times_minus_1" in answers:
        flat = via_c(np.ones(m.size), spacing)[1]
        if answers["times_100"] == flat or answers["times_minus_1"] == flat:
            print("FAIL an out-of-range map encoded as the flat surface clamping would give")
            failures += 1
    if failures:
        sys.exit(1)
    print("one input, one answer: every case agrees across CLI, Python and C")


# ----------------------------------------------------------------- 2-D maps
# The same rule for a 2-D map: `texel encode map.npy --pitch P`, Python's
# texel.encode_2d(array, pitch_mm=P) and texel_encode_2d (C, and the MEX
# through it) give one result or one refusal. A small map with a quick
# encoder setting keeps this to seconds.
PITCH = 0.1
SIZE = 128  # pixels a side: the least the scans need (1,024 samples along each direction)
QUICK = {"directions": 4}  # the CLI has --directions; the other 2-D settings stay at their defaults

lib.texel_encode_2d.restype = ctypes.c_int
lib.texel_encode_2d.argtypes = [ctypes.POINTER(ctypes.c_double), ctypes.c_int, ctypes.c_int, ctypes.c_double, ctypes.c_void_p,
                                ctypes.c_void_p, ctypes.POINTER(ctypes.c_void_p)]
lib.texel_encode2d_result_json.restype = ctypes.c_int
lib.texel_encode2d_result_json.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t, ctypes.POINTER(ctypes.c_size_t)]
lib.texel_encode2d_result_destroy.argtypes = [ctypes.c_void_p]


class Options2D(ctypes.Structure):
    _fields_ = [("directions", ctypes.c_int), ("scan_samples", ctypes.c_size_t), ("correction_rounds", ctypes.c_int)]


lib.texel_encode2d_options_default.restype = Options2D


def texture_of(j):
    """The encoded texture (the --json "estimate", or Python's fields): what must agree across the front doors."""
    j = j.get("estimate", j)
    keys = ("central_pitch_db", "irregularity_db", "texel_length_mm", "fine_strength")
    return tuple(round(float(j[k]), 9) for k in keys) + (j["field"],)


def via_cli_2d(name, a):
    npy, out = os.path.join(WORK, name + "_2d.npy"), os.path.join(WORK, name + "_2d.texel.json")
    np.save(npy, a)
    if os.path.exists(out):
        os.remove(out)
    r = subprocess.run([CLI, "encode", npy, "--pitch", repr(PITCH), "--json", "-o", out] +
                       [f"--{k.replace('_', '-')}={v}" for k, v in QUICK.items()], capture_output=True, text=True)
    if r.returncode == 0:
        import json
        return "ok", texture_of(json.loads(r.stdout))
    assert r.returncode == 2, f"texel encode exited {r.returncode}: {r.stderr}"
    assert not os.path.exists(out), "a refused encode left an output file"
    return "refused", r.stderr.strip()


def via_python_2d(a):
    try:
        r = texel.encode_2d(a, pitch_mm=PITCH, **QUICK)
        return "ok", texture_of({"central_pitch_db": r.central_pitch_db, "irregularity_db": r.irregularity_db,
                                 "texel_length_mm": r.texel_length_mm, "fine_strength": r.spec["fine_strength"],
                                 "field": r.field})
    except texel.Error as e:
        return "refused", str(e)


def via_c_2d(a):
    import json
    a = np.ascontiguousarray(a, dtype=np.float64)
    o = lib.texel_encode2d_options_default()
    for k, v in QUICK.items():
        setattr(o, k, v)
    result = ctypes.c_void_p()
    st = lib.texel_encode_2d(a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), a.shape[1], a.shape[0], PITCH, None,
                             ctypes.byref(o), ctypes.byref(result))
    if st != TEXEL_OK:
        assert st == TEXEL_INVALID_ARGUMENT, f"texel_encode_2d returned {st}: {lib.texel_last_error()}"
        assert not result.value, "a failed texel_encode_2d wrote a handle"
        return "refused", lib.texel_last_error().decode()
    try:
        needed = ctypes.c_size_t()
        assert lib.texel_encode2d_result_json(result, None, 0, ctypes.byref(needed)) == TEXEL_OK
        buf = ctypes.create_string_buffer(needed.value)
        assert lib.texel_encode2d_result_json(result, buf, needed.value, None) == TEXEL_OK
        return "ok", texture_of(json.loads(buf.value.decode()))
    finally:
        lib.texel_encode2d_result_destroy(result)


def main_2d():
    y, x = np.mgrid[0:SIZE, 0:SIZE] * PITCH
    m = 0.5 + 0.25 * np.sin(2 * np.pi * 2.0 * x) * np.cos(2 * np.pi * 1.3 * y) + 0.2 * np.random.default_rng(7).random((SIZE, SIZE))
    m = np.clip(m, 0, 1)
    nan = m.copy()
    nan[3, 5] = np.nan
    cases = [("in_range", m, "ok", None), ("times_100", m * 100, "ok", None), ("times_minus_1", m * -1, "ok", None),
             ("constant_2", np.full(m.shape, 2.0), "refused", "constant: it holds no texture"),
             ("non_finite", nan, "refused", "non-finite")]
    failures = 0
    answers = {}
    for name, a, want, words in cases:
        got = {"CLI": via_cli_2d(name, a), "Python": via_python_2d(a), "C": via_c_2d(a)}
        kinds = {door: g[0] for door, g in got.items()}
        if set(kinds.values()) != {want}:
            print(f"FAIL 2-D {name}: expected {want} from every front door, got {got}")
            failures += 1
        elif want == "ok" and len({g[1] for g in got.values()}) != 1:
            print(f"FAIL 2-D {name}: different textures: {got}")
            failures += 1
        elif want == "refused" and any(words not in g[1] for g in got.values()):
            print(f"FAIL 2-D {name}: refusals without '{words}': {got}")
            failures += 1
        else:
            answers[name] = got["C"][1]
            print(f"2-D {name}: one answer from CLI, Python and C: {got['C'][1]}")
    # Scaled, not clamped: x100 of an in-range map is the same map scaled to full range.
    return failures


main()
if main_2d():
    sys.exit(1)
print("one input, one answer in 2-D too")
