#!/usr/bin/env bash
# Installs the Debian 12 packages crevasse needs, only those missing. Idempotent.
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  libeigen3-dev        # dense small matrices in the engine
  libgsl-dev           # least-squares fits and distributions in analysis/
  nlohmann-json3-dev   # scene and study files
  libsqlite3-dev sqlite3  # study database, and the sqlite3 CLI for users
  libgtest-dev         # unit and physics tests
  libtbb-dev           # concurrent cases and parallel engine loops
  libcairo2-dev        # PNG/SVG figures (side views, regime diagrams)
  libcli11-dev         # command-line parsing of the crevasse CLI
  libbenchmark-dev     # bench/
  zlib1g-dev           # compressed final-particle files (crevasse measure)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
