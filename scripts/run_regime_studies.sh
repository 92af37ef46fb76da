#!/usr/bin/env bash
# The regime studies into results/, in the order that makes one run serve both protocols
# (docs/model.md, "Two protocols"). Days of compute on 2 cores (docs/performance.md): run it in the
# background and run it again after any interruption; every step resumes where it stopped and
# skips what is done.
#
#   nohup bash scripts/run_regime_studies.sh > regime.log 2>&1 &
#
# 1. the steady study, which keeps each case's particles at 1.25, 2 and 3 H_i through the gate;
# 2. the initiation study's 800 m cases at the Π the two share, measured from those particles
#    (the same result hashes as running them); its 400 m cases ran as initiation cases;
# 3. the initiation study's other cases, then its replicas and its geometry companion;
# 4. fits and figures of each.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build -j "$(nproc)" --target crevasse
C=./build/cli/crevasse
R=results

$C study studies/regime_steady.json --db $R/regime_steady.db --keep-particles --views $R/regime_steady_views
# Cases 31-33 and 35-39 (as --dry-run lists them): H_i = 800 m at Π = 0.05-1 but 0.125.
$C study studies/regime_initiation.json --db $R/regime_initiation.db --cases 31-33,35-39 \
  --remeasure $R/regime_steady.db --particles-from $R/regime_steady.db.particles --views $R/regime_initiation_views
$C study studies/regime_initiation.json --db $R/regime_initiation.db --keep-particles --views $R/regime_initiation_views
$C study studies/regime_initiation_replicas.json --db $R/regime_initiation_replicas.db --keep-particles \
  --views $R/regime_initiation_replicas_views
$C study studies/regime_initiation_geometry.json --db $R/regime_initiation_geometry.db --keep-particles \
  --views $R/regime_initiation_geometry_views

for s in regime_steady regime_initiation regime_initiation_geometry; do
  $C fit $R/$s.db
done
# CDFs of two cases per regime (cases 12, 13: H_i = 400 m, Π = 0.075, 0.1; 6, 16: Π = 0.2 at 200
# and 400 m); the steady study's likewise (cases 1, 2 and 4: Π = 0.075, 0.1, 0.2 at 400 m, and 12: 0.2 at 800 m).
$C plot $R/regime_initiation.db --out $R/regime_initiation_figures --cdf-normalise bending --cdf-cases 12 13 6 16
$C plot $R/regime_steady.db --out $R/regime_steady_figures --cdf-normalise bending --cdf-cases 1 2 4 12
$C plot $R/regime_initiation_geometry.db --out $R/regime_initiation_geometry_figures --cdf-normalise bending
# The field sites against the initiation study's laws, with the literature strengths under the table.
$C calibrate --db $R/regime_initiation.db --observations studies/field/observations.json \
  --csv $R/regime_initiation_figures/field_calibration.csv > $R/regime_initiation_figures/field_calibration.txt
