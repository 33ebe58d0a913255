"""The step-wise procedures driven from Python reproduce the C++ results:
the staircase against `texel staircase --json`, the matching optimizers
against the sessions the C++ engine ran and stored (`texel experiment run
--simulate`), replaying the stored answers one question at a time."""
import json

import pytest

import texel

STAIR_CASES = [
    dict(start=0.5, steps=[0.1, 0.05, 0.02], n_up=1, n_down=3, step_type="lin", min_value=0.0, max_value=1.0,
         answers=[1, 1, 1, 0, 1, 1, 1, 1, 1, 0, 0, 1, 1, 1, 0, 1, 1, 1, 1, 0, 1]),
    dict(start=2.0, steps=[0.3, 0.1], n_up=1, n_down=2, step_type="log", min_value=None, max_value=None,
         answers=[1, 1, 1, 1, 0, 1, 1, 0, 0, 1, 1, 1, 1, 0]),
    dict(start=10.0, steps=[6, 3], n_up=2, n_down=1, step_type="db", min_value=None, max_value=20.0,
         answers=[0, 0, 1, 0, 0, 1, 1, 0, 0, 1]),
]


def _flags(c):
    f = ["--start", c["start"], "--steps", ",".join(map(str, c["steps"])), "--n-up", c["n_up"], "--n-down", c["n_down"],
         "--step-type", c["step_type"], "--responses", ",".join(map(str, c["answers"])), "--json"]
    if c["min_value"] is not None:
        f += ["--min", c["min_value"]]
    if c["max_value"] is not None:
        f += ["--max", c["max_value"]]
    return f


@pytest.mark.parametrize("case", STAIR_CASES)
def test_stepped_staircase_equals_cli(cli_json, case):
    s = texel.Staircase(case["start"], case["steps"], n_up=case["n_up"], n_down=case["n_down"],
                        step_type=case["step_type"], min_value=case["min_value"], max_value=case["max_value"])
    shown = []
    for a in case["answers"]:
        if s.finished:
            break
        shown.append(s.next())
        s.answer(bool(a))
    # The CLI refuses answers after the end, so it gets exactly the ones Python used;
    # had Python stopped too early, the CLI would report finished = false.
    case = dict(case, answers=case["answers"][: len(shown)])
    j = cli_json("staircase", *_flags(case))
    assert j["trials"] == len(shown)
    assert shown == j["intensities"]  # exact: the same doubles
    assert s.intensities == j["intensities"]
    assert s.reversal_trials == j["reversal_trials"]
    assert s.reversal_intensities == j["reversal_intensities"]
    assert s.finished == j["finished"]
    assert s.next_value == j["next_value"]
    assert s.convergent_value == j["convergent_value"] == j["next_value"]  # end_value 'next', the default
    assert s.current_step == j["current_step"]
    if "mean_last_reversals" in j:
        assert s.mean_last_reversals(j["mean_last_reversals_k"]) == j["mean_last_reversals"]
    r = texel.Staircase.replay([bool(a) for a in case["answers"]], case["start"], case["steps"],
                               n_up=case["n_up"], n_down=case["n_down"], step_type=case["step_type"],
                               min_value=case["min_value"], max_value=case["max_value"])
    assert r.state_json() == s.state_json()


def test_end_value_last_presented_equals_cli(cli_json):
    # The source studies' reading: the result is the last value presented, not the next one.
    case = dict(STAIR_CASES[0], answers=STAIR_CASES[0]["answers"][:7])  # the 7th answer moves the value
    s = texel.Staircase.replay([bool(a) for a in case["answers"]], case["start"], case["steps"], n_up=1, n_down=3,
                               min_value=0.0, max_value=1.0, apply_initial_rule=False, end_value="last-presented")
    j = cli_json("staircase", *_flags(case), "--no-initial-rule", "--end-value", "last-presented")
    assert j["end_value"] == "last-presented"
    assert s.convergent_value == j["convergent_value"] == j["intensities"][-1] == s.intensities[-1]
    assert s.next_value == j["next_value"] != s.convergent_value
    with pytest.raises(texel.InvalidArgument, match="end_value"):
        texel.Staircase(0.5, [0.1], end_value="final")


def _stored_match_sessions(cli, tmp_path, source_dir, kind):
    protocol = json.loads((source_dir / "examples/protocols/guided-exploration.json").read_text())
    protocol["blocks"] = [b for b in protocol["blocks"] if b["task"] == "guided"]
    protocol["blocks"][0]["references"] = protocol["blocks"][0]["references"][:2]
    if kind == "bayesian":
        protocol["name"] = "bayesian-exploration"
        protocol["blocks"][0]["optimizer"] = {"kind": "bayesian", "comparisons": 12, "candidates": 16, "particles": 64}
    path = tmp_path / f"{kind}.json"
    path.write_text(json.dumps(protocol))
    db = tmp_path / f"{kind}.db"
    cli("experiment", "run", path, "--participant", "P01", "--db", db, "--simulate", "default", "--quiet")
    store = texel.Store(str(db))
    (session,) = store.sessions()
    return store.trials(session["id"])


@pytest.mark.parametrize("kind", ["guided", "bayesian"])
def test_stepped_optimizer_reproduces_the_engine_session(cli, tmp_path, source_dir, kind):
    trials = _stored_match_sessions(cli, tmp_path, source_dir, kind)
    assert trials
    runs = {}
    for t in trials:
        runs.setdefault(t["row"]["reference"], []).append(t)
    assert len(runs) == 2
    for reference, ts in runs.items():
        config = json.loads(ts[0]["state_json"])["config"]
        if kind == "guided":
            opt = texel.GuidedOptimizer(**config)
        else:
            config = {k: v for k, v in config.items() if v is not None}
            opt = texel.BayesOptimizer(**config)
        for t in ts:
            row = t["row"]
            q = opt.next()
            assert (q.a.pitch_db, q.a.irregularity_db) == (row["pitch_a_db"], row["irregularity_a_db"]), reference
            assert (q.b.pitch_db, q.b.irregularity_db) == (row["pitch_b_db"], row["irregularity_b_db"]), reference
            opt.answer(row["response"].lower())
            assert opt.state_json() == t["state_json"]
        assert opt.finished


def test_guided_is_deterministic_and_replayable():
    def run(seed):
        o = texel.GuidedOptimizer(seed=seed)
        target = texel.Matcher((5.0, -10.0), noise_db=0, unsure_band_db=0, seed=seed)
        trial = 0
        while not o.finished:
            o.answer(target.choose(o.next(), trial))
            trial += 1
        return o

    a, b = run(3), run(3)
    assert a.state_json() == b.state_json()
    assert a.comparisons == a.budget == 20
    r = texel.GuidedOptimizer(seed=3)
    r.replay(a.choices)
    assert r.state_json() == a.state_json()
    # A noise-free observer leads the box onto its target (the C++ suite's published case).
    assert abs(a.estimate.pitch_db - 5.0) < 4 and abs(a.estimate.irregularity_db + 10.0) < 4
    assert len(a.boxes["pitch_db"]) == 6


def test_bayes_finds_a_simulated_target():
    o = texel.BayesOptimizer(comparisons=25, seed=4)
    m = texel.Matcher(texel.MatchPoint(8.0, -12.0), noise_db=1.0, seed=4)
    trial = 0
    while not o.finished:
        o.answer(m.choose(o.next(), trial))
        trial += 1
    est = o.estimate
    assert abs(est.pitch_db - 8.0) < 4 and abs(est.irregularity_db + 12.0) < 6
    assert o.uncertainty.pitch_db > 0
    q = texel.BayesOptimizer(seed=4).next()
    total = sum(o.likelihood(q, c, (8.0, -12.0)) for c in ("a", "b", "unsure"))
    assert total == pytest.approx(1.0)


def test_factory_builds_both_kinds():
    g = texel.optimizer("guided", iterations=2, shrink_rate=0.4)
    assert isinstance(g, texel.GuidedOptimizer) and g.budget == 8
    b = texel.optimizer("bayesian", comparisons=5)
    assert isinstance(b, texel.BayesOptimizer) and b.name == "bayesian"


def test_observers_are_seeded():
    p = texel.PsychometricObserver(threshold=0.3, slope=3.5, guess=0.5, seed=9)
    assert p.p_correct(0.3) == pytest.approx(0.5 + 0.5 * (1 - 2.718281828459045 ** -1))
    assert [p.respond(0.3, t) for t in range(50)] == [p.respond(0.3, t) for t in range(50)]
    assert p.inverse(p.p_correct(0.4)) == pytest.approx(0.4)
    r = texel.Rater(seed=2)
    assert r.expected(0.0) == pytest.approx(5.0)
    assert 1 <= r.rate(5.0, 0) <= 5
    m = texel.Matcher((0.0, 0.0), seed=1)
    assert m.distance((3.0, 4.0)) == pytest.approx(5.0)
    assert 1 <= m.confidence(0) <= 5
