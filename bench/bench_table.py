#!/usr/bin/env python3
"""Prints the benchmark table of issue 6 from the JSON of bench_step and bench_limit.

Usage: bench_table.py STEP.json LIMIT.json [--stages]

Every number is the median over the repetitions (--benchmark_repetitions); the ± column is the
standard deviation of the rate over them, relative. Stages are grouped into phases: prepare
(sort, grid box, P2G colouring), P2G, grid (velocity, gravity, boundary conditions), G2P (gather,
volume averaging, F update and material, and the per-particle effects the update sweep applies:
bed projection, piston, clamp, the time step's reduction) and other (the time step). The limit
kernel's rows give its own phases (its grid clear is in P2G).
--stages prints every stage's ns per particle-step instead of the phase columns.
"""
import json
import sys

PHASES = {
    "prepare": ["prepare_grid"],
    "p2g": ["p2g"],
    "grid": ["grid", "grid_velocity", "grid_velocity_gravity", "basal_friction", "box_walls",
             "lateral_walls", "velocity_boundaries", "settle_damping"],
    "g2p": ["g2p", "g2p_velocity", "volume_averaging", "g2p_elastic", "g2p_return_mapping"],
}


def load(path):
    """{run_name: {aggregate_name: entry}} of a Google Benchmark JSON file."""
    with open(path) as f:
        data = json.load(f)
    runs = {}
    for b in data["benchmarks"]:
        if b["run_name"].startswith("sortstep/"):
            # One repetition only (no aggregates): keep the single run as its "median".
            runs.setdefault(b["run_name"].split("/iterations:")[0], {})["median"] = b
            continue
        if b.get("run_type") != "aggregate":
            continue
        name = b["run_name"].split("/iterations:")[0]
        runs.setdefault(name, {})[b["aggregate_name"]] = b
    return data.get("context", {}), runs


def key_of(name):
    """('2d', 'softening', 1) for step/2d/softening/threads:1, ('2d', 'limit', 1) for limit."""
    parts = name.split("/")
    threads = int(parts[-1].split(":")[1])
    if parts[0] == "limit":
        return parts[1], "limit", threads
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
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    _, step_runs = load(argv[1])
    _, limit_runs = load(argv[2])
    show_stages = "--stages" in argv
    rows = {}
    sort_steps = {}
    for runs in (step_runs, limit_runs):
        for name, aggs in runs.items():
            if name.startswith("sortstep/"):
                sort_steps[name] = aggs["median"]
                continue
            rows[key_of(name)] = aggs
    rate = {k: a["median"]["particle_steps_per_s"] for k, a in rows.items()}
    # One thread: particles per CPU-second of the benchmark thread, which a loaded machine
    # disturbs less than the wall clock (the thread's own stalls still count).
    units = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}
    cpu_rate = {k: a["median"]["particles"] / (a["median"]["cpu_time"] * units[a["median"]["time_unit"]])
                for k, a in rows.items() if k[2] == 1}

    def spread(k):
        a = rows[k]
        if "stddev" not in a or rate[k] == 0:
            return ""
        return f"{100.0 * a['stddev']['particle_steps_per_s'] / rate[k]:.0f}%"

    order = sorted(rows, key=lambda k: (k[0], k[1] != "limit", k[1], k[2]))
    if show_stages:
        # The engine's stages, then the limit kernel's phases (p2g with its grid clear, grid,
        # g2p), each in its own columns.
        stages = sorted({s for k in order for s in rows[k]["median"] if s.startswith("ns_")})
        print("| stage (ns per particle-step) | " +
              " | ".join(f"{d} {m} {t}T" for d, m, t in order) + " |")
        print("|---|" + "---|" * len(order))
        for s in stages:
            cells = []
            for k in order:
                v = rows[k]["median"].get(s)
                cells.append(f"{v:.1f}" if v is not None else "")
            print(f"| {s[3:]} | " + " | ".join(cells) + " |")
        return 0

    header = ["case", "particles", "M pst/s", "±", "of limit", "2T/1T", "1T M pst/CPU-s",
              "of limit (CPU)", "particle B", "grid B",
              "heap B (peak; 1st step)", "allocs/step", "prep", "p2g", "grid", "g2p", "other"]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for k in order:
        dim, material, threads = k
        med = rows[k]["median"]
        limit = rate.get((dim, "limit", threads))
        one = rate.get((dim, material, 1))
        frac = f"{100.0 * rate[k] / limit:.0f}%" if limit else ""
        speedup = f"{rate[k] / one:.2f}×" if threads > 1 and one else ""
        cpu = f"{cpu_rate[k] / 1e6:.2f}" if k in cpu_rate else ""
        cpu_limit = cpu_rate.get((dim, "limit", 1))
        cpu_frac = f"{100.0 * cpu_rate[k] / cpu_limit:.0f}%" if k in cpu_rate and cpu_limit else ""
        if material == "limit":
            cells = [f"{dim.upper()} limit kernel, {threads} thread{'s' if threads > 1 else ''}",
                     f"{med['particles']:.0f}", f"{rate[k] / 1e6:.2f}", spread(k), "100%", speedup, cpu, cpu_frac,
                     f"{med['state_B']:.0f}", "", "", ""] + \
                    [f"{phase_ns(med)[p]:.0f}" if any(x.startswith("ns_") for x in med) else ""
                     for p in ["prepare", "p2g", "grid", "g2p", "other"]]
        else:
            ph = phase_ns(med)
            cells = [f"{dim.upper()} {material}, {threads} thread{'s' if threads > 1 else ''}",
                     f"{med['particles']:.0f}", f"{rate[k] / 1e6:.2f}", spread(k), frac, speedup, cpu, cpu_frac,
                     f"{med['particle_B']:.0f}", f"{med['grid_B']:.1f}",
                     f"{med['heap_B']:.0f} ({med['peak_heap_B']:.0f}; {med.get('first_step_peak_heap_B', float('nan')):.0f})",
                     f"{med['allocs_per_step']:.1f}"] + \
                    [f"{ph[p]:.0f}" for p in ["prepare", "p2g", "grid", "g2p", "other"]]
        print("| " + " | ".join(cells) + " |")
    for name, med in sorted(sort_steps.items()):
        dim, what = name.split("/")[1].upper(), name.split("/")[2].replace("_", " ")
        print()
        print(f"{dim} {what}, a later sorting step (step 100): heap {med['heap_B']:.0f} B/particle "
              f"before it, peak {med['sort_step_peak_heap_B']:.0f} B/particle during it.")
    print()
    print("M pst/s: million particle-steps per second (wall clock), median; ±: its standard "
          "deviation over the repetitions. of limit: fraction of the limit kernel at the same "
          "dimension and thread count. 1T M pst/CPU-s: one-thread rate per CPU-second of the "
          "benchmark thread (less disturbed by other load than the wall clock). particle B: per-particle arrays of Particles<Dim>; grid B: "
          "grid mass and velocity; heap B: all heap the simulation holds, per particle, with its "
          "peak during an ordinary step and during the first step (which sorts the particles). "
          "prep … other: ns per particle-step of each phase (wall clock).")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
