#!/usr/bin/python3
"""What `texel render -o X.mat` writes, read by independent readers.

v5 through scipy.io.loadmat, v7.3 through h5py (both Debian packages, run by
/usr/bin/python3). Checks names, shapes (MATLAB column-major: N×1 columns),
values (the map equals the .npy output exactly; positions are i·spacing),
the parameters, the texel listing, the document text, and that the encoder
accepts the file. Also `texel spectrum -o s.mat` and `texel experiment export -o trials.mat`
against their CSV outputs. Usage: check_cli_mat.py TEXEL_BINARY WORKDIR
[PROTOCOLS_DIR]
"""
import csv
import json
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np
import scipy.io

texel, work = sys.argv[1], os.path.abspath(sys.argv[2])
protocols = os.path.abspath(sys.argv[3]) if len(sys.argv) > 3 else None
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
os.chdir(work)

ARGS = ["--central-pitch", "10", "--irregularity", "-5", "--texel-length", "0.25", "--seed", "7", "--device", "tpad"]


def run(*args):
    r = subprocess.run([texel, *args], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"texel {' '.join(args)} failed ({r.returncode}): {r.stderr}")
    return r.stdout


def check(cond, what):
    if not cond:
        sys.exit("FAILED: " + what)
    print("ok:", what)


run("render", *ARGS, "-o", "map.npy")
run("render", *ARGS, "-o", "doc.texel.json")
summary = json.loads(run("render", *ARGS, "-o", "map.mat", "--json"))
run("render", *ARGS, "-o", "map73.mat", "--mat-version", "7.3")
ref = np.load("map.npy")
n = ref.size
spacing = summary["spacing_mm"]
document = open("doc.texel.json", encoding="utf-8").read()
check(n == 19200, "tpad map has 19200 samples")

# --- v5: scipy.io.loadmat ---------------------------------------------------
d = scipy.io.loadmat("map.mat")
names = sorted(k for k in d if not k.startswith("__"))
check(names == ["amplitude", "document", "params", "position_mm", "texels"], f"v5 variables {names}")
check(d["__version__"] == "1.0", "v5 file (scipy reports MAT version 1.0 for level-5 files)")
check(d["amplitude"].shape == (n, 1) and d["amplitude"].dtype == np.float64, "v5 amplitude is N×1 double")
check(np.array_equal(d["amplitude"][:, 0], ref), "v5 amplitude equals the .npy map exactly")
check(d["amplitude"].min() >= 0 and d["amplitude"].max() <= 1, "amplitude in [0, 1]")
check(d["position_mm"].shape == (n, 1), "v5 position_mm is N×1")
check(np.allclose(d["position_mm"][:, 0], np.arange(n) * spacing, rtol=0, atol=1e-9), "position_mm = i·spacing")
p = d["params"][0, 0]
check(p["central_pitch_db"][0, 0] == 10 and p["irregularity_db"][0, 0] == -5, "params: central pitch and irregularity")
check(p["texel_length_mm"][0, 0] == 0.25 and p["seed"][0, 0] == 7, "params: texel length and seed")
check(p["device"][0] == "tpad" and p["parameterization"][0] == "moments", "params: device and parameterization (char)")
check(p["spacing_mm"][0, 0] == spacing and p["samples"][0, 0] == n, "params: spacing and samples")
t = d["texels"][0, 0]
k = t["start_mm"].shape[0]
check(k > 100 and all(t[c].shape == (k, 1) for c in ("index", "start_mm", "frequency_cpm", "amplitude", "region")),
      f"texels: {k} rows, every column N×1")
check(np.allclose(np.diff(t["start_mm"][:, 0]), 0.25), "texels: start_mm steps by the texel length")
check(d["document"][0] == document, "v5 document is the texel.json text")

# --- v7.3: h5py -------------------------------------------------------------
with open("map73.mat", "rb") as f:
    check(f.read(19) == b"MATLAB 7.3 MAT-file", "v7.3 header")
h = h5py.File("map73.mat", "r")
check(sorted(h.keys()) == ["amplitude", "document", "params", "position_mm", "texels"], f"v7.3 variables {sorted(h.keys())}")
# HDF5 stores MATLAB's column-major N×1 as a row-major (1, N) dataset.
check(h["amplitude"].shape == (1, n) and h["amplitude"].attrs["MATLAB_class"] == b"double", "v7.3 amplitude: (1, N) double")
check(np.array_equal(h["amplitude"][0], ref), "v7.3 amplitude equals the .npy map exactly")
check(np.allclose(h["position_mm"][0], np.arange(n) * spacing, rtol=0, atol=1e-9), "v7.3 position_mm")
check(h["params"].attrs["MATLAB_class"] == b"struct", "v7.3 params is a struct")
check(h["params"]["central_pitch_db"][0, 0] == 10 and h["params"]["seed"][0, 0] == 7, "v7.3 params values")
dev = h["params"]["device"]
check(dev.attrs["MATLAB_class"] == b"char" and dev.dtype == np.uint16 and "".join(map(chr, dev[:, 0])) == "tpad",
      "v7.3 params.device is char 'tpad' (uint16 code units)")
# MATLAB's own marker for text stored as integers: 2 = UTF-16 (what MATLAB writes for char).
check(int(dev.attrs.get("MATLAB_int_decode", -1)) == 2, "v7.3 params.device has MATLAB_int_decode = 2")
check(int(h["document"].attrs.get("MATLAB_int_decode", -1)) == 2, "v7.3 document has MATLAB_int_decode = 2")
# The class mark as MATLAB writes it: a scalar, fixed-length ASCII string attribute.
cls = h5py.h5a.open(dev.id, b"MATLAB_class")
ctype = cls.get_type()
check(isinstance(ctype, h5py.h5t.TypeStringID) and not ctype.is_variable_str() and ctype.get_cset() == h5py.h5t.CSET_ASCII
      and cls.get_space().get_simple_extent_type() == h5py.h5s.SCALAR, "v7.3 MATLAB_class: scalar fixed-length ASCII")
doc73 = h["document"][:, 0].astype(np.uint16).tobytes().decode("utf-16-le")
check(doc73 == document, "v7.3 document is the texel.json text")
check(h["texels"]["frequency_cpm"].shape == (1, k), "v7.3 texels columns")

# --- sizes and the encoder ----------------------------------------------------
print("sizes: .npy", os.path.getsize("map.npy"), "v5", os.path.getsize("map.mat"), "v7.3", os.path.getsize("map73.mat"))
# A .mat Texel wrote carries its document: transcoded exactly, the bitstream
# of the document itself, as a .hjif with its document is.
run("encode", "doc.texel.json", "-o", "doc.texel")
for f in ("map.mat", "map73.mat"):
    out = run("encode", f, "-o", f + ".texel")
    check(open(f + ".texel", "rb").read() == open("doc.texel", "rb").read(),
          f"texel encode {f} transcodes its document exactly: {out.splitlines()[0]}")
    out = run("encode", f, "--device", "tpad", "--estimate")
    check("Central Pitch 10.00 dB" in out, f"texel encode {f} --estimate recovers the Central Pitch: {out.splitlines()[0]}")
# Without a document, a .mat is samples to estimate from.
scipy.io.savemat("plain.mat", {"amplitude": ref.reshape(-1, 1)})
out = run("encode", "plain.mat", "--device", "tpad")
check("Central Pitch 10.00 dB" in out, f"texel encode plain.mat estimates: {out.splitlines()[0]}")

# A hostile input is one line naming the file.
scipy.io.savemat("complex.mat", {"amplitude": np.array([[1 + 1j], [2 + 0j], [0.5 + 0j]])})
r = subprocess.run([texel, "encode", "complex.mat"], capture_output=True, text=True)
check(r.returncode == 2 and "complex.mat" in r.stderr and "complex" in r.stderr and r.stderr.count("\n") <= 1,
      f"complex .mat rejected: {r.stderr.strip()}")
# --- spectrum ------------------------------------------------------------------
run("spectrum", "map.npy", "--device", "tpad", "-o", "s.mat", "--spectrum-csv", "s.csv", "--psd-csv", "p.csv")
run("spectrum", "map.npy", "--device", "tpad", "-o", "s73.mat", "--mat-version", "7.3")
s = scipy.io.loadmat("s.mat")
sc = np.loadtxt("s.csv", delimiter=",", skiprows=1)
pc = np.loadtxt("p.csv", delimiter=",", skiprows=1)
check(s["frequency_cpm"].shape == (sc.shape[0], 1) and s["magnitude"].shape == (sc.shape[0], 1), "spectrum columns N×1")
check(np.allclose(s["frequency_cpm"][:, 0], sc[:, 0], rtol=1e-12) and np.allclose(s["magnitude"][:, 0], sc[:, 1], rtol=1e-12),
      "spectrum .mat equals --spectrum-csv")
check(np.allclose(s["psd"][:, 0], pc[:, 1], rtol=1e-12), "psd .mat equals --psd-csv")
check(s["peaks"][0, 0]["frequency_cpm"].shape[1] == 1 and s["params"][0, 0]["spacing_mm"][0, 0] == spacing, "spectrum peaks, params")
with h5py.File("s73.mat", "r") as h5:
    check(np.array_equal(h5["magnitude"][0], s["magnitude"][:, 0]), "spectrum v7.3 equals v5")

# --- experiment export ------------------------------------------------------------
if protocols:
    run("experiment", "run", os.path.join(protocols, "texel-length.json"), "--participant", "S01", "--db", "s.db",
        "--simulate", "threshold=6mm", "--quiet")
    run("experiment", "export", "--db", "s.db", "-o", "trials.csv")
    run("experiment", "export", "--db", "s.db", "-o", "trials.mat")
    run("experiment", "export", "--db", "s.db", "-o", "trials73.mat", "--mat-version", "7.3")
    rows = list(csv.DictReader(open("trials.csv", encoding="utf-8")))
    header = next(csv.reader(open("trials.csv", encoding="utf-8")))
    t = scipy.io.loadmat("trials.mat")["trials"][0, 0]
    check(list(t.dtype.names) == header, f"export: one field per CSV column, in order ({len(header)})")
    nr = len(rows)
    check(nr > 5 and all(t[c].shape == (nr, 1) for c in header), f"export: every field is {nr}×1")
    check(t["participant"].dtype == object and t["participant"][0, 0][0] == "S01", "export: text as cell of char")
    check(t["trial"].dtype == np.float64 and list(t["trial"][:, 0]) == [float(r["trial"]) for r in rows], "export: numbers")
    miss = [i for i, r in enumerate(rows) if r["rating"] == ""]
    check(all(np.isnan(t["rating"][i, 0]) for i in miss), "export: missing is NaN")
    check([x[0] if x.size else "" for x in t["shown_at"][:, 0]] == [r["shown_at"] for r in rows], "export: time stamps")
    with h5py.File("trials73.mat", "r") as h5:
        check(h5["trials"]["trial"].shape == (1, nr) and h5["trials"]["participant"].attrs["MATLAB_class"] == b"cell",
              "export v7.3: columns and a cell column")

print("all .mat checks passed")
