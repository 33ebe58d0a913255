"""One scaling rule for arrays and files (docs/format.md "Input signals"):
an array is read as the .npy file np.save() writes from it, so encode(x) and
encode('x.npy') agree — signed data, values above 1 and integer samples
included — and both agree with the CLI."""
import numpy as np
import pytest

import texel

X = texel.render(seed=7, dtype="float64")

CASES = {
    "negative": X * 2 - 5,
    "above_one": X * 3,
    "uint16": texel.render(seed=7),
    "uint8": texel.render(seed=7, dtype="uint8"),
    "int16": np.round((X - 0.5) * 20000).astype("<i2"),
    "float32": (X * 2 - 5).astype("<f4"),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_array_reads_as_its_npy_file(name, tmp_path):
    a = CASES[name]
    path = tmp_path / f"{name}.npy"
    np.save(path, a)
    from_array = texel.load_signal(a, device="tpad")
    from_file = texel.load_signal(path, device="tpad")
    assert np.array_equal(from_array.samples, from_file.samples)
    assert from_array.scaled == from_file.scaled == (name in ("negative", "above_one", "int16", "float32"))
    assert from_array.samples.min() >= 0 and from_array.samples.max() <= 1


def test_byte_order_and_lists_follow_the_same_rule():
    a = CASES["negative"]
    assert np.array_equal(texel.load_signal(a.astype(">f8"), spacing_mm=0.01).samples,
                          texel.load_signal(a, spacing_mm=0.01).samples)
    assert np.array_equal(texel.load_signal(list(a[:100]), spacing_mm=0.01).samples,
                          texel.load_signal(a[:100], spacing_mm=0.01).samples)


def test_a_dtype_the_rule_does_not_read_is_refused():
    with pytest.raises(texel.FormatError, match="<i8"):
        texel.load_signal(np.arange(100, dtype=np.int64), spacing_mm=0.01)
    with pytest.raises(texel.FormatError, match="constant"):
        texel.encode(np.full(1000, 3.0))


@pytest.mark.parametrize("name", ["negative", "above_one", "int16"])
def test_encode_array_equals_encode_file_and_cli(name, tmp_path, cli):
    a = CASES[name]
    path = tmp_path / f"{name}.npy"
    np.save(path, a)
    r_array = texel.encode(a)  # an array is on the tpad unless told otherwise
    r_file = texel.encode(path, device="tpad")
    assert r_array.bytes == r_file.bytes
    assert r_array.percept == r_file.percept
    cli("encode", path, "--device", "tpad", "-o", tmp_path / "cli.texel")
    assert (tmp_path / "cli.texel").read_bytes() == r_array.bytes
    if name == "negative":
        # Issue 25: the array once clipped to a flat texture (C = 1, F = 0).
        assert r_array.fine_strength > 0.5 and abs(r_array.central_pitch_db - 10) < 1.5
