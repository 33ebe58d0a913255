"""Bitstreams, encode and decode against the CLI; spectra."""
import numpy as np
import pytest

import texel


@pytest.fixture(scope="module")
def encoded(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("codec")
    src = d / "in.bin"
    cli("render", "--central-pitch", 6, "--irregularity", -8, "--seed", 5, "-o", src)
    out = d / "in.texel"
    cli("encode", src, "--device", "tpad", "-o", out)
    return src, out


def test_encode_array_equals_cli_bitstream(encoded):
    src, out = encoded
    m = np.fromfile(src, dtype="<u2")
    r = texel.encode(m)
    assert r.bytes == out.read_bytes()
    assert texel.encode(str(src), device="tpad").bytes == out.read_bytes()
    assert set(r.percept) == {"pitch_db", "noisiness_db", "centroid_db", "spread_db", "drawn_pitch_db", "drawn_noisiness_db"}
    assert r.spec["texel_length_mm"] == pytest.approx(0.25)
    assert r.model_distance >= 0


def test_encode_result_names_model_flags_and_serialises_like_the_cli(encoded, cli, tmp_path):
    import json
    src, _ = encoded
    r = texel.encode(str(src), device="tpad")
    assert r.distance_jnd == r.model_distance  # the old name, readable for a release
    assert r.model_version == 2 and not r.no_texture
    assert r.at_bound == {"central_pitch": False, "irregularity": False}
    j = json.loads(r.to_json())
    c = json.loads(cli("encode", src, "--device", "tpad", "--json").stdout)
    assert j["model"]["version"] == c["model"]["version"] == 2
    assert j["model"]["distance_jnd"] == c["model"]["distance_jnd"]
    assert j["estimate"] == c["estimate"]
    assert texel.encode(str(src), device="tpad", model=1).model_version == 1
    flat = np.full(19200, 0.5)
    assert texel.encode(flat).no_texture
    with pytest.raises(ValueError, match="no texture"):
        texel.encode(flat, no_texture="refuse")


def test_encode_fit_method_equals_the_cli(cli, tmp_path):
    src = tmp_path / "saw.bin"
    cli("reference", "saw", "--device", "tpad", "-o", src)
    for fit in ("least-squares", "simplex"):
        out = tmp_path / f"saw-{fit}.texel"
        cli("encode", src, "--device", "tpad", "--fit", fit, "-o", out)
        assert texel.encode(str(src), device="tpad", fit=fit).bytes == out.read_bytes()
    with pytest.raises(ValueError, match="fit is 'newton'"):
        texel.encode(str(src), device="tpad", fit="newton")


def test_encode_display_in_the_loop_equals_the_cli(cli, tmp_path):
    # The device's frequency response is in the model's loop by default, as
    # `texel encode --device tpad`; 'flat' and drawn_weight as their flags.
    src = tmp_path / "pink.bin"
    cli("reference", "pink", "--device", "tpad", "-o", src)
    streams = {}
    for flags in ((), ("--display-response", "flat"), ("--drawn-weight", "0")):
        out = tmp_path / f"pink{len(streams)}.texel"
        cli("encode", src, "--device", "tpad", *flags, "-o", out)
        streams[flags] = out.read_bytes()
    assert texel.encode(str(src), device="tpad").bytes == streams[()]
    assert texel.encode(np.fromfile(src, dtype="<u2")).bytes == streams[()]  # an array defaults to the tpad
    assert texel.encode(str(src), device="tpad", display_response="flat").bytes == streams[("--display-response", "flat")]
    assert texel.encode(str(src), device="tpad", drawn_weight=0).bytes == streams[("--drawn-weight", "0")]
    assert len(set(streams.values())) == 3
    with pytest.raises(ValueError, match="drawn_weight is -1"):
        texel.encode(str(src), device="tpad", drawn_weight=-1)


def test_decode_equals_cli(cli, encoded, tmp_path):
    _, stream = encoded
    for device in ("tpad", "generic"):
        out = tmp_path / f"dec-{device}.bin"
        cli("decode", stream, "--device", device, "-o", out)
        assert texel.decode(stream.read_bytes(), device=device).tobytes() == out.read_bytes()
        assert texel.decode(str(stream), device=device).tobytes() == out.read_bytes()


def test_bitstream_round_trip(encoded):
    _, stream = encoded
    data = stream.read_bytes()
    b = texel.parse_bitstream(data)
    assert b.to_bytes() == data
    assert b.spec["central_pitch_db"] == pytest.approx(b.central_pitch_db)
    doc = texel.decode_document(b)
    assert texel.bitstream_from_document(doc) == b or texel.bitstream_from_document(doc).central_pitch_db == b.central_pitch_db


def test_bitstream_from_document_decodes_to_the_same_map():
    doc = texel.document(central_pitch_db=7.5, irregularity_db=-6, seed=12)
    b = texel.bitstream_from_document(doc)
    assert texel.decode(b.to_bytes()).tobytes() == doc.render().tobytes()


def test_spectrum_of_a_sinusoid():
    dx = 0.01
    x = np.arange(4096) * dx
    a = 0.5 + 0.3 * np.sin(2 * np.pi * 5.0 * x)
    s = texel.magnitude_spectrum(a, dx)
    k = int(np.argmax(s.magnitude))
    assert s.frequency_cpm[k] == pytest.approx(5.0, abs=s.bin_cpm)
    r = texel.analyse_spectrum(a, dx)
    assert r["peaks"][0]["frequency_cpm"] == pytest.approx(5.0, rel=1e-3)
    assert r["peaks"][0]["amplitude"] == pytest.approx(0.3, rel=1e-2)
    assert r["mean"] == pytest.approx(0.5, abs=1e-3)


def test_spectrum_equals_cli_json(cli_json, tmp_path):
    out = tmp_path / "m.bin"
    m = texel.render(seed=7)
    m.tofile(out)
    j = cli_json("spectrum", out, "--device", "tpad", "--json")
    r = texel.analyse_spectrum(m.astype(np.float64) / 65535.0, texel.device("tpad").spacing_mm)
    assert r["spectrum"].nfft == j["nfft"]
    assert r["mean"] == pytest.approx(j["mean_amplitude"], rel=1e-12)
    assert r["rms"] == pytest.approx(j["rms_amplitude"], rel=1e-9)
    assert r["summary"]["centroid_cpm"] == pytest.approx(j["summary"]["centroid_cpm"], rel=1e-9)
    assert [p["frequency_cpm"] for p in r["peaks"]] == pytest.approx([p["frequency_cpm"] for p in j["peaks"]], rel=1e-9)


def test_transcode_is_exact_and_equals_the_cli(cli, tmp_path):
    doc = tmp_path / "d.texel.json"
    cli("render", "--central-pitch", "8", "--irregularity", "0", "--texel-length", "0.5", "--seed", "3",
        "--device", "tpad", "-o", doc)
    out = tmp_path / "d.texel"
    cli("encode", doc, "-o", out)
    t = texel.transcode(str(doc))
    assert t.exact and t.losses == []
    assert t.bytes == out.read_bytes()
    assert t.spec["seed"] == 3
    assert texel.transcode(t.bytes).bytes == t.bytes  # idempotent
    d = texel.load_document(str(doc))
    assert texel.transcode(d).bytes == t.bytes
    for device in ("tpad", "generic"):
        want = tmp_path / f"{device}.bin"
        cli("render", doc, "--device", device, "-o", want)
        assert texel.decode(t.bytes, device=device).tobytes() == want.read_bytes()
    lossy = texel.transcode(texel.document(central_pitch_db=8.004, seed=3))
    assert not lossy.exact and "central_pitch_db" in lossy.losses[0]
    with pytest.raises(texel.InvalidArgument, match="cannot be transcoded"):
        m = tmp_path / "m.bin"
        cli("render", "--seed", "3", "-o", m)
        texel.transcode(str(m), device="tpad")


def ridges(n=19200, dx=0.01, seed=7):
    """Regular ridges at 2 cycles/mm with two harmonics plus fine grit: a texture whose felt pitch (near the
    fundamental) and log-spectral centroid (pulled up by the grit) differ by several dB."""
    x = np.arange(n) * dx
    rng = np.random.default_rng(seed)
    y = np.sin(2 * np.pi * 2 * x) + 0.5 * np.sin(2 * np.pi * 4 * x + 1) + 0.25 * np.sin(2 * np.pi * 6 * x + 2)
    for _ in range(100):
        y += 0.05 * np.sin(2 * np.pi * 2 * 2 ** (1.5 + 0.5 * rng.normal()) * x + rng.uniform(0, 2 * np.pi))
    return (y - y.min()) / (y.max() - y.min())


def test_encode_target_changes_the_result_and_equals_the_cli(cli_json, tmp_path):
    a = ridges()
    felt = texel.encode(a, spacing_mm=0.01)  # an array is a map: automatic is felt
    assert felt.target == "felt" and texel.encode(a, spacing_mm=0.01, target="felt").bytes == felt.bytes
    centroid = texel.encode(a, spacing_mm=0.01, target="centroid")
    assert centroid.target == "centroid"
    assert centroid.central_pitch_db > felt.central_pitch_db + 1.0  # the grit raises the centroid
    np.save(tmp_path / "r.npy", a)
    j = cli_json("encode", tmp_path / "r.npy", "--spacing", 0.01, "--target", "centroid", "-o", tmp_path / "r.texel",
                 "--json")
    assert (tmp_path / "r.texel").read_bytes() == centroid.bytes
    assert j["model"]["target"] == "centroid"


def test_encode_recording_defaults_to_the_centroid_target(tmp_path):
    fs, speed = 10000.0, 100.0
    x = ridges(n=10000, dx=speed / fs)
    rec = tmp_path / "rec.csv"
    rec.write_text("time_s,value\n" + "".join(f"{i / fs!r},{v!r}\n" for i, v in enumerate(x)))
    auto = texel.encode(rec, swipe_speed_mm_s=speed)
    assert auto.target == "centroid"
    felt = texel.encode(rec, swipe_speed_mm_s=speed, target="felt")
    assert felt.target == "felt" and felt.central_pitch_db != auto.central_pitch_db


def test_encode_refuses_an_unknown_target():
    with pytest.raises(texel.InvalidArgument, match="target is 'loudest'; allowed: automatic, felt, centroid"):
        texel.encode(ridges(n=4096), spacing_mm=0.01, target="loudest")
