#!/usr/bin/env python3
"""Where ice opens and where it yields: the stress state of a run's VTU snapshots by column and by
depth below the local surface (docs/model.md, "Softening with a length").

    crevasse run SCENE.json --out DIR --vtu-interval 30
    python3 scripts/stress_by_depth.py DIR --c PA --qy PA --H M [--x0 M --x1 M --width M]

For each snapshot and each cell (a column `width` wide, a tenth of H deep) it prints the 95th
percentile, over the intact particles (eps_v_p = 0), of the mean tension over the cap, -p/c (1 =
at the cap), and of the deviator over the shear strength, q/q_y (1 = yielding), and the share of
particles that have opened (eps_v_p > 0), in per cent. Reads the engine's VTU (raw appended
Float64 arrays with a UInt64 size header) with the standard library only.
"""
import argparse, glob, os, re, struct
from collections import defaultdict


def read_vtu(path):
    data = open(path, 'rb').read()
    tag = b'<AppendedData encoding="raw">'
    head_end = data.index(tag) + len(tag)
    head = data[:head_end].decode('latin1')
    base = data.index(b'_', head_end) + 1
    n = int(re.search(r'NumberOfPoints="(\d+)"', head).group(1))
    t = float(re.search(r'Name="TimeValue"[^>]*>([^<]+)<', head).group(1))
    arrays = {}
    for m in re.finditer(r'<DataArray type="Float64"(?: Name="(\w+)")? NumberOfComponents="(\d+)" '
                         r'format="appended" offset="(\d+)"', head):
        name, comp, off = m.group(1) or 'points', int(m.group(2)), int(m.group(3))
        nbytes = struct.unpack_from('<Q', data, base + off)[0]
        vals = struct.unpack_from('<%dd' % (nbytes // 8), data, base + off + 8)
        arrays[name] = vals if comp == 1 else [vals[i * comp:(i + 1) * comp] for i in range(n)]
    return t, n, arrays


def p95(v):
    return sorted(v)[int(0.95 * (len(v) - 1))] if v else float('nan')


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('dir', help='output folder of crevasse run (its snapshots/*.vtu)')
    ap.add_argument('--c', type=float, required=True, help='tensile strength c [Pa]')
    ap.add_argument('--qy', type=float, required=True, help='shear strength q_y [Pa]')
    ap.add_argument('--H', type=float, required=True, help='ice thickness H_i [m]')
    ap.add_argument('--x0', type=float, default=0.0)
    ap.add_argument('--x1', type=float, default=None)
    ap.add_argument('--width', type=float, default=200.0, help='column width [m]')
    ap.add_argument('--surface-bin', type=float, default=10.0, help='column width for the local surface [m]')
    a = ap.parse_args()
    paths = sorted(glob.glob(os.path.join(a.dir, 'snapshots', '*.vtu')))
    if not paths:
        raise SystemExit(f"stress_by_depth: no snapshots/*.vtu in {a.dir} (run with --vtu-interval)")
    for path in paths:
        t, n, A = read_vtu(path)
        P = A['points']
        x1 = a.x1 if a.x1 is not None else max(p[0] for p in P)
        top = defaultdict(lambda: -1e300)
        for p in P:
            k = int(p[0] // a.surface_bin)
            top[k] = max(top[k], p[2])
        cells = defaultdict(lambda: [0, 0, [], []])  # particles, opened, -p/c and q/q_y of intact
        for i, p in enumerate(P):
            if not a.x0 <= p[0] < x1:
                continue
            depth = top[int(p[0] // a.surface_bin)] - p[2]
            cell = cells[(int((p[0] - a.x0) // a.width), min(9, max(0, int(depth / (0.1 * a.H)))))]
            cell[0] += 1
            if A['eps_v_p'][i] > 0.0:
                cell[1] += 1
            else:
                cell[2].append(-A['pressure'][i] / a.c)
                cell[3].append(A['von_mises'][i] / a.qy)
        ncol = int(-(-(x1 - a.x0) // a.width))
        print(f"t = {t:.0f} s. Per cell: -p/c and q/q_y (95th percentile over intact particles), "
              "opened %")
        print('depth/H  ' + ''.join(f"{a.x0 + k * a.width:>7.0f}-{a.x0 + (k + 1) * a.width:<9.0f}" for k in range(ncol)))
        for row in range(10):
            line = f"{row / 10:.1f}-{(row + 1) / 10:.1f}  "
            for col in range(ncol):
                count, opened, tp, tq = cells[(col, row)]
                line += f"{p95(tp):5.2f} {p95(tq):4.2f} {100 * opened / count:3.0f}  " if count else ' ' * 17
            print(line)
        print()


if __name__ == '__main__':
    main()
