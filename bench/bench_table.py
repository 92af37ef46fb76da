#!/usr/bin/env python3
"""Prints the benchmark table from the rounds that scripts/bench.sh ran.

Usage: bench_table.py DIR [--stages]

DIR holds, per round R and group G (a dimension and a thread count), limit_R_G.json (the limit
kernel, and the limit kernel with the ΔJ-bar average) and step_R_G.json (the engine's elastic and softening steps), each one repetition, run
one right after the other; and sortstep.json (the sorting-step heap). Interleaving makes the
fraction of the limit robust to a machine whose speed drifts: each round's engine rate is divided
by the limit's rate of the same round, and the table gives the median of those ratios. Every
other number is the median over the rounds; the ± column is the standard deviation of the rate
over them, relative. 2T/1T is the median over the rounds of the two-thread over the one-thread
rate. Stages are grouped into phases: prepare (sort, grid box, P2G colouring), P2G, grid
(velocity, gravity, boundary conditions), G2P (gather, volume averaging, F update and material,
and the per-particle effects the update sweep applies: bed projection, piston, clamp, the time
step's reduction) and other (the time step). The limit kernel's rows give its own phases (its
grid clear is in P2G). --stages prints every stage's ns per particle-step instead.
"""
import glob
import json
import os
import re
import statistics
import sys

PHASES = {
    "prepare": ["prepare_grid"],
    "p2g": ["p2g"],
    "grid": ["grid", "grid_velocity", "grid_velocity_gravity", "basal_friction", "box_walls",
             "lateral_walls", "velocity_boundaries", "settle_damping", "drive_grid"],
    "g2p": ["g2p", "g2p_velocity", "volume_averaging", "g2p_elastic", "g2p_return_mapping"],
}
UNITS = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def runs_of(path):
    """The single-repetition runs of a Google Benchmark JSON file, by name without suffixes."""
    with open(path) as f:
        data = json.load(f)
    out = {}
    for b in data["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration":
            continue
        out[b["run_name"].split("/iterations:")[0]] = b
    return out


def key_of(name):
    """('2d', 'softening', 1) for step/2d/softening/threads:1, ('2d', 'limit', 1) for limit."""
    parts = name.split("/")
    threads = int(parts[-1].split(":")[1])
    if parts[0] in ("limit", "limit_averaging"):
        return parts[1], parts[0], threads
    return parts[1], parts[2], threads


def phase_ns(entry):
    out = {p: 0.0 for p in list(PHASES) + ["other"]}
    for k, v in entry.items():
        if not k.startswith("ns_"):
            continue
        stage = k[3:]
        phase = next((p for p, names in PHASES.items() if stage in names), "other")
        out[phase] += v
    return out


def main(argv):
    if len(argv) < 2 or not os.path.isdir(argv[1]):
        print(__doc__, file=sys.stderr)
        return 2
    folder = argv[1]
    show_stages = "--stages" in argv
    # rounds[key] = {round: entry}
    rounds = {}
    for path in glob.glob(os.path.join(folder, "*_*_*.json")):
        m = re.match(r"(limit|step)_(\d+)_", os.path.basename(path))
        if not m:
            continue
        for name, entry in runs_of(path).items():
            rounds.setdefault(key_of(name), {})[int(m.group(2))] = entry
    if not rounds:
        print(f"bench_table.py: no rounds in {folder}", file=sys.stderr)
        return 2
    sort_steps = {}
    if os.path.exists(os.path.join(folder, "sortstep.json")):
        sort_steps = runs_of(os.path.join(folder, "sortstep.json"))

    def rate(k, r):
        return rounds[k][r]["particle_steps_per_s"]

    def median_of(k, field):
        return statistics.median(e[field] for e in rounds[k].values())

    def median_ratio(k, other):
        common = sorted(set(rounds[k]) & set(rounds.get(other, {})))
        if not common:
            return None
        return statistics.median(rate(k, r) / rate(other, r) for r in common)

    def cpu_rate(k, r):
        e = rounds[k][r]
        return e["particles"] / (e["cpu_time"] * UNITS[e["time_unit"]])

    order = sorted(rounds, key=lambda k: (k[0], not k[1].startswith("limit"), k[1], k[2]))
    n_rounds = max(len(v) for v in rounds.values())
    if show_stages:
        stages = sorted({s for k in order for e in rounds[k].values() for s in e if s.startswith("ns_")})
        print("| stage (ns per particle-step) | " +
              " | ".join(f"{d} {m} {t}T" for d, m, t in order) + " |")
        print("|---|" + "---|" * len(order))
        for s in stages:
            cells = []
            for k in order:
                values = [e[s] for e in rounds[k].values() if s in e]
                cells.append(f"{statistics.median(values):.1f}" if values else "")
            print(f"| {s[3:]} | " + " | ".join(cells) + " |")
        return 0

    header = ["case", "particles", "M pst/s", "±", "of limit", "of limit + avg", "2T/1T", "1T M pst/CPU-s",
              "of limit (CPU)", "particle B", "grid B",
              "heap B", "peak B (1st step)", "heap growth B/step", "prep", "p2g", "grid", "g2p", "other"]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for k in order:
        dim, material, threads = k
        rates = [e["particle_steps_per_s"] for e in rounds[k].values()]
        med_rate = statistics.median(rates)
        spread = f"{100.0 * statistics.stdev(rates) / med_rate:.0f}%" if len(rates) > 1 else ""
        limit_key = (dim, "limit", threads)
        frac = median_ratio(k, limit_key)
        avg_key = (dim, "limit_averaging", threads)
        frac_avg = median_ratio(k, avg_key) if not material.startswith("limit") else None
        one = median_ratio(k, (dim, material, 1)) if threads > 1 else None
        cpu = cpu_frac = ""
        if threads == 1:
            cpu = f"{statistics.median(cpu_rate(k, r) for r in rounds[k]) / 1e6:.2f}"
            if limit_key in rounds:
                common = sorted(set(rounds[k]) & set(rounds[limit_key]))
                cpu_frac = f"{100.0 * statistics.median(cpu_rate(k, r) / cpu_rate(limit_key, r) for r in common):.0f}%"
        first = rounds[k][min(rounds[k])]
        ph = {p: statistics.median(phase_ns(e)[p] for e in rounds[k].values())
              for p in ["prepare", "p2g", "grid", "g2p", "other"]}
        names = {"limit": "limit kernel", "limit_averaging": "limit kernel + ΔJ-bar average"}
        label = f"{dim.upper()} {names.get(material, material)}, " \
                f"{threads} thread{'s' if threads > 1 else ''}"
        common = [label, f"{first['particles']:.0f}", f"{med_rate / 1e6:.2f}", spread,
                  f"{100.0 * frac:.0f}%" if frac else "", f"{100.0 * frac_avg:.0f}%" if frac_avg else "",
                  f"{one:.2f}×" if one else "", cpu, cpu_frac]
        if material.startswith("limit"):
            cells = common + [f"{first['state_B']:.0f}", "", "", "", ""]
        else:
            cells = common + [f"{first['particle_B']:.0f}", f"{first['grid_B']:.1f}",
                              f"{median_of(k, 'heap_B'):.0f}",
                              f"{median_of(k, 'peak_B'):.0f} ({median_of(k, 'first_step_peak_B'):.0f})",
                              f"{median_of(k, 'heap_growth_B_per_step'):.0f}"]
        cells += [f"{ph[p]:.0f}" for p in ["prepare", "p2g", "grid", "g2p", "other"]]
        print("| " + " | ".join(cells) + " |")
    for name, entry in sorted(sort_steps.items()):
        dim, what = name.split("/")[1].upper(), name.split("/")[2].replace("_", " ")
        print()
        print(f"{dim} {what}, a later sorting step (step 100): heap {entry['heap_B']:.0f} B/particle "
              f"before it, peak {entry['sort_step_peak_B']:.0f} B/particle during it.")
    print()
    print(f"{n_rounds} interleaved rounds (per round and group: the limit kernel, then the engine's "
          "cases). M pst/s: million particle-steps per second (wall clock), median over the rounds; "
          "±: its standard deviation over them. of limit: median over the rounds of the rate over "
          "the limit kernel's rate of the same round, at the same dimension and thread count. "
          "of limit + avg: the same against the limit kernel with the ΔJ-bar volume average (the "
          "least work of the engine's default scheme, no material model). "
          "2T/1T: median over the rounds of the two-thread over the one-thread rate. 1T M pst/CPU-s: "
          "one-thread rate per CPU-second of the benchmark thread (less disturbed by other load than "
          "the wall clock). particle B: per-particle arrays of Particles<Dim>; grid B: grid nodes "
          "(mass, intact mass, velocity); heap B: all heap the simulation holds, per particle (glibc's "
          "bytes in use, mallinfo2); peak B: its peak during the measured steps and during the first "
          "step (which sorts the particles), per particle: the heap held when they start plus what "
          "they make resident beyond what was resident then (VmHWM); heap growth B/step: heap in use after "
          "the measured steps minus before them, per step (0: a step gives back all it takes). "
          "prep … other: ns per particle-step of each phase (wall clock), median over the rounds.")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
