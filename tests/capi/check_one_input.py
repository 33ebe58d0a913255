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


main()
