#!/usr/bin/env python3
"""The strength regime's test: the crevasse field at one cohesion c across ice thicknesses.

If spacing is set by the ice strength (L_p proportional to c/(rho_i g)), cases with the same c and
different H_i carry the same spacing; if it is set by bending, it follows H_i. Reads the done 2D
cases of one or more study databases (replicas are listed one by one), groups them by c, and prints
one markdown row per case for every c reached at two or more thicknesses (--every-c: every c):

    python3 scripts/fixed_cohesion_table.py results/regime_initiation.db [results/regime_initiation_replicas.db ...]

With --by-pi the same cases are grouped by Pi instead, with spacing and depth over H_i: the
dependence on H_i at fixed Pi (a law in Pi alone carries the same L_p/H_i and D_p/H_i at every H_i).

Only the reference step (slope 1/2, L_s = H_i) is kept unless --all-steps is given. The last
column reads the crevasse table of the window's first LEAD·L_s (--lead, default 1; L_s the step's
horizontal length): in the draped frame that is the ice that lay on the ramp at the start (the
window begins at the most downstream ice that came over the lip), where the row forms, apart from
the floor ice further on. `ramp_ice_extent.py` measures where that ice ends in kept particles.
"""
import argparse
import sqlite3
import statistics
import sys

def median(values):
    return statistics.median(values) if values else None


def cases(db_path, all_steps, lead):
    con = sqlite3.connect(f"file:{db_path}?mode=ro", uri=True)
    rows = con.execute(
        """select c.case_id, c.case_index, c.seed, c.thickness_m, c.cohesion_ratio, c.slope,
                  c.step_length_ratio, s.crevasse_count, s.spacing_median_m, s.spacing_q25_m,
                  s.spacing_q75_m, s.depth_median_m, c.under_resolved, s.window_min_x_m,
                  c.tensile_strength_pa,
                  json_extract(c.scene_json, '$.ice.density') * json_extract(c.scene_json, '$.gravity.g'),
                  json_extract(c.scene_json, '$.bed.step_length')
           from cases c join summaries s on s.case_id = c.case_id
           where c.status = 'done' and c.dim = 2""").fetchall()
    out = []
    for (case_id, index, seed, h, pi, slope, ls_ratio, count, l_med, l_25, l_75, d_med, under,
         window_min, c, rho_g, step_length) in rows:
        if not all_steps and (abs((slope or 0.5) - 0.5) > 1e-9 or abs(ls_ratio - 1.0) > 1e-9):
            continue
        # As `crevasse fit --ramp-ice` reads them: the spacings the measurement kept between two
        # crevasses of the leading window.
        lead_cracks = con.execute(
            "select x_m, depth_m, spacing_to_next_m from crevasses where case_id = ? and x_m <= ? "
            "order by x_m", (case_id, window_min + lead * step_length)).fetchall()
        pairs = [s for _, _, s in lead_cracks[:-1] if s is not None]
        out.append(dict(db=db_path, index=index, seed=seed, h=h, pi=pi, c=c, rho_g=rho_g,
                        count=count, l_med=l_med, l_25=l_25, l_75=l_75, d_med=d_med,
                        under=bool(under), lead_count=len(lead_cracks), lead_l=median(pairs),
                        lead_d=median([d for _, d, _ in lead_cracks])))
    con.close()
    return out


def fmt(value, digits=0):
    return "–" if value is None else f"{value:.{digits}f}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("databases", nargs="+")
    parser.add_argument("--all-steps", action="store_true", help="keep every step shape")
    parser.add_argument("--lead", type=float, default=1.0,
                        help="length of the window's leading part, in L_s (default 1)")
    parser.add_argument("--every-c", action="store_true",
                        help="also list the values of c (or Pi) reached at one thickness only")
    parser.add_argument("--by-pi", action="store_true",
                        help="group by Pi, spacing and depth over H_i: the dependence on H_i at fixed Pi")
    args = parser.parse_args()

    every = []
    for db in args.databases:
        try:
            every += cases(db, args.all_steps, args.lead)
        except sqlite3.Error as error:
            sys.exit(f"error: {db}: {error}")

    if args.by_pi:
        by_pi(every, args.every_c)
        return
    groups = {}
    for case in every:
        groups.setdefault(round(case["c"] / 1000.0), []).append(case)

    print("| c [kPa] | c/(ρ_i g) [m] | H_i [m] | Π | case (seed) | count | median L_p [m] (quartiles) "
          "| median D_p [m] | D_p/(c/(ρ_i g)) | L_p/D_p | window's first LEAD·L_s: count, median pair spacing, median depth [m] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for c_kpa in sorted(groups):
        group = sorted(groups[c_kpa], key=lambda k: (k["h"], k["seed"]))
        if len({k["h"] for k in group}) < 2 and not args.every_c:
            continue
        for k in group:
            length = k["c"] / k["rho_g"]  # c/(rho_i g) with the case's own density and gravity
            ratio = None if (k["l_med"] is None or not k["d_med"]) else k["l_med"] / k["d_med"]
            spacing = fmt(k["l_med"])
            if k["l_25"] is not None:
                spacing += f" ({fmt(k['l_25'])}–{fmt(k['l_75'])})"
            print(f"| {c_kpa} | {length:.0f} | {k['h']:.0f} | {k['pi']:g}{' (under-resolved)' if k['under'] else ''} "
                  f"| {k['index']} ({k['seed']}) | {k['count']} | {spacing} | {fmt(k['d_med'])} "
                  f"| {fmt(None if k['d_med'] is None else k['d_med'] / length, 1)} | {fmt(ratio, 2)} "
                  f"| {k['lead_count']}, {fmt(k['lead_l'])}, {fmt(k['lead_d'])} |")


def over_h(value, h, digits=3):
    return fmt(None if value is None else value / h, digits)


def by_pi(every, every_pi):
    groups = {}
    for case in every:
        groups.setdefault(round(case["pi"], 6), []).append(case)
    print("| Π | H_i [m] | c [kPa] | case (seed) | count | L_p/H_i | D_p/H_i "
          "| window's first LEAD·L_s: count, L_p/H_i, D_p/H_i |")
    print("|---|---|---|---|---|---|---|---|")
    for pi in sorted(groups):
        group = sorted(groups[pi], key=lambda k: (k["h"], k["seed"]))
        if len({k["h"] for k in group}) < 2 and not every_pi:
            continue
        for k in group:
            h = k["h"]
            print(f"| {pi:g}{' (under-resolved)' if k['under'] else ''} | {h:.0f} | {k['c'] / 1000:.0f} "
                  f"| {k['index']} ({k['seed']}) | {k['count']} | {over_h(k['l_med'], h)} "
                  f"| {over_h(k['d_med'], h)} | {k['lead_count']}, {over_h(k['lead_l'], h)}, "
                  f"{over_h(k['lead_d'], h)} |")


if __name__ == "__main__":
    main()
