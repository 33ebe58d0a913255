"""Texel's procedures and stimuli inside a PsychoPy window loop.

The experiment engine (texel.experiment.Session) runs the protocol — its
blocks, adaptive procedure, randomization and durable records — one question
at a time; this script owns the window and the loop, as a PsychoPy
experiment does. Every answer is committed to the session database before
the next question exists, so a crash loses nothing and
`Session(..., resume=True)` continues where it stopped.

With PsychoPy installed and a display, a participant answers in a window:
number keys play the stimuli (switch freely), letter keys answer. Without
PsychoPy (the tests, a headless machine) the same loop runs as a plain loop
in which a simulated participant answers.

Run after `make python` (or `pip install --no-build-isolation ./python`):
    PYTHONPATH=build/python /usr/bin/python3 examples/python/psychopy_session.py [--db study.db] [--participant P01]
"""
import argparse
import pathlib
import tempfile

import texel
from texel.experiment import Presenter, Session

try:  # PsychoPy is optional: the plain loop below needs nothing but texel
    from psychopy import core, event, visual
except ImportError:
    visual = None

PROTOCOL = pathlib.Path(__file__).resolve().parents[1] / "protocols" / "texel-length.json"


def psychopy_loop(session, player):
    """One question per screen: number keys play stimuli, a choice's first letter answers."""
    win = visual.Window(size=(900, 500), color="black", units="norm")
    text = visual.TextStim(win, height=0.07, wrapWidth=1.8)
    clock = core.Clock()
    try:
        while not session.finished:
            q = session.question
            keys = {c[0].lower(): c for c in q["choices"]}
            labels = "  ".join(f"[{i + 1}] {s['label']}" for i, s in enumerate(q["stimuli"]))
            text.text = f"{q['prompt']}\n\n{labels}\n\nanswer: " + "  ".join(f"[{k}] {c}" for k, c in keys.items())
            session.present(player, 0)
            clock.reset()
            answer = None
            while answer is None:
                player.pump()  # every frame (≤ 20 ms): feeds the player's finger
                text.draw()
                win.flip()
                for k in event.getKeys():
                    if k.isdigit() and 1 <= int(k) <= len(q["stimuli"]):
                        session.present(player, int(k) - 1)
                    elif k in keys:
                        answer = keys[k]
                    elif k == "escape":
                        return  # everything answered so far is stored; resume later
            player.blank()
            session.record({"choice": answer, "rt_ms": clock.getTime() * 1000})
    finally:
        win.close()


def plain_loop(session, player):
    """The same loop without a window: a simulated participant feels each stimulus, then answers."""
    while not session.finished:
        q = session.question
        for i in range(len(q["stimuli"])):
            session.present(player, i)
            player.wait(0.002)
        player.blank()
        row = session.record(session.simulated_response())
        print(f"trial {row['trial']:2d} {row['block']}: {row['variable']} {row['intensity']:.3f} -> {row['response']}"
              f" ({'correct' if row['correct'] == 1 else 'wrong'})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default=str(pathlib.Path(tempfile.mkdtemp()) / "study.db"))
    ap.add_argument("--participant", default="P01")
    ap.add_argument("--protocol", default=str(PROTOCOL))
    ap.add_argument("--resume", action="store_true")
    args = ap.parse_args()
    with texel.Store(args.db, mode="rw") as store, \
         Session(store, args.protocol, args.participant, resume=args.resume,
                 simulate=None if visual else "default") as session, \
         Presenter("null") as player:
        print(f"{session!r} on {player.describe()}")
        (psychopy_loop if visual else plain_loop)(session, player)
        print(f"{session.trials_done} trials stored in {args.db}; finished: {session.finished}")
    with texel.Store(args.db) as store:
        rows = store.rows(columns=True)
        print(f"read back: {len(rows['trial'])} rows, {int(sum(rows['correct'] == 1))} correct")


if __name__ == "__main__":
    main()
