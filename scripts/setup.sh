#!/usr/bin/env bash
# Installs skylane's Debian packages (when missing), configures and builds into build/.
# Usage: scripts/setup.sh [extra cmake args]
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(g++ cmake make ccache pkg-config universal-ctags python3
  libeigen3-dev libgeographiclib-dev libcli11-dev nlohmann-json3-dev libboost-dev
  libcgal-dev libgmp-dev libmpfr-dev libfcl-dev libgdal-dev proj-data
  nats-server libnats-dev libompl-dev libboost-filesystem-dev libboost-serialization-dev libboost-system-dev libode-dev libssl-dev libsqlite3-dev
  libgtest-dev libgmock-dev libbenchmark-dev python3-gps
  chromium)  # headless, for the web map's browser test (tests/web/map_test.mjs)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Node.js and npm (the link tests' independent MAVLink implementation): Debian's packages unless
# the commands are there already (a Node.js that bundles npm conflicts with Debian's npm).
command -v node > /dev/null 2>&1 || missing+=(nodejs)
command -v npm > /dev/null 2>&1 || missing+=(npm)
if [ ${#missing[@]} -gt 0 ]; then
  echo "skylane setup: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build -j "$(nproc)"
