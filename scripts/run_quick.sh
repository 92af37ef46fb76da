#!/usr/bin/env bash
# README's first set-up command: install what is missing, build (Release), and run the main job,
# the quick study, into runs/quick.db (git does not track runs/; the run resumes if interrupted),
# then print its status, fit the regime laws into its fits table and draw the figures into
# runs/quick_figures. The reference results the README quotes are in results/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)" --target crevasse  # the tests are built by scripts/test.sh
mkdir -p runs
./build/cli/crevasse study studies/quick.json --db runs/quick.db --views runs/quick_figures/cases
./build/cli/crevasse status runs/quick.db
./build/cli/crevasse fit runs/quick.db
./build/cli/crevasse plot runs/quick.db --out runs/quick_figures
