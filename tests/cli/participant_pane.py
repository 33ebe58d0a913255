"""A participant at a terminal: `texel experiment run` in a tmux pane of its own.

The terminal tests (terminal_*.py beside this file) start the runner in a
pane with a pseudo-terminal, type into it with `tmux send-keys`, read it with
`tmux capture-pane -p` and record failed checks instead of stopping at the
first. Each test has its own tmux server (-L NAME-PID), kills only that, and
every wait has a deadline.
"""

import os
import re
import subprocess
import sys
import time


class Pane:
    def __init__(self, name):
        self.socket = f"{name}-{os.getpid()}"
        self.env = {k: v for k, v in os.environ.items() if k not in ("TMUX", "TMUX_PANE")}
        self.failures = []
        self.screens = []  # every capture, in order

    def check(self, ok, what):
        if not ok:
            self.failures.append(what)
            print("FAIL:", what, flush=True)

    def tmux(self, *args):
        r = subprocess.run(["tmux", "-L", self.socket, "-f", "/dev/null", *args], env=self.env, capture_output=True,
                           text=True, timeout=20)
        if r.returncode != 0:
            raise RuntimeError(f"tmux {' '.join(args)}: {r.stderr.strip()}")
        return r.stdout

    def start(self, cmd):
        """Runs cmd in a 120 × 50 pane that stays open after it ends (its last
        screen can be read), printing `TEXEL-EXIT <status>`."""
        self.tmux("new-session", "-d", "-s", "p", "-x", "120", "-y", "50", f"{cmd}; echo TEXEL-EXIT $?; sleep 120")

    def capture(self):
        text = self.tmux("capture-pane", "-p", "-J", "-S", "-", "-t", "p")
        self.screens.append(text)
        return text

    def wait_for(self, pattern, timeout=20.0, poll=0.1):
        """The screen and the match once `pattern` is on it; RuntimeError with the last screen at the deadline."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            text = self.capture()
            m = re.search(pattern, text)
            if m:
                return text, m
            time.sleep(poll)
        raise RuntimeError(f"timed out after {timeout} s waiting for /{pattern}/ on the screen:\n{self.screens[-1]}")

    def soft_wait(self, pattern, what, timeout=10.0):
        """wait_for that records a failed check instead of ending the test."""
        try:
            return self.wait_for(pattern, timeout)[0]
        except RuntimeError:
            self.check(False, what)
            return self.screens[-1]

    def send(self, keys):
        """Types keys (none: Enter alone) and Enter."""
        if keys:
            self.tmux("send-keys", "-t", "p", "-l", keys)
        self.tmux("send-keys", "-t", "p", "Enter")

    def new_line_after(self, keys, line, what, timeout=10.0):
        """Sends keys and waits until one more `line` is on the screen than before."""
        before = self.capture().count(line)
        self.send(keys)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.capture().count(line) > before:
                return
            time.sleep(0.1)
        self.check(False, what)

    def run(self, main, passed):
        """Runs main(); a deadline or a tmux failure is a failed check, with the
        last screen. Kills this test's tmux server, then exits 1 on any
        failure, else prints `passed` and returns."""
        try:
            main()
        except Exception as e:
            self.check(False, str(e))
        finally:
            subprocess.run(["tmux", "-L", self.socket, "kill-server"], env=self.env, capture_output=True, timeout=20)
            socket_path = os.path.join(self.env.get("TMUX_TMPDIR", "/tmp"), f"tmux-{os.getuid()}", self.socket)
            if os.path.exists(socket_path):
                os.remove(socket_path)
        if self.failures:
            print(f"{len(self.failures)} failed checks; last screen:\n{self.screens[-1] if self.screens else '(none)'}")
            sys.exit(1)
        print(passed)


def monitor_events(path, name):
    """The --monitor file's `name` events, each a dict of its fields (none when the file does not exist)."""
    if not os.path.exists(path):
        return []
    out = []
    for line in open(path, encoding="utf-8"):
        parts = line.rstrip("\n").split(" ", 2)
        if len(parts) >= 2 and parts[1] == name:
            fields = dict(re.findall(r'(\w+)=("(?:[^"\\]|\\.)*"|\S+)', parts[2] if len(parts) > 2 else ""))
            out.append({k: v.strip('"') for k, v in fields.items()})
    return out
