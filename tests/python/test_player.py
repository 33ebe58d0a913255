"""The player over arrays: swipe output equals `texel swipe` (float WAV, exact)."""
import struct

import numpy as np
import pytest

import texel


def read_float_wav(path):
    """The samples of a mono IEEE-float WAV (what `--wav-format float` writes), read by hand."""
    data = path.read_bytes()
    assert data[:4] == b"RIFF" and data[8:12] == b"WAVE"
    pos, fmt, samples = 12, None, None
    while pos + 8 <= len(data):
        cid, size = data[pos:pos + 4], struct.unpack("<I", data[pos + 4:pos + 8])[0]
        body = data[pos + 8:pos + 8 + size]
        if cid == b"fmt ":
            fmt = struct.unpack("<HHIIHH", body[:16])
        elif cid == b"data":
            samples = np.frombuffer(body, dtype="<f4")
        pos += 8 + size + (size & 1)
    assert fmt is not None and fmt[1] == 1 and fmt[5] == 32, fmt
    return fmt[2], samples


@pytest.mark.parametrize("flags,kwargs", [
    ([], {}),
    (["--output", "amplitude", "--rate", 8333, "--speed", 150], dict(output="amplitude", rate_hz=8333, speed_mm_s=150)),
    (["--pattern", "back-and-forth", "--extent", 30, "--duration", 1.5, "--output", "carrier", "--carrier", 200],
     dict(pattern="back-and-forth", extent_mm=30, duration_s=1.5, output="carrier", carrier_hz=200)),
    (["--output", "amplitude", "--response", "off"], dict(output="amplitude", response="off")),
])
def test_swipe_equals_cli_wav(cli, tmp_path, flags, kwargs):
    doc = texel.document(central_pitch_db=5, seed=3)
    path = tmp_path / "d.texel.json"
    doc.save(str(path))
    wav = tmp_path / "s.wav"
    cli("swipe", path, "-o", wav, "--wav-format", "float", *flags)
    rate, expected = read_float_wav(wav)
    out, pos = texel.swipe(doc, **kwargs)
    assert out.dtype == np.float32 and len(out) == len(pos) == len(expected)
    assert rate == round(kwargs.get("rate_hz", 48000))
    assert out.tobytes() == expected.tobytes()


def test_swipe_csv_positions_match_cli(cli, tmp_path):
    doc = texel.document(seed=8)
    path = tmp_path / "d.texel.json"
    doc.save(str(path))
    csv = tmp_path / "s.csv"
    cli("swipe", path, "-o", csv, "--duration", 0.2)
    rows = np.loadtxt(csv, delimiter=",", skiprows=1)
    out, pos = texel.swipe(doc, duration_s=0.2)
    assert np.allclose(rows[:, 1], pos, rtol=1e-6, atol=1e-6)
    assert np.allclose(rows[:, 2], out, rtol=1e-6, atol=1e-7)


def test_render_trace_over_a_simulated_swipe_equals_swipe():
    doc = texel.document(seed=8)
    trace = texel.simulate_swipe(speed_mm_s=100, surface_mm=doc.device.length_mm, duration_s=0.5)
    assert trace["t_s"].shape == trace["x_mm"].shape == trace["touch"].shape
    a, pa = texel.render_trace(doc, trace["t_s"], trace["x_mm"], trace["touch"], duration_s=0.5)
    b, pb = texel.swipe(doc, duration_s=0.5)
    assert a.tobytes() == b.tobytes() and pa.tobytes() == pb.tobytes()
    m = texel.swipe_measures(trace["t_s"], trace["x_mm"], trace["touch"])
    assert m["mean_speed_mm_s"] == pytest.approx(100, rel=1e-6)
    assert m["directional_proportion"] == pytest.approx(1.0)


def test_trace_errors():
    doc = texel.document()
    with pytest.raises(texel.InvalidArgument, match="non-decreasing"):
        texel.render_trace(doc, [0.0, 0.2, 0.1], [0, 1, 2], duration_s=0.1)
    with pytest.raises(texel.InvalidArgument, match="output"):
        texel.swipe(doc, output="loud")
    with pytest.raises(texel.InvalidArgument, match="response"):
        texel.swipe(doc, response="equalize")
