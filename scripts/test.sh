#!/usr/bin/env bash
# Installs, builds (warnings as errors) and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh -DSKYLANE_WERROR=ON -DSKYLANE_BUILD_TESTS=ON
ctest --test-dir build --output-on-failure -j "$(nproc)"
