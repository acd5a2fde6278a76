#include "fuzz/fuzz_common.hpp"

#include <cxxabi.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <typeinfo>

// The libraries are built with -fsanitize=undefined, whose reports are recoverable by default:
// UBSan would print and carry on, and libFuzzer would never keep the input. Halting turns every
// report into a crash. (UBSAN_OPTIONS in the environment still overrides these defaults.)
extern "C" const char* __ubsan_default_options() { return "halt_on_error=1:print_stacktrace=1"; }

namespace skylane::fuzz {

void fail(const std::string& check, const std::string& detail) {
  std::fprintf(stderr, "\nskylane fuzz: %s: %s\n", check.c_str(), detail.c_str());
  std::fflush(stderr);
  std::abort();
}

namespace {
volatile double keep_alive_sink = 0.0;
}  // namespace

void keepAlive(double value) { keep_alive_sink = value; }

std::string typeName(const std::exception& e) {
  const char* mangled = typeid(e).name();
  int status = 0;
  const std::unique_ptr<char, void (*)(void*)> demangled(
      abi::__cxa_demangle(mangled, nullptr, nullptr, &status), std::free);
  return status == 0 && demangled ? std::string(demangled.get()) : std::string(mangled);
}

void checkParseError(const integrity::ParseError& e, const std::string& source) {
  const std::string what = e.what();
  SKYLANE_FUZZ_CHECK(!what.empty(), "ParseError without a message");
  SKYLANE_FUZZ_CHECK(e.source() == source, "ParseError names source '" + e.source() + "': " + what);
  SKYLANE_FUZZ_CHECK(what.rfind(source, 0) == 0, "message does not start with the source: " + what);
}

}  // namespace skylane::fuzz
