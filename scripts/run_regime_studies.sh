#!/usr/bin/env bash
# The regime studies into results/. Days of compute on 2 cores (docs/performance.md): run it in the
# background and run it again after any interruption; every step resumes where it stopped and
# skips what is done.
#
#   nohup bash scripts/run_regime_studies.sh > regime.log 2>&1 &
#
# `bash scripts/run_regime_studies.sh --fits-only` redraws the fits, figures and calibrations from
# what the databases hold, running nothing (after cases were measured by hand, say).
#
# The cheap cases go first, so that the initiation study covers H_i = 200-600 m with its replicas
# and the step's shape before the long steady row at 800 m (about 2 h per case on both cores):
# 1. the replicas, and the geometry study's cases at S = 1/2, L_s = H_i measured from the steady
#    runs' particles at 2 H_i (the cases a run would store, without the field over time:
#    docs/model.md, "Two protocols"), then its cases that vary one of S and L_s/H_i at a time.
#    A measurement from kept particles whose cases are all stored reads nothing, so the steps
#    pass on a clone, which has the databases but not the particle files;
# 2. the initiation study's cases the steady study does not serve (H_i = 200, 600 m, and
#    Π = 0.0375, 0.125 at 800 m); fits, figures and the field calibration;
# 3. the steady study, which keeps each case's particles at 1.25, 2 and 3 H_i through the gate, and
#    the initiation cases measured from those at 2 H_i; fits, figures, calibration again;
# 4. the rest of the geometry study (S and L_s/H_i together), then its fits and figures.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build -j "$(nproc)" --target crevasse
C=./build/cli/crevasse
R=results
# One and two engine threads give the same results bit for bit (docs/performance.md, "Bit identity").
# The 600 m and 800 m initiation cases ran one at a time on both cores, so that a sitting of a few hours
# finished whole cases; what is left runs two cases at once on one thread each, which makes about a
# tenth more particle-steps per second (docs/performance.md, "Open targets"), and each case resumes from
# its own checkpoint after an interruption.
ONE_CASE_AT_A_TIME="--jobs 1 --threads-per-case 2"
TWO_CASES_AT_ONCE="--jobs 2 --threads-per-case 1"

# Arguments: the steady study's cases whose CDFs are drawn (only cases that are done).
fit_and_plot() {
  for s in regime_steady regime_initiation; do
    $C fit $R/$s.db
  done
  # CDFs of two cases per regime (cases 12, 13: H_i = 400 m, Π = 0.075, 0.1; 6, 16: Π = 0.2 at 200
  # and 400 m); the steady study's likewise (cases 1, 2 and 4: Π = 0.075, 0.1, 0.2 at 400 m, and
  # once its 800 m row has run 12: 0.2 at 800 m).
  $C plot $R/regime_initiation.db --out $R/regime_initiation_figures --cdf-normalise bending --cdf-cases 12 13 6 16
  $C plot $R/regime_steady.db --out $R/regime_steady_figures --cdf-normalise bending --cdf-cases "$@"
  # The field sites against the initiation study's laws, with the literature strengths under the table.
  $C calibrate --db $R/regime_initiation.db --observations studies/field/observations.json \
    --csv $R/regime_initiation_figures/field_calibration.csv > $R/regime_initiation_figures/field_calibration.txt
  # The same read in the ice that lay over the ramp (docs/measurement.md, "The ramp's ice"): its laws,
  # figures named ramp_ice_*, the spacing CDFs of the strength regime's rows over c/(rho_i g) (cases
  # 12, 13: Π = 0.075, 0.1 at 400 m; 22, 23: the same at 600 m), and the calibration from them.
  $C fit $R/regime_initiation.db --ramp-ice
  $C plot $R/regime_initiation.db --out $R/regime_initiation_figures --ramp-ice --cdf-normalise strength --cdf-cases 12 13 22 23
  $C calibrate --db $R/regime_initiation.db --observations studies/field/observations.json --ramp-ice \
    --csv $R/regime_initiation_figures/ramp_ice_field_calibration.csv > $R/regime_initiation_figures/ramp_ice_field_calibration.txt
  # The window but its last H_i, where the outflow's free face breaks the floor ice (docs/measurement.md,
  # "Clear of the front"): its laws, figures named clear_of_front_*, and the calibration from them.
  $C fit $R/regime_initiation.db --clear-of-front
  $C plot $R/regime_initiation.db --out $R/regime_initiation_figures --clear-of-front --cdf-normalise bending --cdf-cases 12 13 6 16
  $C calibrate --db $R/regime_initiation.db --observations studies/field/observations.json --clear-of-front \
    --csv $R/regime_initiation_figures/clear_of_front_field_calibration.csv > $R/regime_initiation_figures/clear_of_front_field_calibration.txt
}

if [ "${1:-}" = "--fits-only" ]; then
  fit_and_plot 1 2 4
  exit 0
fi

$C study studies/regime_initiation_replicas.json --db $R/regime_initiation_replicas.db --keep-particles \
  --views $R/regime_initiation_replicas_views
# Geometry cases 8, 9 (S = 1/2, L_s = H_i at Π = 0.1, 0.3) are the steady study's 400 m scene.
$C study studies/regime_initiation_geometry.json --db $R/regime_initiation_geometry.db --cases 8,9 \
  --remeasure $R/regime_steady.db --particles-from $R/regime_steady.db.particles --views $R/regime_initiation_geometry_views
# S = 0.2, 1 at L_s = H_i and L_s/H_i = 0.5, 2 at S = 1/2, at both Π.
$C study studies/regime_initiation_geometry.json --db $R/regime_initiation_geometry.db --cases 2,3,6,7,10,11,14,15 \
  --keep-particles --views $R/regime_initiation_geometry_views
# As --dry-run lists them: 20-29 the 600 m row, 30 and 34 Π = 0.0375, 0.125 at 800 m. Case 30 goes first:
# at 800 m, Π = 0.0375 is c = 0.27 MPa, the cohesion whose row the 400 and 600 m cases share (the
# strength regime's test at a fixed c, results/README.md).
$C study studies/regime_initiation.json --db $R/regime_initiation.db --cases 30 --keep-particles \
  --views $R/regime_initiation_views $ONE_CASE_AT_A_TIME
$C study studies/regime_initiation.json --db $R/regime_initiation.db --cases 0-10,14,20-30,34 --keep-particles \
  --views $R/regime_initiation_views $ONE_CASE_AT_A_TIME
fit_and_plot 1 2 4

# The steady study, two cases at once. Each steady case serves the initiation case of the same Π
# and H_i, measured from its particles kept at 2 H_i through the gate: steady cases 0-7 (400 m)
# serve initiation cases 11-13, 15-19; 8-15 (800 m) serve 31-33, 35-39 (`--dry-run` lists both
# studies). Those whose particles are kept are measured before the steady study runs on, and after.
SERVED=(11 12 13 15 16 17 18 19 31 32 33 35 36 37 38 39)
measure_served() {
  local cases=()
  for i in "${!SERVED[@]}"; do
    if [ -f "$(printf '%s/regime_steady.db.particles/case_%03d_gate_2_particles.bin' $R "$i")" ]; then
      cases+=("${SERVED[$i]}")
    fi
  done
  if [ ${#cases[@]} -eq 0 ]; then return 0; fi
  $C study studies/regime_initiation.json --db $R/regime_initiation.db --cases "$(IFS=,; echo "${cases[*]}")" \
    --remeasure $R/regime_steady.db --particles-from $R/regime_steady.db.particles --views $R/regime_initiation_views
}
measure_served
steady_status=0
$C study studies/regime_steady.json --db $R/regime_steady.db --keep-particles \
  --views $R/regime_steady_views $TWO_CASES_AT_ONCE || steady_status=$?
measure_served
[ "$steady_status" -eq 0 ] || exit "$steady_status"
fit_and_plot 1 2 4 12

# The rest of the geometry study, S and L_s/H_i together; then its fits and figures.
$C study studies/regime_initiation_geometry.json --db $R/regime_initiation_geometry.db --keep-particles \
  --views $R/regime_initiation_geometry_views $TWO_CASES_AT_ONCE
$C fit $R/regime_initiation_geometry.db
$C plot $R/regime_initiation_geometry.db --out $R/regime_initiation_geometry_figures --cdf-normalise bending
