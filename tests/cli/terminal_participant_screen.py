#!/usr/bin/python3
"""The participant's screen of `texel experiment run`, as a participant sees it.

Runs the texel-length study (a 1-up/3-down staircase, no feedback) in a tmux
pane with a pseudo-terminal and the null stimulus output, types answers with
`tmux send-keys` (right or wrong on purpose, read from the experimenter's
--monitor file, so the staircase moves both ways), captures the pane with
`tmux capture-pane -p` after every step and asserts:

- nothing on the participant's screen depends on correctness or the
  procedure's state: no staircase value, variable or block name, no
  reversal counts, no engineering figures (sample rate, frames, late blocks);
- a countdown is visible, decreases, and is redrawn in place (one line);
- "Now playing: texture N" follows selecting texture N;
- the "Trial N" headers are the export's trial_number (trial + 1 where the
  column does not exist yet);
- the --monitor file does hold the staircase values, reversals and audio setup.

Usage: terminal_participant_screen.py TEXEL PROTOCOL_DIR WORK_DIR [--no-monitor]
(--no-monitor runs a texel without the flag, to check the test fails
against the old runner.) The pane: participant_pane.py.
"""

import csv
import json
import os
import re
import shutil
import subprocess
import sys
import time

from participant_pane import Pane, monitor_events

TEXEL, PROTOCOLS, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
USE_MONITOR = "--no-monitor" not in sys.argv[4:]
PANE = Pane("texel-terminal")
check, capture, wait_for, soft_wait, send, new_line_after = (PANE.check, PANE.capture, PANE.wait_for, PANE.soft_wait,
                                                             PANE.send, PANE.new_line_after)
screens = PANE.screens


def countdown(text):
    values = re.findall(r"Time left: (\d+) s", text)
    return [int(v) for v in values]


def main():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    db, mon, csv_path = (os.path.join(WORK, n) for n in ("s.db", "monitor.log", "trials.csv"))
    # The shipped texel-length protocol without its untimed practice block,
    # so the first trial is a timed staircase trial.
    with open(os.path.join(PROTOCOLS, "texel-length.json")) as f:
        shipped = json.load(f)
    shipped["blocks"] = [b for b in shipped["blocks"] if not b.get("practice")]
    protocol = os.path.join(WORK, "texel-length.json")
    with open(protocol, "w") as f:
        json.dump(shipped, f)
    cmd = f"'{TEXEL}' experiment run '{protocol}' --participant TM1 --db '{db}' --backend null"
    if USE_MONITOR:
        cmd += f" --monitor '{mon}'"
    # The pane stays open after the run so its last screen can be read.
    PANE.start(cmd)

    # Trial 1: the countdown is visible and decreases, in place.
    wait_for(r"(?i)trial 1\b")
    text = soft_wait(r"Time left: \d+ s", "a countdown is shown")
    first = countdown(text)
    time.sleep(2.3)
    text = capture()
    later = countdown(text)
    check(first and later and later[-1] < first[-1], f"countdown decreases: {first} then {later}")
    check(len(later) == 1, f"the countdown is redrawn in place (one 'Time left' line), saw {len(later)}")

    # Selecting texture 2 confirms what plays.
    new_line_after("2", "Now playing: texture 2", "typing 2 plays texture 2 and says so")
    send("h")
    soft_wait(r"(?s)Help: 'h'.*Help: 'h'", "'h' shows the help again")

    # Answer: wrong first (the staircase rises), then right three times (it
    # falls), then wrong, then right: the answers come from the monitor's
    # correct_answer when it is there, else a fixed guess.
    plan = [False, True, True, True, False, True, True]
    for n, right in enumerate(plan, start=1):
        wait_for(rf"(?i)trial {n}\b")
        time.sleep(0.3)
        questions = monitor_events(mon, "question")
        truth = questions[n - 1]["correct_answer"] if len(questions) >= n else "1"
        answer = truth if right else str(int(truth) % 3 + 1)
        # feel the one we pick first ('f N' is the long form of 'N')
        new_line_after(f"f {answer}", f"Now playing: texture {answer}", f"trial {n}: 'Now playing: texture {answer}'")
        send(f"a {answer}")
        wait_for(rf"(?i)trial {n + 1}\b")
    time.sleep(0.3)
    send("q")
    final, _ = wait_for(r"TEXEL-EXIT (\d+)")
    check("TEXEL-EXIT 0" in final, "texel exits 0 after 'q'")
    check("your answers are saved" in final, "the participant is told the answers are saved")

    # What the run stored, and what the screen said about it.
    subprocess.run([TEXEL, "experiment", "export", "--db", db, "-o", csv_path], check=True, capture_output=True, timeout=60)
    rows = list(csv.DictReader(open(csv_path, newline="", encoding="utf-8")))
    check(len(rows) == len(plan), f"{len(plan)} trials stored, found {len(rows)}")
    numbers = [int(r["trial_number"]) if "trial_number" in r else int(r["trial"]) + 1 for r in rows]
    shown = sorted({int(n) for n in re.findall(r"^Trial (\d+)\b", final, re.M)})
    check(shown == numbers + [len(rows) + 1], f"'Trial N' on screen {shown} = export trial_number {numbers} + the trial left")
    values = {r["intensity"] for r in rows} | {r["next_intensity"] for r in rows}
    values.discard("")
    moves = {(float(r["next_intensity"]) > float(r["intensity"])) - (float(r["next_intensity"]) < float(r["intensity"]))
             for r in rows if r["intensity"] and r["next_intensity"]}
    check({1, -1} <= moves, f"the staircase moved both ways (values {sorted(values)})")

    # Nothing on any screen depends on correctness or the procedure's state.
    # The resume line after 'q' is the experimenter's (it repeats the options
    # a resume needs, --backend among them); everything else is the participant's.
    whole = "\n".join(ln for ln in "\n".join(screens).splitlines() if not ln.startswith("(experimenter: "))
    forbidden = ["narrow", "texel_length", "staircase", "reversal", "correct", "wrong", "→", "Hz", "frames",
                 "late block", "backend", "block ", "underrun", "worst", "intensity", "48000"]
    for word in forbidden:
        check(word.lower() not in whole.lower(), f"the participant's screen never shows '{word}'")
    safe = re.compile(r"^(Trial \d+\b.*|\s*Time left: \d+ s)$")
    lines = [ln for ln in whole.splitlines() if not safe.match(ln)]
    for v in sorted(values):
        pat = re.compile(rf"(?<![\w.]){re.escape(v)}(?![\w.])")
        hits = [ln for ln in lines if pat.search(ln)]
        check(not hits, f"the staircase value {v} never appears on the participant's screen: {hits[:3]}")

    # The experimenter's stream has it all.
    results = monitor_events(mon, "result")
    check(len(results) == len(rows), f"the monitor has one result per stored trial ({len(results)} vs {len(rows)})")
    check(all("next_value" in r and "reversals" in r and "correct" in r for r in results), "results carry value, reversals, correctness")
    check({r.get("value") for r in results} | {r.get("next_value") for r in results} >= values,
          "the monitor holds every staircase value the export holds")
    check(len(monitor_events(mon, "audio")) == 1 and "Hz" in open(mon).read() if USE_MONITOR else False,
          "the monitor names the audio setup")
    check(len(monitor_events(mon, "play")) >= len(rows), "the monitor logs every stimulus played")
    check(len(monitor_events(mon, "suspend")) == 1, "the monitor logs the suspend")

    # Not a terminal (answers piped in, output to a file): the same words, the
    # countdown as lines, still nothing of the procedure on stdout or stderr.
    if USE_MONITOR:
        piped = subprocess.run([TEXEL, "experiment", "run", protocol, "--participant", "TM2", "--db", db, "--monitor",
                                os.path.join(WORK, "piped.log")], input="f 2\na 1\na 3\nq\n", capture_output=True,
                               text=True, timeout=60)
        both = piped.stdout + piped.stderr
        check(piped.returncode == 0, f"a piped run exits 0 ({piped.returncode}): {piped.stderr}")
        check("Time left: 30 s" in piped.stdout and "Now playing: texture 2" in piped.stdout and "> f 2" in piped.stdout,
              "a piped run shows the countdown line, the confirmation and the echoed input")
        for word in ("narrow", "texel_length", "Hz", "late", "→", "28.5", "23.5"):
            check(word not in both, f"a piped run never shows '{word}'")
        # A monitor that cannot be opened: exit 2, one line, nothing created.
        bad = subprocess.run([TEXEL, "experiment", "run", protocol, "--participant", "TM3", "--db", os.path.join(WORK, "none.db"),
                              "--monitor", os.path.join(WORK, "no", "such", "dir.log")], input="", capture_output=True,
                             text=True, timeout=60)
        check(bad.returncode == 2 and bad.stderr.count("\n") == 1 and "--monitor" in bad.stderr,
              f"an unopenable --monitor is one line, exit 2: {bad.returncode} {bad.stderr!r}")
        check(not os.path.exists(os.path.join(WORK, "none.db")), "an unopenable --monitor leaves no database")


PANE.run(main, "participant screen: all checks passed")
