#!/usr/bin/env python3
"""The strength regime's test: the crevasse field at one cohesion c across ice thicknesses.

If spacing is set by the ice strength (L_p proportional to c/(rho_i g)), cases with the same c and
different H_i carry the same spacing; if it is set by bending, it follows H_i. Reads the done 2D
cases of one or more study databases (replicas are listed one by one), groups them by c, and prints
one markdown row per case for every c reached at two or more thicknesses:

    python3 scripts/fixed_cohesion_table.py results/regime_initiation.db [results/regime_initiation_replicas.db ...]

Only the reference step (slope 1/2, L_s = H_i) is kept unless --all-steps is given.
"""
import argparse
import sqlite3
import sys

RHO_G = 917.0 * 9.81  # rho_i g [Pa/m], the scenes' ice density and gravity


def cases(db_path, all_steps):
    con = sqlite3.connect(f"file:{db_path}?mode=ro", uri=True)
    rows = con.execute(
        """select c.case_index, c.seed, c.thickness_m, c.cohesion_ratio, c.slope, c.step_length_ratio,
                  s.crevasse_count, s.spacing_median_m, s.spacing_q25_m, s.spacing_q75_m,
                  s.depth_median_m, c.under_resolved
           from cases c join summaries s on s.case_id = c.case_id
           where c.status = 'done' and c.dim = 2""").fetchall()
    con.close()
    out = []
    for (index, seed, h, pi, slope, ls_ratio, count, l_med, l_25, l_75, d_med, under) in rows:
        if not all_steps and (abs((slope or 0.5) - 0.5) > 1e-9 or abs(ls_ratio - 1.0) > 1e-9):
            continue
        out.append(dict(db=db_path, index=index, seed=seed, h=h, pi=pi, c=pi * RHO_G * h,
                        count=count, l_med=l_med, l_25=l_25, l_75=l_75, d_med=d_med,
                        under=bool(under)))
    return out


def fmt(value, digits=0):
    return "–" if value is None else f"{value:.{digits}f}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("databases", nargs="+")
    parser.add_argument("--all-steps", action="store_true", help="keep every step shape")
    args = parser.parse_args()

    every = []
    for db in args.databases:
        try:
            every += cases(db, args.all_steps)
        except sqlite3.Error as error:
            sys.exit(f"error: {db}: {error}")

    groups = {}
    for case in every:
        groups.setdefault(round(case["c"] / 1000.0), []).append(case)

    print("| c [kPa] | c/(ρ_i g) [m] | H_i [m] | Π | case (seed) | count | median L_p [m] (quartiles) "
          "| median D_p [m] | D_p/(c/(ρ_i g)) | L_p/D_p |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for c_kpa in sorted(groups):
        group = sorted(groups[c_kpa], key=lambda k: (k["h"], k["seed"]))
        if len({k["h"] for k in group}) < 2:
            continue
        length = c_kpa * 1000.0 / RHO_G
        for k in group:
            ratio = None if (k["l_med"] is None or not k["d_med"]) else k["l_med"] / k["d_med"]
            spacing = fmt(k["l_med"])
            if k["l_25"] is not None:
                spacing += f" ({fmt(k['l_25'])}–{fmt(k['l_75'])})"
            print(f"| {c_kpa} | {length:.0f} | {k['h']:.0f} | {k['pi']:g}{' (under-resolved)' if k['under'] else ''} "
                  f"| {k['index']} ({k['seed']}) | {k['count']} | {spacing} | {fmt(k['d_med'])} "
                  f"| {fmt(None if k['d_med'] is None else k['d_med'] / length, 1)} | {fmt(ratio, 2)} |")


if __name__ == "__main__":
    main()
