#!/usr/bin/env bash
# Builds skylane with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan/ (GCC, no
# benchmarks), runs the `unit` and `e2e` tests under them, and replays every fuzz corpus and
# stored reproducer through the fuzz targets (label `fuzz`, fuzz/replay_main.cpp). The Monte
# Carlo proofs run in the plain build only (they are statistics, not memory checks, and take
# many times longer instrumented). Any sanitizer report fails the test that made it.
# Usage: scripts/sanitize.sh   (after scripts/setup.sh has installed the packages)
# -O1 without -g: sanitizer reports keep function names, and ccache can reuse the objects of a
# checkout in another folder (with -g it hashes the build folder). Hidden visibility: at -O1 the
# executables emit Eigen template instances that OMPL's shared library would otherwise bind to
# (ELF interposition), so OMPL freed with its own Eigen code memory our copy had allocated — ASan
# reported a bad free in every planning test.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" -DSKYLANE_SANITIZE=ON -DSKYLANE_WERROR=ON \
  -DCMAKE_CXX_VISIBILITY_PRESET=hidden -DCMAKE_VISIBILITY_INLINES_HIDDEN=ON \
  -DSKYLANE_BUILD_TESTS=ON -DSKYLANE_BUILD_BENCH=OFF -DSKYLANE_FUZZ_REPLAY=ON
cmake --build build-asan -j "$(nproc)"
# halt_on_error: a UBSan report is a failure, not a line in a log; leaks are reported at exit.
# One suppression, the same file the fuzzers use (fuzz/ubsan.supp), for the tests too: CGAL's
# In_place_list (the face list of CGAL::Arrangement_2, walked by zone validation and repair)
# static-downcasts its sentinel node, which is not an Arr_face, so -fsanitize=vptr reports
# "downcast of address ... which does not point to an object of type Arr_face" on every face
# walk. It is CGAL's code, the sentinel is never dereferenced as a face, and the pattern is
# matched on that type only (vptr_check:*Arr_face*): any other report still fails the run.
# UBSan is built recoverable here (the default of -fsanitize=undefined), which suppressions need.
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$PWD/fuzz/ubsan.supp"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
# Left out here: the consumer project (it builds against an install, not a memory check). The
# kill-and-resume tests run: they kill the tracker once its database holds some hundreds of fixes
# (26 s and 21 s instrumented on the 2-core VM).
ctest --test-dir build-asan --output-on-failure -j "$(nproc)" -L 'unit|e2e|service|fuzz' -E 'Consumer\.'
