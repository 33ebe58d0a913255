"""texel.load_signal: the library's one loader, the same samples the CLI reads."""
import json
import wave

import numpy as np
import pytest

import texel


@pytest.fixture(scope="module")
def files(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("signal")
    for name in ("m.bin", "m.npy", "m.csv"):
        cli("render", "--central-pitch", 6, "--seed", 3, "-o", d / name)
    return d


def test_every_map_format_reads_to_the_same_samples(files):
    b = texel.load_signal(files / "m.bin", device="tpad")
    n = texel.load_signal(files / "m.npy", device="tpad")
    c = texel.load_signal(files / "m.csv")
    assert b.format == "device-map" and n.format == "npy" and c.format == "csv"
    assert len(b) == len(n) == len(c) == texel.device("tpad").samples
    assert b.spacing_mm == pytest.approx(texel.device("tpad").spacing_mm)
    assert c.spacing_mm == pytest.approx(b.spacing_mm, rel=1e-9)
    np.testing.assert_allclose(n.samples, c.samples, atol=1e-12)
    np.testing.assert_allclose(b.samples, n.samples, atol=1 / 65535)
    assert not b.samples.flags.writeable


def test_matches_the_cli(cli, files):
    s = texel.load_signal(files / "m.bin", device="tpad", region=(10.0, 20.0))
    j = json.loads(cli("info", files / "m.bin", "--device", "tpad", "--region", "10:20", "--json").stdout)
    assert j["amplitude"]["samples"] == len(s)
    assert j["amplitude"]["mean"] == pytest.approx(float(np.mean(s.samples)), rel=1e-12)
    assert j["origin_mm"] == pytest.approx(s.origin_mm)
    assert s.origin_mm >= 10.0 and s.origin_mm + (len(s) - 1) * s.spacing_mm < 20.0


def test_wav_recording_and_channel_policy(tmp_path):
    rate = 8000
    t = np.arange(800) / rate
    left = (0.5 * np.sin(2 * np.pi * 100 * t) * 32767).astype("<i2")
    right = np.zeros_like(left)
    path = tmp_path / "st.wav"
    with wave.open(str(path), "wb") as w:
        w.setnchannels(2)
        w.setsampwidth(2)
        w.setframerate(rate)
        w.writeframes(np.column_stack([left, right]).tobytes())
    with pytest.raises(texel.InvalidArgument, match="swipe_speed_mm_s is required"):
        texel.load_signal(path)
    with pytest.raises(texel.InvalidArgument, match="channel is not chosen.*2 channels"):
        texel.load_signal(path, swipe_speed_mm_s=100)
    s = texel.load_signal(path, swipe_speed_mm_s=100, channel=0)
    assert s.format == "wav" and s.sample_rate_hz == rate and s.scaled
    assert s.spacing_mm == pytest.approx(100 / rate)
    assert max(s.samples) == pytest.approx(1.0) and min(s.samples) >= 0.0
    np.testing.assert_allclose(texel.load_signal(path, swipe_speed_mm_s=100, channel="mix").samples, s.samples, atol=1e-12)


def test_errors_name_the_keywords(files):
    with pytest.raises(texel.InvalidArgument, match="^device is required"):
        texel.load_signal(files / "m.bin")
    with pytest.raises(texel.InvalidArgument, match="^spacing_mm is 0.5 mm"):
        texel.load_signal(files / "m.csv", spacing_mm=0.5)
    with pytest.raises(texel.InvalidArgument, match="^region"):
        texel.load_signal(files / "m.csv", region=(1000.0, 2000.0))
    with pytest.raises(texel.InvalidArgument, match="^max_samples"):
        texel.load_signal(files / "m.npy", device="tpad", max_samples=100)
    with pytest.raises(texel.InvalidArgument, match="extension"):
        texel.load_signal(files / "m.txt")
