#!/usr/bin/env bash
# Fuzzes the two JSON loaders (scene_from_json, parse_study) with libFuzzer + ASan + UBSan for a
# bounded time each, seeded from studies/ and the bad-input corpus tests/inputs/bad_scenes/.
# Builds in build-fuzz (clang, not part of the default build). Any exception other than
# InputError, crash, leak, UB or hang is a finding: its input is saved under
# build-fuzz/run/artifacts_<target>/ and the script exits 1.
#
#   FUZZ_SECONDS=300 bash scripts/fuzz.sh          # seconds per target (default 300)
#   FUZZ_TARGETS="scene" bash scripts/fuzz.sh      # one target only
#   FUZZ_BUILD_JOBS=1                              # parallel compile jobs (default 1)
set -uo pipefail
cd "$(dirname "$0")/.."
seconds=${FUZZ_SECONDS:-300}
targets=${FUZZ_TARGETS:-"scene study"}
jobs=${FUZZ_BUILD_JOBS:-1}

cmake --preset fuzz > build-fuzz.configure.log 2>&1 || { cat build-fuzz.configure.log; exit 1; }
rm -f build-fuzz.configure.log
cmake --build build-fuzz -j "$jobs" --target fuzz_scene fuzz_study || exit 1

run=build-fuzz/run
status=0
total=0
for t in $targets; do
  corpus=$run/corpus_$t
  seeds=$run/seeds_$t
  artifacts=$run/artifacts_$t
  mkdir -p "$corpus" "$seeds" "$artifacts"
  cp studies/scenes/*.json tests/inputs/bad_scenes/* "$seeds"/
  if [ "$t" = study ]; then cp studies/*.json "$seeds"/; fi
  log=$run/fuzz_$t.log
  echo "fuzz_$t: ${seconds}s, corpus $corpus, log $log"
  start=$(date +%s)
  # -timeout: a loader taking 30 s on one input is a hang (the largest valid study, 100000
  # cases, loads in a few seconds). -rss_limit_mb: no input may make a loader allocate 2 GB.
  ./build-fuzz/fuzz/fuzz_$t "$corpus" "$seeds" -dict=fuzz/json.dict -max_total_time="$seconds" \
    -timeout=30 -rss_limit_mb=2048 -max_len=16384 -print_final_stats=1 \
    -artifact_prefix="$artifacts/" > "$log" 2>&1
  rc=$?
  elapsed=$(( $(date +%s) - start ))
  total=$(( total + elapsed ))
  grep -E '^stat::number_of_executed_units|^stat::peak_rss_mb' "$log" | sed "s/^/  fuzz_$t /"
  if [ $rc -ne 0 ]; then
    status=1
    echo "  fuzz_$t: FINDING (exit $rc), input(s) in $artifacts:"
    grep -E 'ERROR:|SUMMARY:|terminate called|what\(\)' "$log" | head -5 | sed 's/^/    /'
    ls "$artifacts" | sed 's/^/    /'
  else
    echo "  fuzz_$t: no finding in ${elapsed}s"
  fi
done
echo "fuzzing: ${total}s in total"
exit $status
