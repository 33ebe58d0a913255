"""Options described once (texel/option_spec.hpp): the analysis options'
defaults, ranges and spellings are the library's, and every front door shows
and applies exactly those — the CLI's `texel experiment analyze` flags and
help, Python's keyword arguments and the package's stub. A default edited by
hand in the stub (or a CLI copy of one) fails here."""
import inspect
import json
import math

import pytest

import texel
from texel.experiment import analysis_options, analyze, simulate_cohort


def _shown(default):
    """A default as the CLI's help shows it: the spelling, or the shortest exact number."""
    if isinstance(default, str):
        return default
    if isinstance(default, float):
        return repr(default) if default != int(default) else str(int(default))
    return str(default)


def test_the_stub_states_the_librarys_defaults():
    described = analysis_options()
    params = inspect.signature(analyze).parameters
    keys = [o["key"] for o in described]
    assert keys, "the library describes the analysis options"
    assert [k for k in params if k not in ("db", "csv", "out_dir")] == keys, "the stub lists every option, in order"
    for o in described:
        assert params[o["key"]].default == o["default"], f"{o['key']}: the stub's default is not the library's"
        if "choices" in o:
            assert o["default"] in o["choices"]


def test_the_cli_flags_and_help_are_the_librarys(cli):
    help_text = " ".join(cli("experiment", "analyze", "--help").stdout.split())
    for o in analysis_options():
        assert o["flag"] in help_text, f"the CLI has no {o['flag']}"
        if isinstance(o["default"], bool):
            continue
        assert f"[{_shown(o['default'])}]" in help_text.split(o["flag"], 1)[1].split(" --", 1)[0], (
            f"{o['flag']}: the CLI's help does not show the library's default {o['default']!r}"
        )


def test_one_rule_for_a_bad_value(cli, tmp_path):
    csv = tmp_path / "none.csv"
    csv.write_text("")
    bad = {"format": "jpg", "convergent": "mean", "memory_rule": "z-score", "level": 1.0, "reversals_k": 0,
           "memory_errors_sd": 0.0, "memory_recall_chance": 1.0, "confidence_distance": "median"}
    described = {o["key"]: o for o in analysis_options()}
    assert set(bad) <= set(described)
    for key, value in bad.items():
        with pytest.raises(texel.InvalidArgument) as py_error:
            analyze(csv=csv, **{key: value})
        r = cli("experiment", "analyze", "--csv", csv, described[key]["flag"], value, check=False)
        assert r.returncode == 2, r.stderr
        # One refusal, each front door naming the option its own way.
        py_text = str(py_error.value)
        cli_text = r.stderr.strip().splitlines()[-1]
        assert py_text.startswith(f"{key} is "), py_text
        assert described[key]["flag"] + py_text[len(key):] in cli_text, (py_text, cli_text)
    with pytest.raises(texel.InvalidArgument, match="unknown option 'reversals'; allowed: format, reversals_k"):
        analyze(csv=csv, reversals=3)
    with pytest.raises(texel.InvalidArgument, match="exactly one of db= or csv="):
        analyze()


def test_python_and_the_cli_give_one_analysis(cli, source_dir, tmp_path):
    db = tmp_path / "s.db"
    protocol = source_dir / "examples" / "protocols" / "coarse-features.json"
    with texel.Store(db, mode="rw") as store:
        simulate_cohort(store, protocol, ["C1", "C2", "C3"])
    options = {"reversals_k": 2, "convergent": "next", "level": 0.9}
    mine = analyze(db=db, out_dir=tmp_path / "figs", format="svg", **options)
    theirs = json.loads(cli("experiment", "analyze", "--db", db, "--reversals", "2", "--convergent", "next",
                            "--level", "0.9", "--json").stdout)
    assert mine["summary"] == theirs
    assert mine["figures"] and all(f.endswith(".svg") for f in mine["figures"])
    assert not math.isnan(mine["summary"]["coarse-features"]["blocks"][0]["convergent"]["mean"])
