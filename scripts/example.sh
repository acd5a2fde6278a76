#!/usr/bin/env bash
# Installs, builds and runs the main job on the bundled example (scripts/run_example.sh);
# results go to examples/out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/run_example.sh ./build/skylane examples/out
