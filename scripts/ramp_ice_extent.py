#!/usr/bin/env python3
"""Where the ice that lay over the ramp at the start ends up: how far past the draped window's
start it reaches in a case's kept final particles.

    python3 scripts/ramp_ice_extent.py results/regime_initiation.db --cases 20-25 \
        [--particles results/regime_initiation.db.particles] [--crevasse build/cli/crevasse]

The draped ice is seeded between the bed and z_b + H_i, so the ice over the ramp holds H_i * L_s of
area (2D, per unit width). Ice does not overtake ice, so, counted from the draped window's start
(the most downstream ice that came over the lip), the final particles' volumes reach H_i * L_s where
the ramp's ice ends. Opening adds volume (the damaged share, a few per cent in weak ice), which
makes the extent read a little short. This is what `fixed_cohesion_table.py --lead` should match.
Each case's particles are written to a temporary VTU by `crevasse measure --vtu`.
"""
import argparse
import os
import sqlite3
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from over_time_table import case_list  # noqa: E402  (the --cases grammar)
from stress_by_depth import read_vtu  # noqa: E402


def extent(vtu_path, window_start, area):
    """Distance past window_start where the cumulative particle volume reaches area, and half of it."""
    _, _, arrays = read_vtu(vtu_path)
    column = sorted((p[0], v) for p, v in zip(arrays['points'], arrays['volume']) if p[0] >= window_start)
    total, half, whole = 0.0, None, None
    for x, v in column:
        total += v
        if half is None and total >= 0.5 * area:
            half = x - window_start
        if total >= area:
            whole = x - window_start
            break
    return half, whole


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('database')
    parser.add_argument('--cases', required=True, help='case indexes, e.g. 20-25,30')
    parser.add_argument('--particles', help='kept particle folder (default: DATABASE.particles)')
    parser.add_argument('--crevasse', default='build/cli/crevasse', help='the crevasse command')
    a = parser.parse_args()
    folder = a.particles or a.database + '.particles'
    con = sqlite3.connect(f"file:{a.database}?mode=ro", uri=True)
    print('| case | H_i [m] | Π | L_s [m] | ramp ice ends past the window start | half of it |')
    print('|---|---|---|---|---|---|')
    with tempfile.TemporaryDirectory() as tmp:
        for index in sorted(case_list(a.cases)):
            row = con.execute(
                """select c.thickness_m, c.cohesion_ratio, s.window_min_x_m,
                          json_extract(c.scene_json, '$.bed.step_length')
                   from cases c join summaries s using (case_id)
                   where c.case_index = ? and c.status = 'done'""", (index,)).fetchone()
            particles = os.path.join(folder, f'case_{index:03d}_particles.bin')
            if row is None or not os.path.exists(particles):
                print(f'| {index} | not done, or no kept particles at {particles} | | | | |')
                continue
            h, pi, start, step_length = row
            vtu = os.path.join(tmp, f'case_{index}.vtu')
            subprocess.run([a.crevasse, 'measure', particles, '--vtu', vtu], check=True,
                           stdout=subprocess.DEVNULL)
            half, whole = extent(vtu, start, h * step_length)
            ends = '–' if whole is None else f'{whole:.0f} m ({whole / h:.2f} H_i)'
            mid = '–' if half is None else f'{half / h:.2f} H_i'
            print(f'| {index} | {h:.0f} | {pi:g} | {step_length:.0f} | {ends} | {mid} |')
    con.close()


if __name__ == '__main__':
    main()
