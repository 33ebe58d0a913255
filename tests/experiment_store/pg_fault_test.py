#!/usr/bin/env python3
"""Fault test of the multi-station store (docs/session-store.md "Many stations").

Four station processes run simulated studies against one PostgreSQL server
(`texel experiment run --db postgresql://… --journal …`) while:
  * stations are SIGKILLed at random moments and resumed (--resume);
  * the server is stopped (as a crash would) for a while and started again;
  * one station's link (through a TCP proxy this script controls) is cut and
    restored.
At the end every station syncs, and the server's export must equal the union
of uninterrupted single-station SQLite runs with the same participants (the
seeds follow from them), ignoring ids and times: 0 trials lost, 0 duplicated.

The first run of the first station is killed the moment its journal file
appears, while `run` is still creating (migrating) it: the next run must
migrate that file and lose nothing.

Only real loss may fail the test as "lost": every participant's session
must first be finished in its station's journal. A station that could not
get there (a refused run, a failing command, an exception in the script's
own station thread) fails the test as a station failure naming it.
(Before, a `sys.exit` inside a station thread ended only that thread,
silently: when a kill left an unmigrated journal, its station's
participants were never run and showed up as 123 "lost" trials — see
journal_state().)

usage: pg_fault_test.py TEXEL PG_ENV_FILE SERVER_SCRIPT PROTOCOL [SEED]
"""
import csv
import json
import os
import random
import select
import shutil
import signal
import socket
import subprocess
import sqlite3
import sys
import tempfile
import threading
import time
import traceback
import urllib.parse

TEXEL, ENV_FILE, SERVER_SCRIPT, PROTOCOL = sys.argv[1:5]
SEED = int(sys.argv[5]) if len(sys.argv) > 5 else 27
STATIONS = 4
PARTICIPANTS = 3  # per station
PACE = "0.04"  # seconds per simulated trial
IGNORED = {"session_id", "shown_at", "answered_at"}  # ids and times

env = {}
with open(ENV_FILE) as f:
    for line in f:
        k, _, v = line.strip().partition("=")
        env[k] = v.strip("'")
PORT = int(env["TEXEL_PG_PORT"])
SOCK = env["TEXEL_PG_SOCKET"]
DB = "fault"


def psql(sql, db="postgres"):
    subprocess.run([env["TEXEL_PG_BIN"] + "/psql", "-h", SOCK, "-p", str(PORT), "-U", "texel_admin", "-d", db, "-qAt",
                    "-v", "ON_ERROR_STOP=1"], input=sql, text=True, check=True, capture_output=True)


class Proxy:
    """127.0.0.1:port → the server; cut() drops every connection and refuses new ones."""

    def __init__(self):
        self.listener = socket.socket()
        self.listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(64)
        self.port = self.listener.getsockname()[1]
        self.up = True
        self.pairs = []
        self.lock = threading.Lock()
        threading.Thread(target=self.accept, daemon=True).start()

    def accept(self):
        while True:
            c, _ = self.listener.accept()
            if not self.up:
                c.close()
                continue
            try:
                s = socket.create_connection(("127.0.0.1", PORT))
            except OSError:
                c.close()
                continue
            with self.lock:
                self.pairs.append((c, s))
            threading.Thread(target=self.pump, args=(c, s), daemon=True).start()

    def pump(self, a, b):
        try:
            while True:
                r, _, _ = select.select([a, b], [], [], 0.5)
                for x in r:
                    data = x.recv(65536)
                    if not data:
                        raise OSError
                    (b if x is a else a).sendall(data)
        except OSError:
            for x in (a, b):
                try:
                    x.close()
                except OSError:
                    pass

    def cut(self):
        self.up = False
        with self.lock:
            for a, b in self.pairs:
                for x in (a, b):
                    try:
                        x.shutdown(socket.SHUT_RDWR)
                    except OSError:
                        pass
            self.pairs = []

    def restore(self):
        self.up = True


def export_rows(db, path, extra_env=None):
    out = subprocess.run([TEXEL, "experiment", "export", "--db", db, "-o", path], capture_output=True, text=True,
                         env=extra_env)
    if out.returncode != 0:
        sys.exit("export of %s failed: %s" % (db, out.stderr.strip()))
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return [tuple((k, v) for k, v in r.items() if k not in IGNORED) for r in rows]


class StationFailure(Exception):
    pass


def sessions_in_file(journal, participant):
    """The participant's sessions in a journal, read from the file itself (read-only); None if unreadable."""
    try:
        con = sqlite3.connect("file:%s?mode=ro" % urllib.parse.quote(journal), uri=True)
        try:
            if not con.execute("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'sessions'").fetchone():
                return 0
            return con.execute("SELECT COUNT(*) FROM sessions WHERE participant = ?", (participant,)).fetchone()[0]
        finally:
            con.close()
    except sqlite3.Error:
        return None


def journal_state(journal, participant):
    """'finished', 'running', '' (no session yet) or 'unmigrated' (no session yet, see below) for the participant.

    A run killed while it creates the journal (the station's first run) leaves a file that has not reached the
    build's schema yet: empty, or with the first migrations only. Read-only commands refuse such a file ("… is an
    empty database", "… has the older schema version 1"); the next `run` migrates it. No session can be in it — a run
    opens its session only after the journal is migrated — which is checked on the file itself rather than read from
    the message. Any other refusal is a station failure (raised: the station thread records it).
    """
    if not os.path.exists(journal):
        return ""
    out = subprocess.run([TEXEL, "experiment", "list", "--db", journal, "--participant", participant, "--json"],
                         capture_output=True, text=True)
    if out.returncode == 0:
        sessions = json.loads(out.stdout)
        return sessions[-1]["status"] if sessions else ""
    if sessions_in_file(journal, participant) == 0:
        return "unmigrated"
    raise StationFailure("list of %s failed: %s" % (journal, out.stderr.strip()))


def main():
    rnd = random.Random(SEED)
    work = tempfile.mkdtemp(prefix="texel-pg-fault-")
    try:
        psql("DROP DATABASE IF EXISTS %s WITH (FORCE); CREATE DATABASE %s;" % (DB, DB))
        admin = "postgresql://texel_admin@/%s?host=%s&port=%d" % (DB, SOCK, PORT)
        names = ["f%d" % i for i in range(1, STATIONS + 1)]
        args = [TEXEL, "store", "init", "--postgres", admin, "--analyst", "fa"]
        for n in names:
            args += ["--station", n]
        subprocess.run(args, check=True, capture_output=True)
        psql("".join("ALTER ROLE %s PASSWORD 'pw-%s';" % (n, n) for n in names + ["fa"]), DB)
        proxy = Proxy()
        pgpass = os.path.join(work, "pgpass")
        with open(pgpass, "w") as f:
            for n in names + ["fa"]:
                for port in (PORT, proxy.port):
                    f.write("127.0.0.1:%d:%s:%s:pw-%s\n" % (port, DB, n, n))
        os.chmod(pgpass, 0o600)
        child_env = dict(os.environ, PGPASSFILE=pgpass)
        uris = {n: "postgresql://%s@127.0.0.1:%d/%s" % (n, proxy.port if n == names[-1] else PORT, DB) for n in names}
        plan = {n: ["%s-P%d" % (n.upper(), k) for k in range(1, PARTICIPANTS + 1)] for n in names}
        kills = {"n": 0, "creating": 0}
        errors = []

        def station(name, seed):
            try:
                run_station(name, seed)
            except BaseException:  # the script's own failure: never to be mistaken for lost trials
                errors.append("%s: station thread failed:\n%s" % (name, traceback.format_exc()))

        def run_station(name, seed):
            r = random.Random(seed)
            journal = os.path.join(work, name + ".db")
            for p in plan[name]:
                resume = False
                for attempt in range(40):
                    cmd = [TEXEL, "experiment", "run", PROTOCOL, "--participant", p, "--db", uris[name], "--journal", journal,
                           "--simulate", "default", "--pace", PACE, "--quiet"] + (["--resume"] if resume else [])
                    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=child_env)
                    killed = False
                    if name == names[0] and p == plan[name][0] and attempt == 0:
                        # Killed while it creates the journal (if the poll sees the file before it is migrated).
                        while not os.path.exists(journal) and proc.poll() is None:
                            time.sleep(0.001)
                        if proc.poll() is None:
                            proc.send_signal(signal.SIGKILL)
                            killed = True
                    elif r.random() < 0.5:
                        try:
                            proc.wait(timeout=r.uniform(0.05, 1.5))
                        except subprocess.TimeoutExpired:
                            proc.send_signal(signal.SIGKILL)
                            killed = True
                    _, err = proc.communicate()
                    if proc.returncode == 0:
                        break
                    if not (killed and proc.returncode == -signal.SIGKILL):
                        errors.append("%s %s: exit %d: %s" % (name, p, proc.returncode, err.strip()))
                        return
                    kills["n"] += 1
                    # Where did the kill land? The station's journal says.
                    state = journal_state(journal, p)
                    if state == "unmigrated":
                        kills["creating"] += 1
                    if state == "finished":
                        break
                    resume = state == "running"
                else:
                    errors.append("%s %s: never finished" % (name, p))

        threads = [threading.Thread(target=station, args=(n, rnd.random())) for n in names]
        start = time.monotonic()
        for t in threads:
            t.start()
        # The server goes away (as in a crash) for 2 s, then one link for 2 s.
        time.sleep(1.5)
        subprocess.run([SERVER_SCRIPT, "down", ENV_FILE], check=True)
        time.sleep(2.0)
        subprocess.run([SERVER_SCRIPT, "up", ENV_FILE], check=True)
        time.sleep(0.5)
        proxy.cut()
        time.sleep(2.0)
        proxy.restore()
        for t in threads:
            t.join()
        run_s = time.monotonic() - start
        if errors:
            sys.exit("station failures (no trial counted as lost):\n  " + "\n  ".join(errors))
        for n in names:
            out = subprocess.run([TEXEL, "experiment", "sync", "--db", uris[n], "--journal", os.path.join(work, n + ".db"),
                                  "--timeout", "60"], capture_output=True, text=True, env=child_env)
            if out.returncode != 0:
                sys.exit("sync of %s failed: %s" % (n, out.stderr.strip()))
        # Only a participant whose session finished on its station can have lost trials.
        unfinished = [p for n in names for p in plan[n] if journal_state(os.path.join(work, n + ".db"), p) != "finished"]
        if unfinished:
            sys.exit("station failures (no trial counted as lost): not finished in their journals: %s" % unfinished)
        # The reference: each participant uninterrupted, on one SQLite station.
        ref_db = os.path.join(work, "reference.db")
        for n in names:
            for p in plan[n]:
                subprocess.run([TEXEL, "experiment", "run", PROTOCOL, "--participant", p, "--db", ref_db, "--simulate",
                                "default", "--quiet"], check=True, capture_output=True)
        ref = export_rows(ref_db, os.path.join(work, "reference.csv"))
        got = export_rows("postgresql://fa@127.0.0.1:%d/%s" % (PORT, DB), os.path.join(work, "server.csv"), child_env)
        journals = [r for n in names for r in export_rows(os.path.join(work, n + ".db"), os.path.join(work, n + ".csv"))]
        key = lambda row: (dict(row)["participant"], dict(row)["protocol"], int(dict(row)["trial"]))
        ref_keys = [key(r) for r in ref]
        got_keys = [key(r) for r in got]
        lost = len(set(ref_keys) - set(got_keys))
        duplicated = len(got_keys) - len(set(got_keys))
        extra = len(set(got_keys) - set(ref_keys))
        differing = len(set(ref) ^ set(got)) if not lost and not duplicated and not extra else -1
        print("fault test: %d stations x %d participants, %d SIGKILLs (%d while the journal was created), server down 2 s, "
              "one link cut 2 s, run %.1f s" % (STATIONS, PARTICIPANTS, kills["n"], kills["creating"], run_s))
        print("server rows %d, reference rows %d: lost %d, duplicated %d, extra %d, differing %d"
              % (len(got), len(ref), lost, duplicated, extra, differing))
        if lost:
            # Where they went missing: already in a station's journal (the local store), or on the way to the server.
            journal_keys = {key(r) for r in journals}
            missing = set(ref_keys) - set(got_keys)
            print("participants with lost trials:", sorted({k[0] for k in missing}))
            print("  of them missing from the station journals: %d; in the journals but not on the server: %d"
                  % (len(missing - journal_keys), len(missing & journal_keys)))
        if lost or duplicated or extra or differing or kills["n"] == 0:
            sys.exit("FAILED")
        # Every session complete on the server (completion records shipped).
        st = subprocess.run([TEXEL, "experiment", "list", "--db", "postgresql://fa@127.0.0.1:%d/%s" % (PORT, DB)],
                            capture_output=True, text=True, env=child_env)
        running = [l for l in st.stdout.splitlines() if " running " in l]
        if st.returncode != 0 or running:
            sys.exit("sessions not complete on the server: %s %s" % (st.stderr.strip(), running))
        print("OK")
    finally:
        shutil.rmtree(work, ignore_errors=True)


main()
