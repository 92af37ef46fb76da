#!/usr/bin/env python3
"""The crevasse field of each case over time, from a study run with measure_interval_s.

    python3 scripts/over_time_table.py results/numerics/initiation_settling_800.db [--cases 0,1]
        [--every 0.1] [--tolerance-cracks 1] [--tolerance-spacing 0.0125]
    python3 scripts/over_time_table.py DB.checkpoints/CASE.ckpt.over_time.json --thickness 800

The second form reads a running case's rows so far (kept beside its checkpoint).

For each done (or checkpointed-then-done) case the measurement stored every measure_interval_s in
result_json.extra.over_time is printed as a table: simulated time, ice pushed through the gate in
H_i, crack count, spacing quartiles and median depth (in m and over H_i), and the share of the
deep ice (below H_i/2) that is damaged. --every thins the rows to one per that many H_i pushed.

The last column answers "has the field settled?": from which row on do count and median spacing
and depth stay within a tolerance of their values at the end of the run. Tolerances: one crack,
and for spacing and depth the larger of --tolerance-spacing (H_i; default one particle spacing at
dx = 10 m and H_i = 800 m, the detector's accuracy, docs/measurement.md) and the replica spread
given with --spread (H_i). The settling point is the first row after which every later row holds.
--tolerance-cracks -1 leaves the count out: in the passed frame (the steady protocol) the count
grows with the length of ice that has come over the lip, while spacing and depth settle.
"""
import argparse
import json
import sqlite3
import sys


def settled_from(rows, h, tol_count, tol_len):
    """Index of the first row from which every row stays within tolerance of the last one."""
    if not rows:
        return None
    last = rows[-1]
    def near(x, y):
        if x is None or y is None:
            return x is None and y is None
        return abs(x - y) / h <= tol_len
    def close(r):
        return ((tol_count < 0 or abs(r["crevasse_count"] - last["crevasse_count"]) <= tol_count)
                and near(median(r), median(last))
                and near(r.get("depth_median_m"), last.get("depth_median_m")))
    k = len(rows)
    while k > 0 and close(rows[k - 1]):
        k -= 1
    return k


def median(r):
    s = r.get("spacing_m") or []
    return s[1] if len(s) == 3 and s[1] is not None else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("db", help="study database, or a running case's CASE.ckpt.over_time.json")
    ap.add_argument("--thickness", type=float, default=0.0, help="H_i [m], with an over_time.json file")
    ap.add_argument("--pi", type=float, default=float("nan"), help="Pi, with an over_time.json file (shown only)")
    ap.add_argument("--cases", default="", help="case indices, e.g. 3,5,8-11 (default all)")
    ap.add_argument("--every", type=float, default=0.0, help="print one row per this many H_i pushed")
    ap.add_argument("--tolerance-cracks", type=int, default=1, help="-1: leave the count out (passed frame)")
    ap.add_argument("--tolerance-spacing", type=float, default=0.0125)
    ap.add_argument("--spread", type=float, default=0.0, help="replica spread of spacing/depth over H_i")
    a = ap.parse_args()
    if a.db.endswith(".json"):
        if a.thickness <= 0:
            sys.exit("over_time_table: give --thickness (H_i in m) with an over_time.json file")
        try:
            rows = [(0, a.thickness, a.pi, 0, json.dumps({"extra": {"over_time": json.load(open(a.db))}}))]
        except (OSError, ValueError) as e:
            sys.exit(f"over_time_table: cannot read {a.db}: {e}")
    else:
        rows = read_db(a.db)
    show(rows, a)


def read_db(path):
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        rows = con.execute("SELECT case_index, thickness_m, cohesion_ratio, seed, result_json FROM cases "
                           "WHERE status = 'done' ORDER BY case_index").fetchall()
    except sqlite3.Error as e:
        sys.exit(f"over_time_table: cannot read {path}: {e}")
    return rows


def case_list(text):
    """Case indices as the study command takes them: "3,5,8-11"."""
    wanted = set()
    for part in (p.strip() for p in text.split(",")):
        if "-" in part:
            first, last = (int(x) for x in part.split("-", 1))
            wanted.update(range(first, last + 1))
        elif part:
            wanted.add(int(part))
    return wanted


def show(rows, a):
    wanted = case_list(a.cases)
    tol_len = max(a.tolerance_spacing, a.spread)
    for idx, h, pi, seed, rj in rows:
        if wanted and idx not in wanted:
            continue
        ot = (json.loads(rj or "{}").get("extra") or {}).get("over_time") or []
        if not ot:
            print(f"case {idx}: no over_time (run without measure_interval_s, or stored from particles kept at a gate mark)")
            continue
        k = settled_from(ot, h, a.tolerance_cracks, tol_len)
        counted = f"count within {a.tolerance_cracks}, " if a.tolerance_cracks >= 0 else ""
        print(f"case {idx}: H_i = {h:g} m, Pi = {pi:g}{f', seed {seed}' if seed else ''}; {len(ot)} samples; "
              f"settled ({counted}spacing and depth within {tol_len:g} H_i of the end) "
              f"from {ot[k]['pushed_over_h']:.2f} H_i pushed, t = {ot[k]['time_s']:.0f} s")
        print(f"{'t/s':>6} {'pushed/H':>8} {'n':>3} {'q25/m':>7} {'med/m':>7} {'q75/m':>7} {'med/H':>6} "
              f"{'depth/m':>8} {'depth/H':>7} {'deepdmg':>7}")
        next_mark = 0.0
        for i, r in enumerate(ot):
            p = r["pushed_over_h"]
            if a.every > 0 and p < next_mark and i != len(ot) - 1 and i != k:
                continue
            next_mark = p + a.every
            s = [float("nan") if v is None else v for v in (r.get("spacing_m") or [None] * 3)]
            d = r.get("depth_median_m")
            d = float("nan") if d is None else d
            dd = r.get("deep_damaged_fraction")
            dd = float("nan") if dd is None else dd
            mark = " <- settled" if i == k else ""
            print(f"{r['time_s']:6.0f} {p:8.2f} {r['crevasse_count']:3d} {s[0]:7.0f} {s[1]:7.0f} {s[2]:7.0f} "
                  f"{s[1] / h:6.3f} {d:8.0f} {d / h:7.3f} {dd:7.3f}{mark}")
        print()


if __name__ == "__main__":
    main()
