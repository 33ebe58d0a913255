"""Reading a session database gives the rows `texel experiment export` writes."""
import csv
import math

import numpy as np
import pytest

import texel


@pytest.fixture(scope="module")
def database(cli, tmp_path_factory, source_dir):
    d = tmp_path_factory.mktemp("store")
    db = d / "s.db"
    cli("experiment", "run", source_dir / "examples/protocols/texel-length.json", "--participant", "S01", "--db", db,
        "--simulate", "default", "--quiet")
    out = d / "trials.csv"
    cli("experiment", "export", "--db", db, "-o", out)
    with open(out, newline="") as f:
        rows = list(csv.DictReader(f))
    return db, rows


def cell_text(v):
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return "" if math.isnan(v) else v
    return str(v)


def test_records_equal_the_cli_export(database):
    db, expected = database
    records = texel.read_trials(str(db))
    assert len(records) == len(expected) > 0
    assert list(records[0].keys()) == texel.trial_columns() == list(expected[0].keys())
    for got, want in zip(records, expected):
        for k, v in got.items():
            text = cell_text(v)
            if isinstance(text, float):
                assert text == float(want[k]), k
            else:
                assert text == want[k], k


def test_columns_are_numpy(database):
    db, expected = database
    cols = texel.Store(str(db)).rows(columns=True)
    assert cols["trial"].dtype == np.int64
    assert cols["reversal"].dtype == np.bool_
    assert cols["intensity"].dtype == np.float64
    assert len(cols["participant"]) == len(expected)
    assert list(cols["participant"]) == [r["participant"] for r in expected]


def test_store_sessions_and_trials(database):
    db, expected = database
    s = texel.Store(str(db))
    assert s.participants() == ["S01"]
    (session,) = s.sessions()
    assert session["protocol"] == "texel-length" and session["trials_done"] == len(expected)
    trials = s.trials(session["id"])
    assert trials[0]["trial"] == 0
    assert any(t["state_json"] for t in trials)  # the staircase's state (the practice trials have none)
    assert repr(texel.Store(str(db)).rows(session["id"])) == repr(texel.read_trials(str(db)))  # NaN-aware


def test_session_json_is_the_cli_and_studio_view(database, cli_json):
    # One serialiser (texel::experiment::to_json(SessionInfo)): Python's view of
    # a session is the one `texel experiment list --json` (and the studio) writes.
    import json

    db, _ = database
    (listed,) = cli_json("experiment", "list", "--db", db, "--json")
    s = texel.Store(str(db))
    assert json.loads(s.session_json(listed["id"])) == listed
    (session,) = s.sessions()
    assert {k: v for k, v in session.items() if k != "protocol_json"} == listed
    assert session["protocol_json"]
