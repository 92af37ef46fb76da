#!/usr/bin/env bash
# Builds the benchmarks (Release, in build-bench) and prints the benchmark table: the engine's
# full step against the limit kernel, 2D/3D, elastic/softening, 1 and 2 threads, each number
# the median of BENCH_REPETITIONS (5) interleaved rounds (bench/bench_table.py). Takes ~2 minutes
# on 2 cores after the build. Timings on a shared machine are noisy: the load average before and
# after is printed with the table.
#   BENCH_FILTER=regex   run only the groups it matches: 2d/threads:1, 2d/threads:2, 3d/threads:1,
#                        3d/threads:2 (e.g. 2d, or threads:1) and sortstep
#   BENCH_JOBS=N         build jobs (1)
#   BENCH_BUILD_DIR=DIR  build directory (build-bench), e.g. to keep a separate tree per session
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BENCH_BUILD_DIR:-build-bench}
reps=${BENCH_REPETITIONS:-5}
filter=${BENCH_FILTER:-.}
command -v python3 >/dev/null || { echo "bench.sh: python3 is needed to print the table" >&2; exit 1; }

log="$build/bench.log"
mkdir -p "$build"
{
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release
  cmake --build "$build" -j "${BENCH_JOBS:-1}" --target bench_step bench_limit
} >"$log" 2>&1 || { cat "$log" >&2; echo "bench.sh: build failed" >&2; exit 1; }

load_before=$(cut -d' ' -f1-3 /proc/loadavg)
# Interleaved rounds: per round and group (dimension, thread count), the limit kernel (alone and
# with the ΔJ-bar average) and then the engine's cases, one repetition each, so that a drift of the machine's speed divides out of
# the fraction of the limit (bench_table.py takes each round's ratio).
out="$build/bench-rounds"
rm -rf "$out"
mkdir -p "$out"
run() {  # program filter output
  "$build/bench/$1" --benchmark_filter="$2" --benchmark_out="$out/$3" \
    --benchmark_out_format=json >>"$log" 2>&1 || { tail -20 "$log" >&2; exit 1; }
}
for r in $(seq "$reps"); do
  for dim in 2d 3d; do
    for t in 1 2; do
      [[ "$dim/threads:$t" =~ $filter ]] || continue
      run bench_limit "^limit(_averaging)?/$dim/threads:$t/" "limit_${r}_${dim}_$t.json"
      run bench_step "^step/$dim/[a-z]+/threads:$t/" "step_${r}_${dim}_$t.json"
    done
  done
done
if [ "$filter" = . ] || [[ sortstep =~ $filter ]]; then
  run bench_step "^sortstep/" sortstep.json
fi
load_after=$(cut -d' ' -f1-3 /proc/loadavg)

native=$(sed -n 's/^CREVASSE_NATIVE:BOOL=//p' "$build/CMakeCache.txt")
[ "$native" = ON ] && arch="-march=native" || arch="no -march=native"
model=$(lscpu | sed -n 's/^Model name: *//p' | head -1)
echo "Machine: ${model:-unknown CPU}, $(nproc) cores; $(c++ --version | head -1);" \
  "Release -O3 ($arch); $reps interleaved rounds;" \
  "load average before ${load_before}, after ${load_after}"
echo
python3 bench/bench_table.py "$out"
