#!/usr/bin/env bash
# The test suite under sanitizers, from the presets in CMakePresets.json:
#   asan: AddressSanitizer + UndefinedBehaviorSanitizer (any UB aborts), build-asan,
#         then `ctest -LE slow` (every fast test, engine, analysis, study and cli);
#   tsan: ThreadSanitizer, build-tsan, then the concurrent runner and CLI tests (labels study
#         and cli);
#   asan-ci, tsan-ci: CI's subsets (.ci/run; docs/reliability.md, "Sanitizers"), built in the
#         same folders with only the programs they run.
# A report makes the test fail; the ctest logs are in build-<preset>/Testing/Temporary/.
#
#   bash scripts/sanitize.sh            # asan and tsan
#   bash scripts/sanitize.sh asan       # one of them
#   SANITIZE_JOBS=1                     # parallel compile and test jobs (default 1)
set -uo pipefail
cd "$(dirname "$0")/.."
presets=${*:-"asan tsan"}
jobs=${SANITIZE_JOBS:-1}
status=0
for p in $presets; do
  config=${p%-ci}
  case $p in
    asan) targets=() ;;  # everything
    asan-ci) targets=(--target crevasse test_analysis test_study test_cli) ;;
    tsan | tsan-ci) targets=(--target crevasse test_study test_cli) ;;
    *) echo "sanitize.sh: unknown preset $p (asan, tsan, asan-ci, tsan-ci)"; exit 2 ;;
  esac
  echo "== $p: configure and build (build-$config, -j$jobs)"
  start=$(date +%s)
  cmake --preset "$config" > /dev/null || exit 1
  cmake --build "build-$config" -j "$jobs" "${targets[@]}" || exit 1
  echo "== $p: built in $(( $(date +%s) - start ))s; ctest"
  start=$(date +%s)
  # gtest_discover_tests lists the tests of every program at build time; with only some
  # programs built ctest skips the others' placeholders, hence the presets' label filters.
  if ctest --preset "$p" -j "$jobs"; then
    echo "== $p: passed in $(( $(date +%s) - start ))s"
  else
    echo "== $p: FAILED (see build-$config/Testing/Temporary/LastTest.log)"
    status=1
  fi
done
exit $status
