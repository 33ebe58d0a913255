"""texel.experiment: a protocol run from Python, one question at a time, on
the engine the terminal runner drives — so a simulated participant's rows
equal `texel experiment run --simulate`'s, and resume is exact."""
import os
import subprocess

import pytest

import texel
from texel.experiment import Presenter, Session, simulate_cohort

COMPARED = ("trial", "block", "variable", "intensity", "response", "correct", "correct_answer", "next_intensity")


@pytest.fixture(scope="module")
def protocol(source_dir):
    return source_dir / "examples" / "protocols" / "texel-length.json"


def run_plain_loop(session, player, stop_after=None):
    while not session.finished and session.trials_done != stop_after:
        q = session.question
        assert q["stimuli"] and q["choices"]
        for i in range(len(q["stimuli"])):
            session.present(player, i)
        session.record(session.simulated_response())


def columns(db, session_id=None):
    with texel.Store(db) as store:
        rows = store.rows(session_id)
    return [{k: r[k] for k in COMPARED} for r in rows]


def test_a_simulated_session_equals_the_cli_run(protocol, tmp_path, cli):
    db = tmp_path / "py.db"
    with texel.Store(db, mode="rw") as store, Session(store, protocol, "P01", simulate="default") as s, \
            Presenter("null") as player:
        assert s.trials_done == 0 and not s.finished
        assert "Session" in repr(s) and "P01" in repr(s)
        run_plain_loop(s, player)
        assert s.finished and player.shown >= s.trials_done
        info = s.info
    assert info["participant"] == "P01" and info["protocol"] == "texel-length"
    cli("experiment", "run", protocol, "--participant", "P01", "--db", tmp_path / "cli.db", "--simulate", "default",
        "--quiet")
    py_rows, cli_rows = columns(db), columns(tmp_path / "cli.db")
    assert len(py_rows) > 5
    assert py_rows == cli_rows


def test_resume_continues_where_it_stopped(protocol, tmp_path):
    db = tmp_path / "s.db"
    with texel.Store(db, mode="rw") as store, Presenter() as player:
        with Session(store, protocol, "P02", simulate="default") as s:
            run_plain_loop(s, player, stop_after=4)
        with pytest.raises(texel.InvalidArgument, match=r"has an unfinished .* resume it \(Session\(\.\.\., resume=True\)\)") as e:
            Session(store, protocol, "P02")  # an unfinished session exists: resume it, explicitly
        assert "--" not in str(e.value), "Python's error names Python's argument, not the CLI's flag"
        with pytest.raises(texel.InvalidArgument, match=r"no unfinished .* \(start one with resume=False\)"):
            Session(store, protocol, "P03", resume=True)
        with Session(store, protocol, "P02", resume=True) as s:
            assert s.trials_done == 4
            run_plain_loop(s, player)
            assert s.finished
            resumed_id = s.id
    # The same participant run without interruption stores the same rows.
    db2 = tmp_path / "straight.db"
    with texel.Store(db2, mode="rw") as store, Presenter() as player, \
            Session(store, protocol, "P02", simulate="default") as s:
        run_plain_loop(s, player)
    assert columns(db, resumed_id) == columns(db2)


def test_a_person_answers_and_a_bad_answer_stores_nothing(protocol, tmp_path):
    with texel.Store(tmp_path / "p.db", mode="rw") as store, Session(store, protocol, "P04") as s:
        q = s.question
        assert set(q) >= {"prompt", "stimuli", "choices", "trial", "block"}
        assert "correct_answer" not in q  # participant-safe
        doc = s.stimulus(0)
        assert isinstance(doc, texel.Document) and doc.render().size > 0
        with pytest.raises(texel.InvalidArgument):
            s.record({"choice": "no such choice"})
        assert s.trials_done == 0
        with pytest.raises(texel.Error):
            s.simulated_response()  # opened for a person
        row = s.record({"choice": q["choices"][0], "rt_ms": 1234.0})
        assert row["trial"] == 0 and row["rt_ms"] == 1234.0 and row["response"] == q["choices"][0]
        assert s.trials_done == 1
    assert len(texel.read_trials(tmp_path / "p.db")) == 1


def test_closed_objects_refuse_and_leave_no_wal(protocol, tmp_path):
    db = tmp_path / "c.db"
    store = texel.Store(db, mode="rw")
    s = Session(store, protocol, "P05", simulate="default")
    s.record(s.simulated_response())
    s.close()
    s.close()  # again: nothing
    with pytest.raises(texel.InvalidArgument, match="closed"):
        s.question
    store.close()
    with pytest.raises(texel.InvalidArgument, match="closed"):
        store.sessions()
    assert "closed" in repr(store)
    with texel.Store(db) as ro:
        assert ro.sessions()[0]["trials_done"] == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.db"]


def test_simulate_cohort_and_protocol_as_dict(protocol, tmp_path):
    import json

    with texel.Store(tmp_path / "k.db", mode="rw") as store:
        ids = simulate_cohort(store, json.loads(protocol.read_text()), ["A1", "A2"])
        assert len(ids) == 2
        assert {x["status"] for x in store.sessions()} == {"finished"}
        assert {x["state"] for x in store.sessions()} == {"finished"}


def test_store_mode_is_checked(tmp_path):
    with pytest.raises(texel.InvalidArgument, match="mode"):
        texel.Store(tmp_path / "x.db", mode="w")
    with pytest.raises(texel.IoError):
        texel.Store(tmp_path / "missing.db")  # read-only never creates


def test_a_session_needs_a_writable_store(protocol, tmp_path):
    texel.Store(tmp_path / "w.db", mode="rw").close()
    with texel.Store(tmp_path / "w.db") as store, pytest.raises(texel.InvalidArgument, match="rw"):
        Session(store, protocol, "P06")


def test_answers_are_bound_to_the_question_token(protocol, tmp_path):
    # The token rule (docs/studio.md): a stale token or a paused session stores nothing.
    with texel.Store(tmp_path / "t.db", mode="rw") as store, Session(store, protocol, "P06") as s:
        q = s.question
        first = s.handout
        # texel-length opens with untimed practice trials (no time limit)
        assert first["trial_number"] == 1 and first["time_limit_s"] == 0 and not first["suspended"]
        s.suspend()
        assert s.handout["suspended"] and s.handout["token"] == first["token"]
        with pytest.raises(texel.InvalidArgument, match="paused"):
            s.record({"choice": q["choices"][0]}, token=first["token"])
        s.resume()
        row = s.record({"choice": q["choices"][0]}, token=first["token"])
        assert row["trial_number"] == 1 and row["interrupted"] == 1 and row["rt_ms"] >= 0
        with pytest.raises(texel.InvalidArgument, match="no longer the current one"):
            s.record({"choice": q["choices"][0]}, token=first["token"])  # replayed
        assert s.trials_done == 1
        row = s.record({"choice": s.question["choices"][0]})  # the current token by default
        assert row["trial_number"] == 2 and row["interrupted"] == 0


def test_a_display_plays_the_trials_and_its_finger_fills_the_swipe_columns(protocol, tmp_path, cli):
    """A script on a real display: the reference controller with a scripted 1-D finger. The display
    stores each trial's stimuli and plays them from its own sensor; the rows carry its finger."""
    exe = os.environ.get("TEXEL_BIN") or str(cli("--version").args[0])
    ctl = subprocess.Popen([exe, "controller", "--pty", "--sensor", "strokes", "--quiet"], stdout=subprocess.PIPE,
                           stderr=subprocess.DEVNULL, text=True)
    try:
        pty = ctl.stdout.readline().strip()
        assert pty.startswith("/dev/"), pty
        with pytest.raises(texel.InvalidArgument, match="passive"):
            Presenter("serial:" + pty, mode="passive")  # the display senses the finger: passive would ignore it
        with pytest.raises(texel.InvalidArgument, match="allowed: display-plays, host-streams, passive"):
            Presenter("null", mode="sideways")
        db = tmp_path / "display.db"
        with texel.Store(db, mode="rw") as store, Session(store, protocol, "P01", simulate="default") as s, \
                Presenter("serial:" + pty) as player:
            assert player.mode == "display-plays"
            for _ in range(3):
                q = s.question
                for i in range(len(q["stimuli"])):
                    s.present(player, i)
                    player.wait(0.35)
                row = s.record(s.simulated_response())
                assert row["presentation_mode"] == "display-plays"
                assert row["finger_source"] == "display"
                assert row["swipe_flag"] == "", row["swipe_flag"]
                # The scripted strokes: tens of mm/s, never the simulated observer's drawn figures alone.
                assert 5 < row["swipe_mean_speed_mm_s"] < 1000
        with texel.Store(db) as store:
            assert len(store.rows()) == 3
    finally:
        ctl.terminate()
        ctl.wait(5)
