#pragma once
/// \file
/// \brief What every skylane fuzz target checks: a parser either returns or throws
/// `integrity::ParseError`; any other exception, a crash, a hang or a sanitizer report is a bug.
/// Whatever a successful parse returns must then be usable without throwing at all.
///
/// Other exceptions are deliberately not caught: with no handler anywhere, the C++ runtime
/// calls std::terminate before unwinding, so libFuzzer's "deadly signal" stack trace shows the
/// frame that threw, and libstdc++ prints the exception's type and what() just above it.

#include "integrity/gnss/parse_error.hpp"

#include <optional>
#include <string>
#include <utility>

namespace skylane::fuzz {

/// \brief Prints "skylane fuzz: <check>: <detail>" and aborts, so libFuzzer records the input.
[[noreturn]] void fail(const std::string& check, const std::string& detail);

/// \brief Stores a value where the optimiser cannot drop the computation that produced it.
void keepAlive(double value);

/// \brief Checks what a ParseError promises: a message that starts with the source it was given.
void checkParseError(const integrity::ParseError& e, const std::string& source);

/// \brief Runs `parse()`; a ParseError ends the input (after checkParseError). A result is
/// handed to `use(result)`. Nothing else is caught (see the file comment).
template <class Parse, class Use>
void parseThenUse(const std::string& source, Parse&& parse, Use&& use) {
  using Result = decltype(parse());
  std::optional<Result> result;
  try {
    result.emplace(std::forward<Parse>(parse)());
  } catch (const integrity::ParseError& e) {
    checkParseError(e, source);
    return;
  }
  std::forward<Use>(use)(*result);
}

/// \brief Fails with the condition's text and a detail when `cond` is false.
#define SKYLANE_FUZZ_CHECK(cond, detail)                                   \
  do {                                                                     \
    if (!(cond)) ::skylane::fuzz::fail("check failed: " #cond, (detail)); \
  } while (false)

}  // namespace skylane::fuzz
