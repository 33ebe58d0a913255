#!/usr/bin/python3
"""The distributed-irregularity study in `texel experiment run`, as a participant does it.

Runs examples/protocols/distributed-irregularity.json (its test block cut to
one level, two shifts and a control: 5 trials) in a tmux pane with the null
stimulus output opened with the device's four channels. In every trial the
participant feels the three textures (types 1, 2, 3: each says "Now
playing: texture N") and answers — right on odd trials and wrong on even
ones, read from the experimenter's --monitor file — then asserts that:

- texel exits 0 at the end and the export has the five playback-oddity
  rows, scored exactly as answered, with both odd playbacks and the control;
- the monitor logged a play for every texture felt, and the presentation's
  four channels;
- nothing on the participant's screen names the condition (simultaneous,
  sequential, control, irregularity, shift, playback) or says whether an
  answer was right.

Usage: terminal_distributed_irregularity.py TEXEL PROTOCOL_DIR WORK_DIR.
The pane: participant_pane.py.
"""

import csv
import json
import os
import shutil
import subprocess
import sys

from participant_pane import Pane, monitor_events

TEXEL, PROTOCOLS, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
TRIALS = 5
PANE = Pane("texel-di")
check, wait_for, send, new_line_after = PANE.check, PANE.wait_for, PANE.send, PANE.new_line_after


def main():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    db, mon, csv_path = (os.path.join(WORK, n) for n in ("s.db", "monitor.log", "trials.csv"))
    with open(os.path.join(PROTOCOLS, "distributed-irregularity.json")) as f:
        p = json.load(f)
    test = [b for b in p["blocks"] if b["name"] == "test"][0]
    test.update(irregularity_levels_db=[0.7918], shifts_db=[-3, 3], repeats=2, control_repeats=1)
    p["blocks"] = [test]
    protocol = os.path.join(WORK, "di.json")
    with open(protocol, "w") as f:
        json.dump(p, f)
    PANE.start(f"'{TEXEL}' experiment run '{protocol}' --participant DI1 --db '{db}' --backend null --monitor '{mon}'")

    answered = []
    for n in range(1, TRIALS + 1):
        wait_for(rf"Trial {n} of {TRIALS}")
        for texture in (1, 2, 3):
            new_line_after(str(texture), f"Now playing: texture {texture}", f"trial {n}: typing {texture} plays it and says so")
        truth = monitor_events(mon, "question")[n - 1]["correct_answer"]
        answer = truth if n % 2 == 1 else str(int(truth) % 3 + 1)
        answered.append(answer == truth)
        send(f"a {answer}")
    final, _ = wait_for(r"TEXEL-EXIT (\d+)", 30)
    check("TEXEL-EXIT 0" in final, "texel exits 0 at the end of the protocol")

    subprocess.run([TEXEL, "experiment", "export", "--db", db, "-o", csv_path], check=True, capture_output=True, timeout=60)
    rows = list(csv.DictReader(open(csv_path, newline="", encoding="utf-8")))
    check(len(rows) == TRIALS, f"{TRIALS} trials stored, found {len(rows)}")
    check(all(r["task"] == "playback-oddity" for r in rows), "every row is a playback oddity")
    check([r["correct"] == "1" for r in rows] == answered, f"scored as answered: {[r['correct'] for r in rows]} vs {answered}")
    check(sorted(r["condition"] for r in rows) == ["control", "odd-sequential", "odd-sequential", "odd-simultaneous",
                                                   "odd-simultaneous"], f"both odd playbacks and the control: {rows}")
    plays = monitor_events(mon, "play")
    check(len(plays) >= 3 * TRIALS, f"the monitor logs every texture felt ({len(plays)})")
    check("4 channels" in open(mon, encoding="utf-8").read(), "the monitor names the presentation's four channels")

    whole = "\n".join(ln for ln in "\n".join(PANE.screens).splitlines() if not ln.startswith("(experimenter: "))
    for word in ["simultaneous", "sequential", "control", "irregularity", "shift", "playback", "correct", "wrong", "pad-4"]:
        check(word not in whole.lower(), f"the participant's screen never shows '{word}'")


if __name__ == "__main__":
    PANE.run(main, "distributed irregularity at the terminal: all checks passed")
