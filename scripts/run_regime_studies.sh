#!/usr/bin/env bash
# The regime studies into results/, in the order that makes one run serve both protocols
# (docs/model.md, "Two protocols"). Days of compute on 2 cores (docs/performance.md): run it in the
# background and run it again after any interruption; every step resumes where it stopped and
# skips what is done.
#
#   nohup bash scripts/run_regime_studies.sh > regime.log 2>&1 &
#
# 1. the steady study, which keeps each case's particles at 1.25, 2 and 3 H_i through the gate;
# 2. the initiation study's cases at 400 and 800 m at the Π the two share, and the geometry
#    study's two cases on the same scene, measured from those particles at 2 H_i (the same result
#    hashes as running them);
# 3. the initiation study's other cases, its replicas, and the geometry study's cases that vary
#    one of S and L_s/H_i at a time;
# 4. fits, figures and the field calibration;
# 5. the rest of the geometry study (S and L_s/H_i together), then its fits and figures.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build -j "$(nproc)" --target crevasse
C=./build/cli/crevasse
R=results

$C study studies/regime_steady.json --db $R/regime_steady.db --keep-particles --views $R/regime_steady_views
# As --dry-run lists them: initiation cases 11-13, 15-19 (400 m) and 31-33, 35-39 (800 m), Π =
# 0.05-1 but 0.0375 and 0.125; geometry cases 8, 9 (S = 1/2, L_s = H_i, the same scene).
$C study studies/regime_initiation.json --db $R/regime_initiation.db --cases 11-13,15-19,31-33,35-39 \
  --remeasure $R/regime_steady.db --particles-from $R/regime_steady.db.particles --views $R/regime_initiation_views
$C study studies/regime_initiation_geometry.json --db $R/regime_initiation_geometry.db --cases 8,9 \
  --remeasure $R/regime_steady.db --particles-from $R/regime_steady.db.particles --views $R/regime_initiation_geometry_views
$C study studies/regime_initiation.json --db $R/regime_initiation.db --keep-particles --views $R/regime_initiation_views
$C study studies/regime_initiation_replicas.json --db $R/regime_initiation_replicas.db --keep-particles \
  --views $R/regime_initiation_replicas_views
# S = 0.2, 1 at L_s = H_i and L_s/H_i = 0.5, 2 at S = 1/2, at both Π.
$C study studies/regime_initiation_geometry.json --db $R/regime_initiation_geometry.db --cases 2,3,6,7,10,11,14,15 \
  --keep-particles --views $R/regime_initiation_geometry_views

for s in regime_steady regime_initiation; do
  $C fit $R/$s.db
done
# CDFs of two cases per regime (cases 12, 13: H_i = 400 m, Π = 0.075, 0.1; 6, 16: Π = 0.2 at 200
# and 400 m); the steady study's likewise (cases 1, 2 and 4: Π = 0.075, 0.1, 0.2 at 400 m, and 12: 0.2 at 800 m).
$C plot $R/regime_initiation.db --out $R/regime_initiation_figures --cdf-normalise bending --cdf-cases 12 13 6 16
$C plot $R/regime_steady.db --out $R/regime_steady_figures --cdf-normalise bending --cdf-cases 1 2 4 12
# The field sites against the initiation study's laws, with the literature strengths under the table.
$C calibrate --db $R/regime_initiation.db --observations studies/field/observations.json \
  --csv $R/regime_initiation_figures/field_calibration.csv > $R/regime_initiation_figures/field_calibration.txt
# The rest of the geometry study, S and L_s/H_i varied together; then its fits and figures.
$C study studies/regime_initiation_geometry.json --db $R/regime_initiation_geometry.db --keep-particles \
  --views $R/regime_initiation_geometry_views
$C fit $R/regime_initiation_geometry.db
$C plot $R/regime_initiation_geometry.db --out $R/regime_initiation_geometry_figures --cdf-normalise bending
