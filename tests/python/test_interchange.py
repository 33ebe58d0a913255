"""MPEG-I Haptics (.hjif) and glTF export against the CLI; .hjif through the loader and the transcoder."""
import json

import numpy as np
import pytest

import texel


def test_export_hjif_equals_the_cli_and_round_trips(cli, tmp_path):
    doc = texel.document(seed=7)
    x = texel.export_hjif(doc, date="2026-01-02")
    src = tmp_path / "a.texel.json"
    src.write_text(texel.document_json(doc))
    out = tmp_path / "a.hjif"
    cli("export", src, "-o", out, "--date", "2026-01-02")
    assert x["json"] == out.read_text()
    assert texel.hjif_conformance_errors(x["json"]) == []
    assert x["max_error"] <= 1 / 512 and 0 < x["keyframes"] <= 19200
    # Exact: the carried document transcodes to the document's own bitstream.
    assert texel.transcode(str(out)).bytes == texel.transcode(doc).bytes
    # Samples: within the tolerance of the rendered map.
    s = texel.load_signal(str(out))
    m = texel.render_document(doc, dtype="float64")
    assert np.max(np.abs(s.samples - m)) <= 1 / 512


def test_export_options_and_errors():
    doc = texel.document(seed=3)
    j = json.loads(texel.export_hjif(doc, modality="vibrotactile-texture", tolerance=0.05, date="2026-01-02")["json"])
    assert j["perceptions"][0]["perception_modality"] == "Vibrotactile Texture"
    with pytest.raises(ValueError, match="modality"):
        texel.export_hjif(doc, modality="tickle")
    with pytest.raises(ValueError, match="tolerance"):
        texel.export_hjif(doc, tolerance=0)
    assert texel.hjif_conformance_errors('{"version": "1999"}')


def test_export_gltf():
    doc = texel.document(seed=7)
    g = json.loads(texel.export_gltf(doc, hjif_uri="a.hjif"))
    assert "MPEG_haptic_material" in g["extensionsUsed"]
    glb = texel.export_gltf(doc, hjif_uri="a.hjif", container="glb")
    assert glb[:4] == b"glTF"
    with pytest.raises(ValueError, match="container"):
        texel.export_gltf(doc, hjif_uri="a.hjif", container="usd")
