#!/usr/bin/env bash
# README's first set-up command: install what is missing, build (Release), and run the main job,
# the quick study, into results/quick.db (resumes if interrupted), then print its status, fit the
# regime laws into its fits table and draw the figures into results/quick_figures.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)"
./build/study/crevasse study studies/quick.json --db results/quick.db
./build/study/crevasse status results/quick.db
./build/study/crevasse fit results/quick.db
./build/study/crevasse plot results/quick.db --out results/quick_figures
