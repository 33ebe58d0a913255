"""Arrays equal the CLI's output byte for byte: render, documents, references."""
import numpy as np
import pytest

import texel


def test_acceptance_render_equals_cli_bin(cli, tmp_path):
    m = texel.render(central_pitch_db=10, irregularity_db=-5, texel_length_mm=0.25, seed=7, device="tpad")
    assert m.dtype == np.uint16 and m.shape == (19200,)
    out = tmp_path / "a.bin"
    cli("render", "--central-pitch", 10, "--irregularity", -5, "--texel-length", 0.25, "--seed", 7, "--device", "tpad", "-o", out)
    assert m.tobytes() == out.read_bytes()


def test_array_owns_its_buffer_without_copy():
    m = texel.render(seed=3)
    assert m.base is not None  # the capsule holding the engine's vector
    assert not m.flags.owndata


@pytest.mark.parametrize(
    "kwargs,flags",
    [
        (dict(central_pitch_db=3, irregularity_db=-12, texel_length_mm=0.5, seed=11, quantization_db=3),
         ["--central-pitch", 3, "--irregularity", -12, "--texel-length", 0.5, "--seed", 11, "--quantization", 3]),
        (dict(coarse_strength=0.6, fine_strength=0.8, coarse=texel.SineProfile(period_mm=7, phase_deg=30), seed=2),
         ["--coarse-strength", 0.6, "--fine-strength", 0.8, "--coarse-sine", 7, "--coarse-phase", 30, "--seed", 2]),
        (dict(parameterization="log", irregularity_db=2, phase="reset", fill="partial", out_of_band="clamp", seed=5),
         ["--parameterization", "log", "--irregularity", 2, "--phase", "reset", "--fill", "partial", "--out-of-band", "clamp",
          "--seed", 5]),
        (dict(device="generic", seed=9), ["--device", "generic", "--seed", 9]),
        (dict(length_mm=40, spacing_mm=0.01, seed=4), ["--length", 40, "--spacing", 0.01, "--seed", 4]),
    ],
)
def test_render_options_equal_cli(cli, tmp_path, kwargs, flags):
    out = tmp_path / "m.bin"
    cli("render", *flags, "-o", out)
    assert texel.render(**kwargs).tobytes() == out.read_bytes()


def test_float64_equals_cli_npy(cli, tmp_path):
    out = tmp_path / "m.npy"
    cli("render", "--seed", 7, "-o", out)
    a = texel.render(seed=7, dtype="float64")
    b = np.load(out)
    assert a.dtype == np.float64
    assert np.array_equal(a.astype(b.dtype), b)


def test_points_profile_equals_cli_csv_profile(cli, tmp_path):
    prof = tmp_path / "p.csv"
    prof.write_text("position_mm,value\n0,0\n50,1\n101.76,0.2\n")
    out = tmp_path / "m.bin"
    cli("render", "--coarse-strength", 1, "--coarse-profile", prof, "-o", out)
    a = texel.render(coarse_strength=1, coarse=texel.PointsProfile([(0, 0), (50, 1), (101.76, 0.2)]))
    b = texel.render(coarse_strength=1, coarse=texel.read_profile_csv(str(prof)))
    assert a.tobytes() == out.read_bytes() == b.tobytes()


def test_document_round_trip_and_render(cli, tmp_path):
    doc = texel.document(central_pitch_db=4, irregularity_db=-8, seed=21, description="from python")
    path = tmp_path / "d.texel.json"
    doc.save(str(path))
    again = texel.load_document(str(path))
    assert again.to_json() == doc.to_json()
    assert texel.parse_document(doc.to_json()).to_json() == doc.to_json()
    assert again.regions[0]["texel"]["central_pitch_db"] == 4
    out = tmp_path / "d.bin"
    cli("render", path, "-o", out)
    assert again.render().tobytes() == out.read_bytes()
    assert texel.render_document(again).tobytes() == out.read_bytes()


def test_texels_listing_equals_cli(cli, tmp_path):
    out, listing = tmp_path / "m.bin", tmp_path / "t.csv"
    cli("render", "--seed", 7, "-o", out, "--texels", listing)
    rows = np.loadtxt(listing, delimiter=",", skiprows=1)
    t = texel.texels(texel.document(seed=7))
    assert len(t["frequency_cpm"]) == rows.shape[0]
    assert np.allclose(t["frequency_cpm"], rows[:, 2], rtol=1e-12, atol=0)
    assert np.allclose(t["start_mm"], rows[:, 1], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name,params,flags", [
    ("4sin", {}, []),
    ("pink", {}, ["--seed", 3]),
    ("2sin", {"frequencies_cpm": [2.5, 6]}, ["--param", "frequencies_cpm=2.5,6"]),
    ("bandpass-f4-z0.5", {}, []),
])
def test_reference_equals_cli(cli, tmp_path, name, params, flags):
    out = tmp_path / "r.bin"
    cli("reference", name, *flags, "-o", out)
    seed = int(flags[flags.index("--seed") + 1]) if "--seed" in flags else 1
    a = texel.reference(name, seed=seed, **params)
    assert a.dtype == np.uint16
    assert a.tobytes() == out.read_bytes()


def test_reference_catalogue():
    names = texel.reference_names()
    assert "4sin" in names and "pink" in names
    info = texel.reference_info("2sin")
    assert any(p["key"] == "frequencies_cpm" for p in info["params"])


def test_devices():
    assert "tpad" in texel.builtin_devices()
    d = texel.device("tpad")
    assert d.samples == 19200 and d.format == "u16le"
    assert d.positions_mm[1] == pytest.approx(d.spacing_mm)
    assert texel.device("tpad", length_mm=10).samples < 19200
    assert texel.render(device=d, seed=7).tobytes() == texel.render(seed=7).tobytes()
