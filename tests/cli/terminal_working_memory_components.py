#!/usr/bin/python3
"""The working-memory components study in `texel experiment run`, as a participant does it.

Runs examples/protocols/working-memory-components.json (its coarse
conditions, one trial each, with short timings) in a tmux pane with the null
stimulus output. For every trial it reads the distractor from the screen the
way a participant would and answers it:

- the matrix: reads the 4 × 4 digits, answers the cell asked;
- the digit sequence (verbal): reads the digits as they appear one at a time,
  answers the position asked;
- the digit stream (executive, 2-back): presses Enter (tmux send-keys) while a
  digit equal to the one two before it is on screen.

Then it asserts that the export scored exactly that: every recall right
(digit_correct 1), the 2-back's hits equal to its targets with no false
alarm (nback_hits = nback_targets, nback_false_alarms 0) — so what the screen
showed is the question's own sequence, in order, and each Enter reached the
digit on screen — and that nothing on the participant's screen names the
condition (coarse, control, the component, targets, correctness).

Usage: terminal_working_memory_components.py TEXEL PROTOCOL_DIR WORK_DIR.
The pane: participant_pane.py.
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
TRIALS = 4

PANE = Pane("texel-wm")
check, capture, send = PANE.check, PANE.capture, PANE.send
screens = PANE.screens


def wait_for(pattern, timeout=30.0):
    return PANE.wait_for(pattern, timeout, poll=0.05)


def digit_on_screen(text):
    """The sequence's digit line (eight spaces, one digit), or None (blank)."""
    m = re.findall(r"^ {8}(\d)\s*$", text, re.M)
    return int(m[-1]) if m else None


def read_matrix(text):
    rows = re.findall(r"^ {6}([.\d])  ([.\d])  ([.\d])  ([.\d])\s*$", text, re.M)
    return [[0 if c == "." else int(c) for c in row] for row in rows[-4:]]


def run_sequence(executive, asked):
    """Reads the digits as they appear (consecutive digits differ in the
    loaded tasks); for the 2-back, Enter while a target is on screen. Ends
    when the same/different question shows (the asked-th time)."""
    seen, pressed = [], 0
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        text = capture()
        d = digit_on_screen(text)
        if d is not None and (not seen or d != seen[-1]):
            seen.append(d)
            if executive and len(seen) >= 3 and seen[-1] == seen[-3]:
                send("")
                pressed += 1
        if text.count("type 'a' and your answer") > asked:
            break
        time.sleep(0.03)
    return seen, pressed


def main():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    db, mon, csv_path = (os.path.join(WORK, n) for n in ("s.db", "monitor.log", "trials.csv"))
    with open(os.path.join(PROTOCOLS, "working-memory-components.json")) as f:
        p = json.load(f)
    test = [b for b in p["blocks"] if b["name"] == "test"][0]
    test.update(texture_s=0.5, matrix_s=8, trials_per_condition=1)  # 0.8 s a digit in the 2-back: room for a loaded machine
    test["conditions"] = [c for c in test["conditions"] if c["stimulus"] == "coarse"]
    p["blocks"] = [test]
    protocol = os.path.join(WORK, "wm.json")
    with open(protocol, "w") as f:
        json.dump(p, f)
    cmd = f"'{TEXEL}' experiment run '{protocol}' --participant WM1 --db '{db}' --backend null --monitor '{mon}'"
    PANE.start(cmd)

    kinds = []
    for n in range(1, TRIALS + 1):
        text, _ = wait_for(rf"Trial {n} of {TRIALS}")
        asked = text.count("type 'a' and your answer")
        recalls = text.count("Which digit")
        text, m = wait_for(r"Remember this matrix|Remember these digits|Respond whenever[^\n]*")
        matrix = None
        if m.group(0) == "Remember this matrix":
            kinds.append("matrix")
            time.sleep(0.3)
            matrix = read_matrix(capture())
            check(len(matrix) == 4, f"trial {n}: a 4 × 4 matrix on screen")
        elif m.group(0) == "Remember these digits":
            kinds.append("sequence")
            seen, _ = run_sequence(False, asked)
        else:
            kinds.append("2-back")
            check("the same as the one two before it" in m.group(0), f"trial {n}: the 2-back instruction: {m.group(0)}")
            check("Press Enter" in m.group(0), f"trial {n}: the terminal says how to respond")
            seen, pressed = run_sequence(True, asked)
            check(len(seen) == 10, f"trial {n}: ten digits seen one at a time, saw {seen}")
            check(pressed == 3, f"trial {n}: three 2-back targets on screen, pressed {pressed} on {seen}")
        deadline = time.monotonic() + 30
        while capture().count("type 'a' and your answer") <= asked and time.monotonic() < deadline:
            time.sleep(0.05)
        check(not re.search(r"^ {8}\d\s*$", screens[-1], re.M), f"trial {n}: the digits are hidden again when the question comes")
        truth = [q for q in monitor_events(mon, "question")][n - 1]["correct_answer"]
        send(f"a {truth}")
        if kinds[-1] == "2-back":
            text, _ = wait_for(rf"Trial {n + 1} of|TEXEL-EXIT")
            check(text.count("Which digit") == recalls, f"trial {n}: the 2-back has no recall question")
            continue
        deadline = time.monotonic() + 30
        while capture().count("Which digit") <= recalls and time.monotonic() < deadline:
            time.sleep(0.05)
        question = re.findall(r"Which digit [^\n]*\?", screens[-1])[-1]
        if kinds[-1] == "matrix":
            cell = re.search(r"row (\d), column (\d)", question)
            answer = matrix[int(cell.group(1)) - 1][int(cell.group(2)) - 1] if cell else 1
            check(cell or all(v == 1 for row in matrix for v in row), f"trial {n}: the control matrix holds only 1s")
        elif kinds[-1] == "sequence":
            at = re.search(r"number (\d) of the (\d)", question)
            if at:
                check(int(at.group(2)) == 5 and len(seen) == 5, f"trial {n}: five digits seen, saw {seen}")
                answer = seen[int(at.group(1)) - 1]
            else:
                answer = 1
        send(str(answer))
    final, _ = wait_for(r"TEXEL-EXIT (\d+)", 30)
    check("TEXEL-EXIT 0" in final, "texel exits 0 at the end of the protocol")
    check(sorted(kinds) == sorted(["matrix", "matrix", "sequence", "2-back"]),
          f"the control and the visuospatial trial show a matrix, verbal a sequence, executive a stream: {kinds}")

    subprocess.run([TEXEL, "experiment", "export", "--db", db, "-o", csv_path], check=True, capture_output=True, timeout=60)
    rows = list(csv.DictReader(open(csv_path, newline="", encoding="utf-8")))
    check(len(rows) == TRIALS, f"{TRIALS} trials stored, found {len(rows)}")
    for r in rows:
        kind = r["condition"].split("-")[-1]
        check(r["correct"] == "1", f"{r['condition']}: same/different answered right (the monitor's truth)")
        if kind == "executive":
            check(r["nback_targets"] == "3" and r["nback_hits"] == "3" and r["nback_false_alarms"] == "0",
                  f"{r['condition']}: Enter on each target on screen scores 3 hits of 3, no false alarm: "
                  f"{r['nback_hits']}/{r['nback_targets']}, {r['nback_false_alarms']} false alarms")
            check(r["digit_correct"] == "", f"{r['condition']}: no digit recall")
        else:
            check(r["digit_correct"] == "1", f"{r['condition']}: the digit read from the screen is the one asked")
            check(r["nback_targets"] == "", f"{r['condition']}: no n-back columns")

    whole = "\n".join(ln for ln in "\n".join(screens).splitlines() if not ln.startswith("(experimenter: "))
    for word in ["coarse", "control", "visuospatial", "verbal", "executive", "back", "target", "hit", "false alarm",
                 "correct", "wrong", "condition", "patch"]:
        check(word not in whole.lower(), f"the participant's screen never shows '{word}'")


if __name__ == "__main__":
    PANE.run(main, "working-memory components at the terminal: all checks passed")
