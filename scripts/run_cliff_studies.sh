#!/usr/bin/env bash
# Regenerates the calving-front (cliff scene) studies of studies/cliff/ into results/cliff/
# (results/README.md says what each file is): runs each study into results/cliff/<name>.db
# (resumable: run it again after an interruption and finished cases are skipped), fits its
# laws into the database's fits table, draws its figures into results/cliff/<name>_figures/
# and, for the main study, runs the field calibration.
#
#   bash scripts/run_cliff_studies.sh                 # every study, in the order below
#   bash scripts/run_cliff_studies.sh slope three_d   # only these
#
# Measured cost on the 2-core development VM, in case wall time (docs/study_format.md,
# "Shipped studies"): spacing_vs_cohesion about 10 min, spacing_replicas 9 min,
# spacing_resolution 23 min, slope 5 min, step_length 6 min, three_d 31 min (3 cases),
# two_d_long 3 min, three_d_long 38 min (2 cases, 19 min each side by side),
# drive_speed_long 29 min, drive_speed_replicas 23 min, accuracy_drive 6 min and
# accuracy_cost 28 min (these two one case at a time, so that each case's wall time and peak
# memory are its own); all but spacing_vs_cohesion measured on an engine about half as fast.
set -euo pipefail
cd "$(dirname "$0")/.."
crevasse=./build/cli/crevasse
if [[ ! -x $crevasse ]]; then
  bash scripts/install_deps.sh
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
  cmake --build build -j "$(nproc)"
fi

studies=("$@")
if [[ ${#studies[@]} -eq 0 ]]; then
  studies=(spacing_vs_cohesion spacing_replicas spacing_resolution slope step_length three_d
           two_d_long three_d_long drive_speed_long drive_speed_replicas accuracy_drive
           accuracy_cost)
fi

for name in "${studies[@]}"; do
  db=results/cliff/$name.db
  $crevasse study "studies/cliff/$name.json" --db "$db"
  $crevasse status "$db"
  case $name in
    spacing_vs_cohesion)
      # Fragmented cases (the slab shatters into cells' worth of rubble) have no spacing and
      # their "depth" is that of rubble: left out of the laws, still marked on the figures.
      $crevasse fit "$db" --group cohesion_ratio thickness --exclude-fragmented
      # CDFs: the two Π = 0.2 cases at 100 and 800 m (5 and 6 crevasses) and two above Π*.
      $crevasse plot "$db" --out "results/cliff/${name}_figures" --colour-by thickness \
        --cdf-normalise thickness --cdf-cases 4,40,33,17
      $crevasse calibrate --db "$db" --observations studies/field/observations.json \
        --csv "results/cliff/${name}_figures/field_calibration.csv" \
        | tee "results/cliff/${name}_figures/field_calibration.txt"
      ;;
    slope)
      $crevasse fit "$db" --group slope --exclude-fragmented
      $crevasse plot "$db" --out "results/cliff/${name}_figures" --group slope --colour-by cohesion_ratio
      ;;
    step_length)
      $crevasse fit "$db" --group step_length_ratio --exclude-fragmented
      $crevasse plot "$db" --out "results/cliff/${name}_figures" --group step_length_ratio \
        --colour-by cohesion_ratio
      ;;
    spacing_replicas | spacing_resolution)
      # Compared case by case with spacing_vs_cohesion (results/README.md); the main study's
      # diagram with these cases added:
      $crevasse plot results/cliff/spacing_vs_cohesion.db --out "results/cliff/${name}_figures" \
        --colour-by thickness --add-cases "$db"
      ;;
    three_d)
      # The 3D cases on the diagram of the 2D study at the same groups (quick).
      $crevasse plot results/cliff/cliff_quick.db --out "results/cliff/${name}_figures" --add-cases "$db"
      ;;
    three_d_long)
      # The long-window 3D cases on the diagram of their 2D counterpart (run two_d_long first).
      $crevasse plot results/cliff/two_d_long.db --out "results/cliff/${name}_figures" --add-cases "$db"
      ;;
    two_d_long | drive_speed_long | drive_speed_replicas | accuracy_drive)
      # drive_speed_*: tables by scripts/drive_speed_table.py (results/README.md, "Drive speed");
      # accuracy_drive: its rows join accuracy_cost's table.
      ;;
    accuracy_cost)
      added=()
      [[ -f results/cliff/accuracy_drive.db ]] && added=(--add-cases results/cliff/accuracy_drive.db)
      $crevasse accuracy "$db" --out "results/cliff/${name}" "${added[@]}"
      ;;
  esac
done
