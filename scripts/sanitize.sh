#!/usr/bin/env bash
# The test suite under sanitizers, from the presets in CMakePresets.json:
#   asan: AddressSanitizer + UndefinedBehaviorSanitizer (any UB aborts), build-asan,
#         then `ctest -LE slow` (every fast test, engine, analysis and study);
#   tsan: ThreadSanitizer, build-tsan, then the concurrent runner and CLI tests (label study).
# A report makes the test fail; the ctest logs are in build-<preset>/Testing/Temporary/.
#
#   bash scripts/sanitize.sh            # both
#   bash scripts/sanitize.sh asan       # one of them
#   SANITIZE_JOBS=1                     # parallel compile and test jobs (default 1)
set -uo pipefail
cd "$(dirname "$0")/.."
presets=${*:-"asan tsan"}
jobs=${SANITIZE_JOBS:-1}
status=0
for p in $presets; do
  echo "== $p: configure and build (build-$p, -j$jobs)"
  cmake --preset "$p" > /dev/null || exit 1
  if [ "$p" = tsan ]; then
    cmake --build "build-$p" -j "$jobs" --target crevasse test_study || exit 1
  else
    cmake --build "build-$p" -j "$jobs" || exit 1
  fi
  echo "== $p: ctest"
  start=$(date +%s)
  # gtest_discover_tests lists the tests of every program at build time; with only some
  # programs built (tsan) ctest skips the others' placeholders, hence the label filter.
  if ctest --preset "$p" -j "$jobs"; then
    echo "== $p: passed in $(( $(date +%s) - start ))s"
  else
    echo "== $p: FAILED (see build-$p/Testing/Temporary/LastTest.log)"
    status=1
  fi
done
exit $status
