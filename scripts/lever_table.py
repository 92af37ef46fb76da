#!/usr/bin/env python3
"""Compare replicated settings of a numerical lever with a reference setting.

    python3 scripts/lever_table.py results/numerics/flowing_domain_replicas_total_volume.db \
        [MORE.db ...] --reference upstream_length_ratio=2 downstream_length_ratio=3.95

A study that sweeps one or more numerical settings (domain lengths, drive speed, CFL) crossed with
cohesion_ratio and replicated with jittered particles; several databases are read as one (a
setting is the set of swept values other than cohesion_ratio and the replica, so a study that
adds a setting sweeps every name the reference names). For each Pi and setting the script prints
the replicas' median spacing and depth over H_i, their mean and standard deviation, the medians
of all crevasses of all replicas pooled, and the shift of the mean against the reference setting.

Rule: a setting is as good as the reference at a Pi when, for spacing and for depth, the mean of
its replicas lies within a tolerance of the reference replicas' mean, the tolerance being the
larger of the reference replicas' standard deviation (the scatter of one run) and one particle
spacing (the detector's accuracy, docs/measurement.md). A shift smaller than that changes what a
single case reports by less than the case's own scatter.

Why not "inside the reference replicas' range": for n reference and m test replicas drawn from
one distribution, all m fall inside the range of the n with probability n(n-1)/((n+m)(n+m-1)),
0.2 for three and three, so that rule rejects an unchanged setting four times in five per
quantity.
"""
import argparse
import json
import sqlite3
import statistics
import sys


def parse_reference(items):
    ref = {}
    for item in items:
        if "=" not in item:
            sys.exit(f"lever_table: --reference takes name=value pairs, got '{item}'")
        name, value = item.split("=", 1)
        ref[name] = float(value)
    return ref


def mean_sd(values):
    if not values:
        return None, None
    if len(values) == 1:
        return values[0], 0.0
    return statistics.mean(values), statistics.stdev(values)


def fmt(v, digits=3):
    return "-" if v is None else f"{v:.{digits}f}"


def load(db):
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    rows = con.execute(
        "SELECT c.case_id, c.axes_json, c.thickness_m, c.wall_s, s.spacing_median_over_h,"
        " s.depth_median_over_h, s.crevasse_count, s.spacings_json, s.settings_json, c.cohesion_ratio"
        " FROM cases c JOIN summaries s USING(case_id) WHERE c.status = 'done'").fetchall()
    depths = {}
    for case_id, d in con.execute("SELECT case_id, depth_over_h FROM crevasses"):
        depths.setdefault(case_id, []).append(d)
    con.close()
    return rows, depths


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("db", nargs="+")
    ap.add_argument("--reference", nargs="+", required=True, metavar="NAME=VALUE")
    ap.add_argument("--group", default="cohesion_ratio",
                    help="axis the settings are compared within (default cohesion_ratio)")
    args = ap.parse_args()
    ref = parse_reference(args.reference)

    rows, depths = [], {}
    for db in args.db:
        db_rows, db_depths = load(db)
        if not db_rows:
            sys.exit(f"lever_table: no finished case in {db}")
        rows += db_rows
        depths.update(db_depths)
    groups = {}
    for case_id, axes_json, h, wall, sp, dp, count, spacings_json, settings_json, pi in rows:
        axes = json.loads(axes_json)
        # A study that fixes Π instead of sweeping it is one group, at its Π.
        group = axes.pop(args.group, pi if args.group == "cohesion_ratio" else None)
        axes.pop("replica", None)
        missing = [k for k in ref if k not in axes]
        if missing:
            sys.exit(f"lever_table: axis {missing[0]} of --reference is not swept in every database")
        setting = tuple(sorted(axes.items()))
        spacing_m = json.loads(settings_json)["particle_spacing_m"]
        groups.setdefault(group, {}).setdefault(setting, []).append({
            "spacing": sp, "depth": dp, "count": count, "wall": wall, "h": h,
            "tol_floor": spacing_m / h,
            "all_spacings": [x / h for x in json.loads(spacings_json)],
            "all_depths": depths.get(case_id, [])})

    ref_key = tuple(sorted(ref.items()))
    print("| Π | setting | n | L_p/H_i of the replicas | mean ± sd | pooled | shift / tol | "
          "D_p/H_i of the replicas | mean ± sd | pooled | shift / tol | mean wall [s] | verdict |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for group in sorted(groups):
        settings = groups[group]
        if ref_key not in settings:
            sys.exit(f"lever_table: no reference case at {args.group} = {group}")
        reference = settings[ref_key]
        for setting in sorted(settings, key=lambda s: (s != ref_key, s)):
            runs = settings[setting]
            cells, ok = [], True
            for name in ("spacing", "depth"):
                values = [r[name] for r in runs if r[name] is not None]
                ref_values = [r[name] for r in reference if r[name] is not None]
                m, sd = mean_sd(values)
                rm, rsd = mean_sd(ref_values)
                pooled = [x for r in runs for x in r["all_" + ("spacings" if name == "spacing" else "depths")]]
                shift = "reference"
                if setting != ref_key:
                    if m is None or rm is None:
                        shift, ok = "no value", False
                    else:
                        tol = max(rsd, reference[0]["tol_floor"])
                        shift = f"{m - rm:+.3f} / {tol:.3f}"
                        ok = ok and abs(m - rm) <= tol
                cells += [", ".join(fmt(v) for v in values) or "-",
                          f"{fmt(m)} ± {fmt(sd)}",
                          fmt(statistics.median(pooled)) if pooled else "-", shift]
            wall = statistics.mean(r["wall"] for r in runs if r["wall"] is not None)
            label = ", ".join(f"{k} = {v:g}" for k, v in setting)
            verdict = "reference" if setting == ref_key else ("as good" if ok else "differs")
            print(f"| {group:g} | {label} | {len(runs)} | " + " | ".join(cells) +
                  f" | {wall:.0f} | {verdict} |")


if __name__ == "__main__":
    main()
