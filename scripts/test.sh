#!/usr/bin/env bash
# Installs, builds (warnings as errors) and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh -DSKYLANE_WERROR=ON -DSKYLANE_BUILD_TESTS=ON
# The independent implementations the link tests check against (node-mavlink), from the lockfile.
npm ci --prefix tests/link/js --no-audit --no-fund --loglevel=error
ctest --test-dir build --output-on-failure -j "$(nproc)"
