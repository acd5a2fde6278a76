#include "fuzz/fuzz_common.hpp"

#include <cstdio>
#include <cstdlib>

// The libraries are built with -fsanitize=undefined, whose reports are recoverable by default:
// UBSan would print and carry on, and libFuzzer would never keep the input. Halting turns every
// report into a crash. Known reports inside third-party code are suppressed by fuzz/ubsan.supp
// (each line says why). (UBSAN_OPTIONS in the environment still overrides single flags.)
extern "C" const char* __ubsan_default_options() {
  return "halt_on_error=1:print_stacktrace=1:suppressions=" SKYLANE_UBSAN_SUPPRESSIONS;
}

namespace skylane::fuzz {
namespace {

volatile double keep_alive_sink = 0.0;

}  // namespace

void fail(const std::string& check, const std::string& detail) {
  std::fprintf(stderr, "\nskylane fuzz: %s: %s\n", check.c_str(), detail.c_str());
  std::fflush(stderr);
  std::abort();
}

void keepAlive(double value) { keep_alive_sink = value; }

void checkParseError(const integrity::ParseError& e, const std::string& source) {
  const std::string what = e.what();
  SKYLANE_FUZZ_CHECK(e.source() == source, "ParseError names source '" + e.source() + "': " + what);
  SKYLANE_FUZZ_CHECK(what.rfind(source, 0) == 0, "message does not start with the source: " + what);
}

}  // namespace skylane::fuzz
