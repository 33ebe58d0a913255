"""Engine errors arrive as texel.Error subclasses carrying the engine's message."""
import pytest

import texel


def test_hierarchy():
    assert issubclass(texel.InvalidArgument, texel.Error)
    assert issubclass(texel.InvalidArgument, ValueError)
    assert issubclass(texel.FormatError, texel.Error)
    assert issubclass(texel.IoError, texel.Error)
    assert issubclass(texel.IoError, OSError)
    assert issubclass(texel.Error, RuntimeError)


def test_invalid_texel_length_names_field_and_value():
    with pytest.raises(texel.InvalidArgument) as e:
        texel.render(texel_length_mm=-1)
    assert "texel_length" in str(e.value) and "-1" in str(e.value)
    with pytest.raises(ValueError):
        texel.render(coarse_strength=2)


def test_same_message_as_the_engine_gives_the_cli(cli, tmp_path):
    # A document with a bad field: the CLI prints the library's message after "error: ".
    doc = texel.document(seed=3)
    text = doc.to_json().replace('"seed": 3', '"seed": -3')
    bad = tmp_path / "bad.texel.json"
    bad.write_text(text)
    r = cli("render", bad, "-o", tmp_path / "x.bin", check=False)
    assert r.returncode == 2
    with pytest.raises(texel.Error) as e:
        texel.parse_document(text, str(bad))
    assert str(e.value) in r.stderr


def test_unknown_names():
    with pytest.raises(texel.InvalidArgument, match="tpad"):
        texel.render(device="no-such-device")
    with pytest.raises(texel.InvalidArgument, match="4sin"):
        texel.reference("no-such-reference")
    with pytest.raises(texel.InvalidArgument, match="phase"):
        texel.render(phase="sideways")
    with pytest.raises(texel.InvalidArgument, match="dtype"):
        texel.render(dtype="int7")
    with pytest.raises(texel.InvalidArgument):
        texel.reference("2sin", no_such_param=3)


def test_format_errors():
    with pytest.raises(texel.FormatError):
        texel.parse_bitstream(b"\x54\x01garbage")
    with pytest.raises(texel.FormatError):
        texel.parse_document("{not json")


def test_io_error_is_an_oserror():
    with pytest.raises(OSError) as e:
        texel.load_document("/nonexistent/dir/x.texel.json")
    assert isinstance(e.value, texel.IoError)
    assert "/nonexistent/dir/x.texel.json" in str(e.value)
    with pytest.raises(texel.IoError):
        texel.Store("/nonexistent/dir/db.sqlite")


def test_procedure_errors():
    with pytest.raises(texel.InvalidArgument, match="step_sizes"):
        texel.Staircase(1.0, [])
    s = texel.Staircase.replay([False, False, False], 1.0, [1.0], n_reversals=1, n_down=1)
    if s.finished:
        with pytest.raises(texel.Error):
            s.next()
    with pytest.raises(texel.InvalidArgument, match="choice"):
        texel.GuidedOptimizer().answer("maybe")
    with pytest.raises(texel.InvalidArgument, match="no_such_key"):
        texel.optimizer("guided", no_such_key=1)
