#!/usr/bin/env bash
# Builds skylane with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan/ (GCC, no
# benchmarks), runs the `unit` and `e2e` tests under them, and replays every fuzz corpus and
# stored reproducer through the fuzz targets (label `fuzz`, fuzz/replay_main.cpp). The Monte
# Carlo proofs run in the plain build only (they are statistics, not memory checks, and take
# many times longer instrumented). Any sanitizer report fails the test that made it.
# Usage: scripts/sanitize.sh   (after scripts/setup.sh has installed the packages)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSKYLANE_SANITIZE=ON -DSKYLANE_WERROR=ON \
  -DSKYLANE_BUILD_TESTS=ON -DSKYLANE_BUILD_BENCH=OFF -DSKYLANE_FUZZ_REPLAY=ON
cmake --build build-asan -j "$(nproc)"
# halt_on_error: a UBSan report is a failure, not a line in a log; leaks are reported at exit.
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$PWD/fuzz/ubsan.supp"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
ctest --test-dir build-asan --output-on-failure -j "$(nproc)" -L 'unit|e2e|fuzz' -E 'Consumer\.'
