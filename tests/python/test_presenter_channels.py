"""texel.experiment.Presenter on a multi-actuator display (issue #40): the
channels= option, presentation_channels() of a protocol, and the one-line
refusal of a document whose device has more actuators than the presenter
has channels (the library's tests check what each channel plays:
tests/experiment/test_presenter_channels.cpp)."""
import json
import os
import pathlib

import pytest

import texel
from texel.experiment import Presenter, presentation_channels

SOURCE = pathlib.Path(os.environ.get("TEXEL_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))

PAD4 = {"name": "pad-4", "samples": 10000, "spacing_mm": 0.01, "format": "f32le", "refresh_hz": 48000,
        "actuators": [{"name": f"a{c}", "offset_mm": 2 * c - 3} for c in range(4)]}


def doc(playback):
    return json.dumps({"format": "texel-document", "version": 6, "device": PAD4, "playback": {"mode": playback},
                       "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": 5,
                                   "texel_length_mm": 0.25, "seed": 40}})


def test_a_four_channel_presenter_plays_a_simultaneous_document():
    with Presenter("null", channels=4) as p:
        assert p.channels == 4
        assert "4 channels" in p.describe()
        p.show(doc("simultaneous"))
        p.wait(0.05)
        p.show(doc("sequential"))
        p.wait(0.05)
        assert p.stats["blocks"] > 0
        assert p.shown == 2


def test_a_one_channel_presenter_refuses_a_four_actuator_document():
    with Presenter("null") as p:
        with pytest.raises(texel.InvalidArgument, match="'pad-4' has 4 actuators; this presenter plays 1 channel: "
                                                        "open it with channels 4"):
            p.show(doc("simultaneous"))
    with pytest.raises(texel.InvalidArgument, match="channels is 4, but backend serial:/nonexistent"):
        Presenter("serial:/nonexistent", channels=4)


def test_presentation_channels_is_the_protocols_device():
    protocol = json.loads((SOURCE / "examples/protocols/texel-length.json").read_text())
    assert presentation_channels(protocol) == 1
