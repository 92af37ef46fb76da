#!/usr/bin/env bash
# README's second set-up command: install what is missing, build (Release), run the test suite.
# Long physics runs carry the ctest label "slow" and are excluded here; run them with
#   ctest --test-dir build -L slow
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)"
ctest --test-dir build -LE slow --output-on-failure -j "$(nproc)" --timeout 900
