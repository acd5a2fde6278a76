#!/usr/bin/env bash
# Checks that a change leaves the bundled example's outputs as they were: builds skylane at a
# base revision (default: HEAD) in a scratch worktree, runs scripts/run_example.sh with both
# binaries on this tree's example data, and compares every output file after dropping the
# wall-clock figures (elapsed and planning times) and applying the renamed keys of
# scripts/renamed_keys.tsv (old → new, for outputs of the base binary). Exit 1 on a difference.
# Usage: scripts/compare_example.sh [BASE_REV]
set -euo pipefail
cd "$(dirname "$0")/.."
BASE="${1:-HEAD}"
WORK="${TMPDIR:-/tmp}/skylane-compare-$$"
mkdir -p "$WORK"
trap 'git worktree remove --force "$WORK/base" >/dev/null 2>&1 || true; rm -rf "$WORK"' EXIT
git worktree add --detach "$WORK/base" "$BASE" >/dev/null
cmake -S "$WORK/base" -B "$WORK/base/build" -DCMAKE_BUILD_TYPE=Release -DSKYLANE_BUILD_TESTS=OFF -DSKYLANE_BUILD_BENCH=OFF >/dev/null
cmake --build "$WORK/base/build" --target skylane -j "$(nproc)" >/dev/null
cmake --build build --target skylane -j "$(nproc)" >/dev/null
echo "compare_example: running the example with $BASE and with this tree" >&2
scripts/run_example.sh "$WORK/base/build/skylane" "$WORK/out_base" >/dev/null 2>&1
scripts/run_example.sh ./build/skylane "$WORK/out_new" >/dev/null 2>&1
python3 scripts/compare_outputs.py "$WORK/out_base" "$WORK/out_new" scripts/renamed_keys.tsv
