#pragma once
/// \file
/// \brief What every skylane fuzz target checks: a parser either returns or throws
/// `integrity::ParseError`; any other exception, a crash, a hang or a sanitizer report is a bug.
/// Whatever a successful parse returns must then be usable without throwing.

#include "integrity/gnss/parse_error.hpp"

#include <exception>
#include <optional>
#include <string>
#include <utility>

namespace skylane::fuzz {

/// \brief Prints "skylane fuzz: <check>: <detail>" and aborts, so libFuzzer records the input.
[[noreturn]] void fail(const std::string& check, const std::string& detail);

/// \brief Demangled dynamic type of an exception, for reports ("std::invalid_argument").
[[nodiscard]] std::string typeName(const std::exception& e);

/// \brief Stores a value where the optimiser cannot drop the computation that produced it.
void keepAlive(double value);

/// \brief Checks what a ParseError promises: a message, and the source it was given.
void checkParseError(const integrity::ParseError& e, const std::string& source);

/// \brief Runs `parse()`; a ParseError ends the input quietly (checked by checkParseError),
/// anything else thrown fails. A result is handed to `use(result)`, which must not throw at all.
template <class Parse, class Use>
void parseThenUse(const std::string& source, Parse&& parse, Use&& use) {
  using Result = decltype(parse());
  std::optional<Result> result;
  try {
    result.emplace(std::forward<Parse>(parse)());
  } catch (const integrity::ParseError& e) {
    checkParseError(e, source);
    return;
  } catch (const std::exception& e) {
    fail("parser threw something other than ParseError", typeName(e) + ": " + e.what());
  } catch (...) {
    fail("parser threw something other than ParseError", "a non-std exception");
  }
  try {
    std::forward<Use>(use)(*result);
  } catch (const std::exception& e) {
    fail("using a parsed result threw", typeName(e) + ": " + e.what());
  } catch (...) {
    fail("using a parsed result threw", "a non-std exception");
  }
}

/// \brief Fails with the condition's text and a detail when `cond` is false.
#define SKYLANE_FUZZ_CHECK(cond, detail)                                   \
  do {                                                                     \
    if (!(cond)) ::skylane::fuzz::fail("check failed: " #cond, (detail)); \
  } while (false)

}  // namespace skylane::fuzz
