#!/usr/bin/env python3
"""Kill/resume check on the default scene (docs/reliability.md, "Guarantees").

Runs a small study on studies/scenes/flowing_inflow_2d.json once without interruption, then
again while sending SIGKILL (default 20) and SIGINT (default 5) at random moments, resuming with
the same command after each. Checks that the database passes integrity_check, every case is done
exactly once with the result hash of the uninterrupted run, and every SIGINT ended the process
with exit code 130. Prints the figures.

    python3 scripts/kill_resume.py [--kills 20] [--interrupts 5] [--binary build/cli/crevasse]
"""
import argparse
import json
import os
import random
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--kills", type=int, default=20)
    ap.add_argument("--interrupts", type=int, default=5)
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "cli", "crevasse"))
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    work = tempfile.mkdtemp(prefix="kill_resume.")
    study = {
        "name": "kill_resume",
        "base_scene": os.path.join(ROOT, "studies", "scenes", "flowing_inflow_2d.json"),
        "fixed": {"/output/vtu_interval": 0, "gate_length_ratio": 3},
        "sweep": {"cohesion_ratio": {"log": [0.1, 1.0, 8]}},
        "resources": {"jobs": 2, "threads_per_case": 1, "checkpoint_interval_s": 2},
    }
    path = os.path.join(work, "s.json")
    with open(path, "w") as f:
        json.dump(study, f)

    def cmd(db):
        return [a.binary, "study", path, "--db", os.path.join(work, db), "--quiet"]

    t0 = time.time()
    subprocess.run(cmd("ref.db"), check=True)
    ref_wall = time.time() - t0
    signals = [signal.SIGKILL] * a.kills + [signal.SIGINT] * a.interrupts
    rng.shuffle(signals)
    sent = {"SIGKILL": 0, "SIGINT": 0}
    interrupt_codes = []
    finished_early = 0
    for sig in signals:
        p = subprocess.Popen(cmd("k.db"), stderr=subprocess.DEVNULL)
        try:
            p.wait(timeout=rng.uniform(0.3, max(1.0, ref_wall / 15)))
            finished_early += 1  # ended before the signal: nothing left to interrupt
            break
        except subprocess.TimeoutExpired:
            p.send_signal(sig)
            code = p.wait()
            sent[signal.Signals(sig).name] += 1
            if sig == signal.SIGINT:
                interrupt_codes.append(code)
    final = subprocess.run(cmd("k.db"))

    def rows(db, sql):
        con = sqlite3.connect("file:%s?mode=ro" % os.path.join(work, db), uri=True)
        try:
            return con.execute(sql).fetchall()
        finally:
            con.close()

    integrity = rows("k.db", "PRAGMA integrity_check")[0][0]
    ref = dict(rows("ref.db", "SELECT case_id, result_hash FROM cases"))
    got = rows("k.db", "SELECT case_id, status, result_hash, attempts, "
                       "json_extract(run_json, '$.resumed_from_time_s') FROM cases")
    same = all(status == "done" and ref.get(cid) == h for cid, status, h, _, _ in got)
    resumed = sum(1 for *_, r in got if r is not None and r > 0)
    sessions = rows("k.db", "SELECT count(*) FROM sessions")[0][0]
    ok = (final.returncode == 0 and integrity == "ok" and same and len(got) == len(ref)
          and all(c == 130 for c in interrupt_codes))
    print("kill/resume on %s (%d cases, 2 jobs; uninterrupted run %.0f s)" %
          (os.path.relpath(study["base_scene"], ROOT), len(ref), ref_wall))
    print("  SIGKILL sent %d, SIGINT sent %d (exit codes %s), sessions %d" %
          (sent["SIGKILL"], sent["SIGINT"], sorted(set(interrupt_codes)), sessions))
    print("  integrity_check %s; %d/%d cases done with the uninterrupted run's result hash; "
          "%d continued from a checkpoint; attempts per case %s" %
          (integrity, sum(1 for g in got if g[1] == "done" and ref.get(g[0]) == g[2]), len(ref),
           resumed, sorted(g[3] for g in got)))
    print("  %s (scratch: %s)" % ("OK" if ok else "FAILED", work))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
