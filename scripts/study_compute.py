#!/usr/bin/env python3
"""The compute that study databases hold: per database and H_i, the cases simulated, their
particle-steps and engine wall time, and the cases served by another case's run (measured from
particles a longer run kept at this case's stop, which costs seconds). A case measured again from
its own run's particles counts that run. Wall times add up per case: two cases run at once count
twice."""
import os
import argparse
import json
import sqlite3
import statistics
import sys
from collections import defaultdict


def rows(db):
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    try:
        cases = con.execute(
            "SELECT thickness_m, status, wall_s, particle_steps, threads, run_json FROM cases").fetchall()
    finally:
        con.close()
    return os.path.basename(db), cases


def self_test():
    """Four cases at one H_i: one run, one measured again from its own run's particles (its run
    counts), one served by a longer run's mark (no compute), one pending."""
    import io
    import tempfile
    from contextlib import redirect_stdout
    with tempfile.TemporaryDirectory() as d:
        db = os.path.join(d, "t.db")
        con = sqlite3.connect(db)
        con.execute("CREATE TABLE cases (thickness_m REAL, status TEXT, wall_s REAL, particle_steps INTEGER, "
                    "threads INTEGER, run_json TEXT)")
        con.executemany("INSERT INTO cases VALUES (?, ?, ?, ?, ?, ?)", [
            (400, "done", 1000.0, 2_000_000_000, 1, json.dumps({"engine_wall_s": 1000.0})),
            (400, "done", 0.2, 1_000_000_000, 1,
             json.dumps({"engine_wall_s": 800.0, "measured_from": {"database": "t.db"}})),
            (400, "done", 0.2, 5_000_000_000, 1,
             json.dumps({"engine_wall_s": 9000.0,
                         "measured_from": {"database": "s.db", "kept_at_gate_mark_of_case_id": "x"}})),
            (400, "pending", None, None, None, None),
        ])
        con.commit()
        con.close()
        out = io.StringIO()
        with redirect_stdout(out):
            report([db])
    expected = "| t.db | 400 | 2 | 1 | 1 | 3.0 | 0.50 | 1.6 |"
    if expected not in out.getvalue().splitlines():
        sys.exit(f"study_compute.py --self-test: expected the row\n{expected}\ngot\n{out.getvalue()}")
    print("study_compute.py --self-test: passed")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("databases", nargs="*")
    ap.add_argument("--self-test", action="store_true", help="check the accounting on a generated database")
    args = ap.parse_args()
    if args.self_test:
        self_test()
        return
    if not args.databases:
        ap.error("give one or more study databases")
    report(args.databases)


def report(databases):
    print("| database | H_i [m] | cases run | served by another case's run | pending | particle-steps [10⁹] | case wall time [h] | M particle-steps/s per case (median) |")
    print("|---|---|---|---|---|---|---|---|")
    total_pst = 0.0
    total_wall = 0.0
    total_run = 0
    for db in databases:
        try:
            name, cases = rows(db)
        except sqlite3.Error as e:
            sys.exit(f"study_compute.py: {db}: {e}")
        by_h = defaultdict(lambda: {"run": 0, "kept": 0, "pending": 0, "pst": 0.0, "wall": 0.0, "rates": []})
        for h, status, wall, pst, threads, run_json in cases:
            g = by_h[h]
            if status != "done":
                g["pending"] += 1
                continue
            run = json.loads(run_json) if run_json else {}
            if "kept_at_gate_mark_of_case_id" in run.get("measured_from", {}):
                g["kept"] += 1
                continue
            wall = run.get("engine_wall_s", wall)
            g["run"] += 1
            g["pst"] += pst or 0
            g["wall"] += wall or 0.0
            if wall and pst:
                g["rates"].append(pst / wall / 1e6)
        for h in sorted(by_h):
            g = by_h[h]
            rate = f"{statistics.median(g['rates']):.1f}" if g["rates"] else "–"
            print(f"| {name} | {h:.0f} | {g['run']} | {g['kept']} | {g['pending']} | {g['pst'] / 1e9:.1f} | "
                  f"{g['wall'] / 3600:.2f} | {rate} |")
            total_pst += g["pst"]
            total_wall += g["wall"]
            total_run += g["run"]
    print(f"| all | | {total_run} | | | {total_pst / 1e9:.1f} | {total_wall / 3600:.2f} | |")


if __name__ == "__main__":
    main()
