#!/usr/bin/env python3
"""Drive-speed table of a study that sweeps /drive/speed (studies/cliff/drive_speed_long.json).

    python3 scripts/drive_speed_table.py results/cliff/drive_speed_long.db [--reference 4]

Exports the database with `crevasse export` into a temporary directory and prints, per
(H_i, Pi) pair, one Markdown row per drive speed: the crevasse count, the median spacing and
depth over H_i with their quartiles, whether each median lies inside the reference speed's
quartile range (its spread), and the case wall time over the reference's.
"""
import argparse
import csv
import subprocess
import sys
import tempfile
from pathlib import Path


def num(text):
    return float(text) if text not in ("", None) else None


def fmt(v, digits=3):
    return "-" if v is None else f"{v:.{digits}g}"


def replica_table(groups, reference):
    """Replicated runs: each speed's replica medians against the reference speed's range."""
    print("| H_i [m] | Π | V_x [m/s] | L_p/H_i of the replicas | mean | in reference range | "
          "D_p/H_i of the replicas | mean | in reference range | mean wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for (h, pi), by_speed in sorted(groups.items()):
        ref = by_speed.get(reference, [])

        def medians(runs, name):
            return [m for m in (num(s[f"{name}_median_over_h"]) for _, s in runs) if m is not None]

        for v, runs in sorted(by_speed.items()):
            cells = []
            for name in ("spacing", "depth"):
                vals = medians(runs, name)
                mean = sum(vals) / len(vals) if vals else None
                r = medians(ref, name)
                inside = ""
                if v != reference:
                    inside = "-" if mean is None or not r else (
                        "yes" if min(r) <= mean <= max(r) else "**no**")
                frag = sum(1 for _, s in runs if s.get("fragmented") == "1")
                listed = ", ".join(fmt(x) for x in vals) + (f" ({frag} fragmented)" if frag else "")
                cells += [listed or "-", fmt(mean), inside]
            wall = [num(c["wall_s"]) for c, _ in runs]
            print(f"| {h:g} | {pi:.3g} | {v:g} | " + " | ".join(cells) +
                  f" | {sum(wall) / len(wall):.3g} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("db")
    ap.add_argument("--reference", type=float, default=4.0, help="reference drive speed [m/s]")
    ap.add_argument("--crevasse", default="build/cli/crevasse")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([args.crevasse, "export", args.db, "--csv", tmp], check=True,
                       stdout=subprocess.DEVNULL)
        cases = list(csv.DictReader(open(Path(tmp) / "cases.csv")))
        summaries = {r["case_id"]: r for r in csv.DictReader(open(Path(tmp) / "summaries.csv"))}
    if not cases or "axis./drive/speed" not in cases[0]:
        sys.exit(f"{args.db}: not a study over /drive/speed")
    groups = {}
    for c in cases:
        if c["status"] != "done":
            continue
        s = summaries[c["case_id"]]
        key = (float(c["thickness_m"]), float(c["cohesion_ratio"]))
        groups.setdefault(key, {}).setdefault(float(c["axis./drive/speed"]), []).append((c, s))
    if any(len(runs) > 1 for by_speed in groups.values() for runs in by_speed.values()):
        replica_table(groups, args.reference)
        return
    groups = {k: {v: runs[0] for v, runs in by.items()} for k, by in groups.items()}

    print("| H_i [m] | Π | V_x [m/s] | crevasses | L_p/H_i [q25, q75] | in spread | "
          "D_p/H_i [q25, q75] | in spread | wall [s] | wall / reference |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for (h, pi), by_speed in sorted(groups.items()):
        ref = by_speed.get(args.reference)
        for v, (c, s) in sorted(by_speed.items()):
            l = [num(s[f"spacing_{q}_over_h"]) for q in ("q25", "median", "q75")]
            d = [num(s[f"depth_{q}_over_h"]) for q in ("q25", "median", "q75")]
            frag = s.get("fragmented") == "1"
            wall = num(c["wall_s"])

            def inside(vals, name):
                if ref is None or v == args.reference or vals[1] is None:
                    return "" if v == args.reference else "-"
                r = [num(ref[1][f"{name}_{q}_over_h"]) for q in ("q25", "median", "q75")]
                if r[0] is None:
                    return "-"
                return "yes" if r[0] <= vals[1] <= r[2] else "**no**"

            speed = "-"
            if ref is not None and wall:
                speed = "reference" if v == args.reference else f"{wall / num(ref[0]['wall_s']):.2f}"
            print(f"| {h:g} | {pi:.3g} | {v:g} | {s['crevasse_count']}{' (fragmented)' if frag else ''} | "
                  f"{fmt(l[1])} [{fmt(l[0])}, {fmt(l[2])}] | {inside(l, 'spacing')} | "
                  f"{fmt(d[1])} [{fmt(d[0])}, {fmt(d[2])}] | {inside(d, 'depth')} | "
                  f"{fmt(wall, 3)} | {speed} |")


if __name__ == "__main__":
    main()
