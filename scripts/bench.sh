#!/usr/bin/env bash
# Builds the benchmarks (Release, in build-bench) and prints the table of issue 6: the engine's
# full step against the limit kernel, 2D/3D, elastic/softening, 1 and 2 threads, each number
# the median of BENCH_REPETITIONS (5) repetitions. Takes ~3 minutes on 2 cores. Timings on a
# shared machine are noisy: the load average before and after is printed with the table.
#   BENCH_FILTER=regex   run only the matching cases (Google Benchmark --benchmark_filter)
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
for prog in bench_limit bench_step; do
  "$build/bench/$prog" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
    --benchmark_filter="$filter" --benchmark_out="$build/$prog.json" \
    --benchmark_out_format=json >>"$log" 2>&1 || { tail -20 "$log" >&2; exit 1; }
done
load_after=$(cut -d' ' -f1-3 /proc/loadavg)

native=$(sed -n 's/^CREVASSE_NATIVE:BOOL=//p' "$build/CMakeCache.txt")
[ "$native" = ON ] && arch="-march=native" || arch="no -march=native"
model=$(lscpu | sed -n 's/^Model name: *//p' | head -1)
echo "Machine: ${model:-unknown CPU}, $(nproc) cores; $(c++ --version | head -1);" \
  "Release -O3 ($arch); median of $reps repetitions;" \
  "load average before ${load_before}, after ${load_after}"
echo
python3 bench/bench_table.py "$build/bench_step.json" "$build/bench_limit.json"
