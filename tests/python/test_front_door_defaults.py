"""One definition per option (issue 39): the options of render, encode,
swipe, play and the 2-D paths are described once by the library
(visit_options beside TexelSpec, EncoderConfig, SwipeOptions, PlayerConfig,
Path2DConfig; texel.options() reads the description), and every front door
shows exactly those defaults:

- the CLI's --help ("[default]" after each flag, made from the description);
- Python's keyword defaults as the package states them (the stub, which is
  the functions' signature) and as their docstrings state them;
- C's texel.h "[default]" comments (the *_default() values themselves are
  compared in C++: CApi.EveryDefaultIsTheLibrarysDescription).

Nothing is changed; a default edited by hand in any of these fails here.
The analysis options are checked the same way in test_options.py."""
import inspect
import pathlib
import re

import pytest

import texel

# Python's functions and the descriptions whose options they take. Each
# description's every option must be a keyword of the first function listed.
PYTHON = {
    "render": ["render", "document"],
    "encode": ["encode"],
    "swipe": ["swipe", "render_trace", "render_trace_2d", "swipe_2d"],
    "path_2d": ["simulate_path_2d", "swipe_2d"],
}
# Keywords a function takes from another description or requires: swipe_2d's
# length is the swipe's (2 s), not a bare simulated path's (1 s), and its
# rate the output's; render_trace's length is required (the trace's own).
TAKEN_ELSEWHERE = {("swipe_2d", "path_2d", "duration_s"), ("swipe_2d", "path_2d", "rate_hz"),
                   ("render_trace", "swipe", "duration_s"), ("render_trace_2d", "swipe", "duration_s")}
# The CLI commands and the descriptions whose flags they offer.
CLI = {
    "render": ["render"],
    "encode": ["encode"],
    "swipe": ["swipe", "render", "path_2d"],  # swipe also takes the texture and the 2-D path
    "play": ["play", "render", "path_2d"],
}


def _flat(text):
    return " ".join(text.split())


def _first_bracket(text):
    m = re.search(r"\[([^\]]*)\]", text)
    return m.group(1) if m else None


def _same_default(stated, described):
    """A default as a front door states it against the library's value."""
    if described["default"] is None:
        return stated is None
    if "choices" in described:
        return stated == described["default"]
    if isinstance(described["default"], bool):
        return stated is described["default"]
    return isinstance(stated, (int, float)) and not isinstance(stated, bool) and float(stated) == float(described["default"])


@pytest.mark.parametrize("name", sorted({*PYTHON, *CLI, "player"}))
def test_the_library_describes_the_operation(name):
    described = texel.options(name)
    assert described, name
    keys = [o["key"] for o in described]
    assert len(keys) == len(set(keys)), f"{name}: a key described twice"
    for o in described:
        assert o["help"] and o["default_text"], o
        if "choices" in o:
            assert o["default"] in o["choices"], o
        elif o["default"] is not None and not isinstance(o["default"], bool):
            lo, hi = o["min"], o["max"]
            v = o["default"]
            assert (v > lo if o["min_exclusive"] else v >= lo) and (v < hi if o["max_exclusive"] else v <= hi), (
                f"{name}.{o['key']}: the default {v} is outside its own range")
    with pytest.raises(texel.InvalidArgument, match="allowed: render, encode"):
        texel.options("nonsense")


def _cli_options(help_text):
    """Each option line of a CLI11 help, by its long flag: "--speed FLOAT  Swipe speed (mm/s) [100]"."""
    lines = {}
    for line in help_text.splitlines():
        m = re.match(r"\s+(?:-\w,)?(--[\w-]+)\b(.*)", line)
        if m:
            lines[m.group(1)] = m.group(2)
    return lines


@pytest.mark.parametrize("command", sorted(CLI))
def test_the_cli_shows_the_librarys_defaults(cli, command):
    options = _cli_options(cli(command, "--help").stdout)
    checked = 0
    for name in CLI[command]:
        for o in texel.options(name):
            if not o["flag"]:
                continue  # not a CLI flag (a bare path's own sample rate and length)
            assert o["flag"] in options, f"texel {command} has no {o['flag']} ({name}.{o['key']})"
            shown = _first_bracket(options[o["flag"]])
            assert shown == o["default_text"], (
                f"texel {command} {o['flag']}: the help shows [{shown}], the library's default is "
                f"{o['default_text']} ({name}.{o['key']})")
            checked += 1
    assert checked >= len(texel.options(CLI[command][0]))


@pytest.mark.parametrize("name", sorted(PYTHON))
def test_python_states_the_librarys_defaults(name):
    described = texel.options(name)
    primary = PYTHON[name][0]
    for fn_name in PYTHON[name]:
        fn = getattr(texel, fn_name)
        params = inspect.signature(fn).parameters  # the stub's (python/texel/__init__.pyi)
        doc = fn.__doc__ or ""
        for o in described:
            key = o["key"]
            if key not in params:
                assert fn_name != primary, f"texel.{primary} has no keyword {key} ({name})"
                continue
            if (fn_name, name, key) in TAKEN_ELSEWHERE:
                continue
            stated = params[key].default
            assert _same_default(stated, o), (
                f"texel.{fn_name}({key}=...): the stub says {stated!r}, the library {o['default']!r}")
            # The docstring's own "key  text [default]" line, where it has one.
            for line in doc.splitlines():
                if re.match(rf"\s*{re.escape(key)}\s{{2,}}", line) and "[" in line:
                    shown = _first_bracket(line).strip("'\"")
                    assert shown == o["default_text"], (
                        f"texel.{fn_name}'s docstring says {key} [{shown}], the library {o['default_text']}")


# texel.h: each described option's field in each struct (C name, key), and
# how C spells an enumeration's default.
C_STRUCTS = {
    ("texel_params", "render"): {"central_pitch_db": "central_pitch_db", "irregularity_db": "irregularity_db",
                                 "texel_length_mm": "texel_length_mm", "seed": "seed",
                                 "parameterization": "parameterization", "quantization_db": "quantization_db",
                                 "coarse_strength": "coarse_strength", "fine_strength": "fine_strength"},
    ("texel_encode_options", "encode"): {"boundary_mm": "boundary_mm", "texel_length_mm": "texel_length_mm",
                                         "parameterization": "parameterization", "seed": "seed",
                                         "coarse_bits": "coarse_bits", "max_bytes": "max_bytes",
                                         "model_version": "model", "refuse_no_texture": "no_texture",
                                         "target": "target"},
    ("texel_player_config", "player"): {"rate_hz": "rate_hz", "mode": "output", "gain": "gain",
                                        "carrier_hz": "carrier_hz", "prediction_s": "prediction_s",
                                        "response_handling": "response", "response_limit_db": "response_limit_db"},
    ("texel_path2d_config", "path_2d"): {"shape": "path", "speed_mm_s": "speed_mm_s", "angle_deg": "angle_deg",
                                         "start_x_mm": "start_x_mm", "start_y_mm": "start_y_mm",
                                         "radius_mm": "radius_mm", "leg_mm": "leg_mm", "zigzag_deg": "zigzag_deg",
                                         "duration_s": "duration_s", "rate_hz": "rate_hz"},
}
# C states these as numbers: 0 = none, 0/1 = flag/refuse.
C_NUMBER_FOR = {("max_bytes", None): "0", ("no_texture", "flag"): "0", ("no_texture", "refuse"): "1"}


def _c_struct_fields(header, struct):
    body = re.search(r"typedef struct " + struct + r" \{(.*?)\} " + struct + ";", header, re.S)
    assert body, f"texel.h has no struct {struct}"
    fields = {}
    for m in re.finditer(r"([A-Za-z_][A-Za-z0-9_]*)\s*;\s*/\*(.*?)\*/", body.group(1), re.S):
        fields[m.group(1)] = _flat(m.group(2))
    return fields


def test_the_c_header_states_the_librarys_defaults(source_dir):
    header = (pathlib.Path(source_dir) / "include" / "texel.h").read_text(encoding="utf-8")
    for (struct, name), fields in C_STRUCTS.items():
        described = {o["key"]: o for o in texel.options(name)}
        comments = _c_struct_fields(header, struct)
        for field, key in fields.items():
            assert field in comments, f"{struct}.{field} has no comment"
            brackets = re.findall(r"\[([^\]]*)\]", comments[field])
            stated = brackets[-1] if brackets else None  # the last: "> 0 and <= 1000 [0.25]"
            o = described[key]
            expected = C_NUMBER_FOR.get((key, o["default"]), o["default_text"])
            assert stated is not None and stated.lower() == expected.lower(), (
                f"texel.h {struct}.{field}: the comment says [{stated}], the library's default is {expected} ({name}.{key})")
