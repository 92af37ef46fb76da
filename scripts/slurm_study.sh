#!/usr/bin/env bash
# Runs a study as a SLURM job array, one shard per array task, then merges the shards.
#
#   scripts/slurm_study.sh studies/numerics/flowing_domain.json 9         # 9 shards
#   SLURM_CPUS=4 SLURM_TIME=2-00:00:00 scripts/slurm_study.sh STUDY N [extra sbatch options]
#
# Each task runs `crevasse study STUDY --shard I/N --db results/<name>.shard-I-of-N.db` with as
# many concurrent cases as it has CPUs (one engine thread each). A task that is killed (time
# limit, preemption, node failure) is resumed by resubmitting the same array index: finished
# cases are kept and not rerun (`sbatch --array=I ...` or `scontrol requeue`). When every task
# has ended, a dependent job merges the shards into results/<name>.db and prints its status.
# Run from the repository root on a node that shares the file system with the compute nodes;
# the databases must be on a local or POSIX-locking file system (SQLite WAL, flock).
set -euo pipefail

if [[ $# -lt 2 ]]; then
  echo "usage: $0 STUDY.json SHARDS [sbatch options...]" >&2
  exit 2
fi
study=$1
shards=$2
shift 2
crevasse=${CREVASSE:-build/cli/crevasse}
cpus=${SLURM_CPUS:-2}
time_limit=${SLURM_TIME:-1-00:00:00}
[[ -x $crevasse ]] || { echo "$0: $crevasse not found; build first (scripts/test.sh) or set CREVASSE" >&2; exit 2; }
[[ $shards =~ ^[1-9][0-9]*$ ]] || { echo "$0: SHARDS must be a positive integer, got '$shards'" >&2; exit 2; }

# Refuse a bad study now rather than in every array task; also gives the study name.
"$crevasse" study "$study" --dry-run > /dev/null
name=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["name"])' "$study")
mkdir -p results/slurm

array_id=$(sbatch --parsable --job-name="crevasse-$name" --array="0-$((shards - 1))" \
  --cpus-per-task="$cpus" --time="$time_limit" --output="results/slurm/$name-%A_%a.log" "$@" \
  --wrap="$crevasse study '$study' --shard \${SLURM_ARRAY_TASK_ID}/$shards --jobs $cpus --threads-per-case 1 \
          --db results/$name.shard-\${SLURM_ARRAY_TASK_ID}-of-$shards.db")

inputs=""
for ((i = 0; i < shards; i++)); do inputs+=" results/$name.shard-$i-of-$shards.db"; done
merge_id=$(sbatch --parsable --job-name="crevasse-$name-merge" --dependency="afterany:$array_id" \
  --time=01:00:00 --output="results/slurm/$name-merge-%j.log" \
  --wrap="$crevasse merge results/$name.db$inputs; $crevasse status results/$name.db")

echo "submitted array $array_id ($shards shards of $name) and merge job $merge_id"
echo "progress: for f in results/$name.shard-*-of-$shards.db; do $crevasse status \$f | head -4; done"
