"""2-D surfaces (issue #26) from Python: a version-4 document to 2-D arrays and
bitmap files, and 2-D finger paths through the 2-D player, each equal to the
CLI's output for the same document (`texel render --surface 2d`, `texel swipe
--path/--trace-2d/--bitmap`)."""
import json
import struct
import zlib

import numpy as np
import pytest

import texel
from test_player import read_float_wav


@pytest.fixture(scope="module")
def golden(source_dir):
    """The 2-D golden document (160 × 96 pixels of 0.05 mm, four regions) with its spectral region made of
    texel cells: the spectral field takes seconds to prepare, and the binding does not depend on the design."""
    j = json.loads((source_dir / "tests/golden/references/v4-surface2d.texel.json").read_text())
    assert j["surface2d"]["regions"][1]["field"] == "spectral"
    j["surface2d"]["regions"][1]["field"] = "cells"
    return texel.parse_document(json.dumps(j))


def variant(doc, one_region=False, **bitmap):
    """The document with its device's bitmap fields changed and/or only its first region (whole surface)."""
    j = json.loads(doc.to_json())
    j["device"]["bitmap"].update(bitmap)
    if one_region:
        r = j["surface2d"]["regions"][0]
        r.pop("width_mm"), r.pop("height_mm")
        j["surface2d"]["regions"] = [r]
    return texel.parse_document(json.dumps(j))


def png_pixels(path):
    """Grey pixels of a PNG written without filters (as write_bitmap writes them), decoded by hand."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        size, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + size]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + size
    width, height, depth = header[0], header[1], header[2]
    raw = zlib.decompress(idat)
    stride = width * depth // 8 + 1
    rows = [raw[j * stride:(j + 1) * stride] for j in range(height)]
    assert all(r[0] == 0 for r in rows)  # filter type None
    return np.frombuffer(b"".join(r[1:] for r in rows), dtype=">u2" if depth == 16 else "u1").reshape(height, width)


def save(doc, tmp_path, name="d.texel.json"):
    path = tmp_path / name
    doc.save(str(path))
    return path


def test_render_2d_shape_dtype_and_strips(golden):
    assert repr(golden) == "<texel.Document on 'golden-2d', 2-D, 4 region(s)>"
    info = texel.bitmap_info(golden)
    assert info["width_px"] == 160 and info["height_px"] == 96 and info["pixel_pitch_mm"] == 0.05
    a = texel.render_2d(golden)
    assert a.shape == (96, 160) and a.dtype == np.float64 and 0 <= a.min() and a.max() <= 1
    assert np.array_equal(texel.render_2d(golden, rows=(37, 11)), a[37:48])
    assert np.array_equal(texel.render_2d(golden, rows=(95, 1)), a[95:])
    assert texel.render_2d(golden, rows=(96, 0)).shape == (0, 160)
    assert np.array_equal(texel.render_2d(golden, dtype="float32"), a.astype(np.float32))
    native = texel.render_2d(golden, dtype="native")  # depth 16, darker = more friction: round(a·65535)
    assert native.dtype == np.uint16 and np.array_equal(native, np.round(a * 65535).astype(np.uint16))
    assert texel.bitmap_info(texel.device("tpad")) is None


def test_render_2d_equals_cli_npy_and_png(golden, cli, tmp_path):
    path = save(golden, tmp_path)
    cli("render", path, "--surface", "2d", "-o", tmp_path / "cli.npy")
    assert np.array_equal(np.load(tmp_path / "cli.npy"), texel.render_2d(golden))
    for depth in (8, 16):
        cli("render", path, "--surface", "2d", "--depth", depth, "-o", tmp_path / f"cli{depth}.png")
        stats = texel.write_bitmap(golden, tmp_path / f"py{depth}.png", depth=depth)
        assert stats["depth_bits"] == depth and (stats["width_px"], stats["height_px"]) == (160, 96)
        assert (tmp_path / f"py{depth}.png").read_bytes() == (tmp_path / f"cli{depth}.png").read_bytes()
        assert np.array_equal(png_pixels(tmp_path / f"cli{depth}.png"), texel.render_2d(golden, dtype=f"uint{depth}"))


def test_native_pixels_follow_the_device_depth_and_polarity(golden, cli, tmp_path):
    doc = variant(golden, depth_bits=8, polarity="brighter_more_friction")
    native = texel.render_2d(doc, dtype="native")
    assert native.dtype == np.uint8
    assert np.array_equal(native, np.round((1 - texel.render_2d(doc)) * 255).astype(np.uint8))
    cli("render", save(doc, tmp_path), "--surface", "2d", "-o", tmp_path / "cli.png")
    assert np.array_equal(png_pixels(tmp_path / "cli.png"), native)


def test_coarse_raster(golden):
    r = texel.coarse_raster(golden)
    assert r["values"].shape == (96, 160) and r["values"].dtype == np.float32 and r["pitch_mm"] == 0.05
    # Region 0 is a disc at (2, 1.2) mm, radius 1: inside 1, outside 0.2; other regions read 0.
    assert r["values"][24, 40] == pytest.approx(1.0) and r["values"][2, 2] == pytest.approx(0.2)
    assert r["values"][24, 120] == 0.0
    assert texel.coarse_raster(golden, region=1, pitch_mm=0.1)["values"].shape == (48, 80)


@pytest.mark.parametrize("kwargs,rows", [(dict(dtype="int32"), None), ({}, (90, 10)), ({}, (-1, 2))])
def test_render_2d_refuses_bad_arguments(golden, kwargs, rows):
    with pytest.raises(texel.InvalidArgument, match="dtype|rows"):
        texel.render_2d(golden, rows=rows, **kwargs)


def test_a_1d_document_has_no_2d_rendering():
    with pytest.raises(texel.InvalidArgument, match="not a 2-D document"):
        texel.render_2d(texel.document())


@pytest.mark.parametrize("flags,kwargs", [
    (["--path", "line", "--angle", 37, "--start-y", 1], dict(path="line", angle_deg=37, start_y_mm=1)),
    (["--path", "circle", "--radius", 1, "--start", 2, "--start-y", 1.2, "--speed", 50],
     dict(path="circle", radius_mm=1, start_x_mm=2, start_y_mm=1.2, speed_mm_s=50)),
    (["--path", "zigzag", "--leg", 1.5, "--zigzag-angle", 60, "--start-y", 2, "--output", "amplitude"],
     dict(path="zigzag", leg_mm=1.5, zigzag_deg=60, start_y_mm=2, output="amplitude")),
])
def test_swipe_2d_equals_cli_wav(golden, cli, tmp_path, flags, kwargs):
    doc = variant(golden, one_region=True)
    wav = tmp_path / "s.wav"
    cli("swipe", save(doc, tmp_path), "-o", wav, "--wav-format", "float", "--duration", 0.25, *flags)
    _, expected = read_float_wav(wav)
    out, x, y = texel.swipe_2d(doc, duration_s=0.25, **kwargs)
    assert out.dtype == np.float32 and len(out) == len(x) == len(y) == len(expected) == 12000
    assert out.tobytes() == expected.tobytes()


def test_render_trace_2d_equals_cli_trace_and_bitmap(golden, cli, tmp_path):
    doc = variant(golden, one_region=True)
    path = save(doc, tmp_path)
    trace = texel.simulate_path_2d(path="circle", radius_mm=1, start_x_mm=2, start_y_mm=1.5, speed_mm_s=40,
                                   duration_s=0.2)
    assert trace.shape == (202, 4) and trace[-1, 3] == 0 and trace[:-1, 3].all()
    csv = tmp_path / "trace.csv"
    csv.write_text("time_s,x_mm,y_mm,touch\n" + "".join(f"{t!r},{x!r},{y!r},{int(c)}\n" for x, y, t, c in trace))
    cli("swipe", path, "--trace-2d", csv, "-o", tmp_path / "t.wav", "--wav-format", "float")
    out, x, y = texel.render_trace_2d(doc, trace)
    assert out.tobytes() == read_float_wav(tmp_path / "t.wav")[1].tobytes()
    assert x[0] == pytest.approx(3.0) and y[0] == pytest.approx(1.5)
    # Without the touch column the finger never lifts: the same output until the trace's last sample.
    touching, _, _ = texel.render_trace_2d(doc, trace[:, :3])
    assert np.array_equal(touching[:9600], out[:9600]) and not np.array_equal(touching, out)
    # Bitmap mode: the document's friction bitmap at (x, y), as `--bitmap map.npy`.
    np.save(tmp_path / "m.npy", texel.render_2d(doc))
    cli("swipe", path, "--trace-2d", csv, "--bitmap", tmp_path / "m.npy", "--raster-pitch", 0.05, "-o",
        tmp_path / "b.wav", "--wav-format", "float")
    bitmap, _, _ = texel.render_trace_2d(doc, trace, mode="bitmap")
    assert bitmap.tobytes() == read_float_wav(tmp_path / "b.wav")[1].tobytes()
    assert not np.array_equal(bitmap, out)


def test_path_at_lift(golden):
    doc = variant(golden, one_region=True)
    a = texel.simulate_path_2d(path="line", start_y_mm=1, duration_s=0.05)
    b = a.copy()
    b[:, 2] += 0.1  # the same stroke again after a lift
    trace = np.vstack([a, b])
    keep, _, _ = texel.render_trace_2d(doc, trace, output="amplitude")
    reset, _, _ = texel.render_trace_2d(doc, trace, output="amplitude", path_at_lift="reset")
    first = slice(0, 2400)
    assert np.array_equal(keep[first], reset[first])  # the first stroke is the same
    assert not np.array_equal(keep, reset)  # the second starts over only with reset


@pytest.mark.parametrize("trace,match", [
    (np.zeros((3, 2)), r"shape \(3, 2\)"),
    (np.zeros(3), r"shape \(3,\)"),
    (np.zeros((0, 3)), r"N >= 1"),
    ([[0, 0, 1], [0, 0, 0.5]], r"trace\[1, 2\] \(t_s\)"),
    ([[0, np.nan, 0], [0, 0, 0.5]], r"trace\[0, 1\] is not finite"),
])
def test_render_trace_2d_refuses_bad_traces(golden, trace, match):
    with pytest.raises(texel.InvalidArgument, match=match):
        texel.render_trace_2d(variant(golden, one_region=True), trace, duration_s=0.1)


@pytest.mark.parametrize("kwargs,match", [
    (dict(mode="texture"), "mode is 'texture'"),
    (dict(path_at_lift="hold"), "path_at_lift is 'hold'"),
    (dict(path="spiral"), "path"),
    (dict(speed_mm_s=0), "speed_mm_s"),
    (dict(zigzag_deg=180, path="zigzag"), "zigzag_deg"),
])
def test_swipe_2d_refuses_bad_options(golden, kwargs, match):
    with pytest.raises(texel.InvalidArgument, match=match):
        texel.swipe_2d(variant(golden, one_region=True), duration_s=0.05, **kwargs)


def test_a_surface_of_several_regions_plays_only_as_a_bitmap(golden):
    with pytest.raises(texel.InvalidArgument, match="one region; the document has 4"):
        texel.swipe_2d(golden, duration_s=0.05)
    out, _, _ = texel.swipe_2d(golden, mode="bitmap", duration_s=0.05, start_y_mm=1)
    assert len(out) == 2400 and np.any(out != 0)


def test_write_bitmap_refuses_other_extensions(golden, tmp_path):
    with pytest.raises(texel.InvalidArgument, match="png, .npy"):
        texel.write_bitmap(golden, tmp_path / "m.bmp")
    assert not (tmp_path / "m.bmp").exists()


# ------------------------------------------------------------ 2-D encoding
CHEAP = dict(directions=4, scan_samples=1024, correction_rounds=0)  # the encoder's own tests measure its accuracy


@pytest.fixture(scope="module")
def square_map(golden):
    """A 400 × 400 map of 0.05 mm pixels (20 mm square): large enough to scan 1024 samples along every direction."""
    doc = variant(golden, one_region=True, width_px=400, height_px=400)
    return texel.render_2d(doc)


def test_encode_2d_array_equals_its_npy_file(square_map, tmp_path):
    r = texel.encode_2d(square_map, pitch_mm=0.05, **CHEAP)
    np.save(tmp_path / "m.npy", square_map)
    assert texel.encode_2d(tmp_path / "m.npy", pitch_mm=0.05, **CHEAP).to_json() == r.to_json()
    j = json.loads(r.to_json())
    assert j["estimate"]["central_pitch_db"] == r.central_pitch_db and j["method"] == "bitmap" == r.method
    assert len(r.per_direction) == 4 and [d["direction_deg"] for d in r.per_direction] == [0, 45, 90, 135]
    assert r.field in ("spectral", "cells", "oriented") and r.document.version == 4
    assert r.target == "felt" and r.model_version == 2
    assert "2-D, 1 region(s)" in repr(r.document)


def test_encode_2d_saves_a_document_that_renders(square_map, tmp_path):
    r = texel.encode_2d(square_map, pitch_mm=0.05, coarse_image_path="m.coarse.npy", **CHEAP)
    r.save(tmp_path / "m.texel.json")
    doc = texel.load_document(str(tmp_path / "m.texel.json"))
    assert texel.render_2d(doc).shape == (400, 400)
    assert (tmp_path / "m.coarse.npy").exists() == (r.coarse_image is not None)


def test_encode_2d_of_a_png_keeps_its_depth_and_polarity_as_the_cli_does(golden, cli, tmp_path):
    """An 8-bit PNG read brighter-more-friction: the document's generated device says so, as `texel encode` writes it."""
    doc = variant(golden, one_region=True, width_px=400, height_px=400, depth_bits=8)
    texel.write_bitmap(doc, tmp_path / "m.png")
    r = texel.encode_2d(tmp_path / "m.png", pitch_mm=0.05, polarity="brighter_more_friction", **CHEAP)
    bitmap = json.loads(r.document.to_json())["device"]["bitmap"]
    assert bitmap["depth_bits"] == 8 and bitmap["polarity"] == "brighter_more_friction"
    cli("encode", tmp_path / "m.png", "--pitch", "0.05", "--polarity", "brighter_more_friction", "--directions", "4",
        "-o", tmp_path / "cli.texel.json")
    assert json.loads((tmp_path / "cli.texel.json").read_text())["device"]["bitmap"] == bitmap


@pytest.mark.parametrize("source,kwargs,match", [
    (np.zeros((2, 20, 20)), dict(pitch_mm=0.05), "3 dimensions"),
    (np.zeros((20, 20)), {}, "needs pitch_mm"),
    (np.zeros((64, 64)), dict(pitch_mm=0.05, field="round"), "field is 'round'"),
    (np.zeros((64, 64)), dict(pitch_mm=0.05, target="loudest"), "target is 'loudest'"),
])
def test_encode_2d_refuses_bad_input(source, kwargs, match):
    with pytest.raises(texel.InvalidArgument, match=match):
        texel.encode_2d(source, **{**CHEAP, **kwargs})


def test_encode_2d_reads_an_array_by_the_one_input_rule():
    """Values outside [0, 1] are scaled to full range (as the CLI and C scale them), never clamped; a constant
    map outside [0, 1] holds no texture; a non-finite value is refused."""
    with pytest.raises(texel.FormatError, match="constant: it holds no texture"):
        texel.encode_2d(np.full((64, 64), 2.0), pitch_mm=0.05, **CHEAP)
    bad = np.full((64, 64), 0.5)
    bad[3, 4] = np.inf
    with pytest.raises(texel.FormatError, match="non-finite value"):
        texel.encode_2d(bad, pitch_mm=0.05, **CHEAP)
