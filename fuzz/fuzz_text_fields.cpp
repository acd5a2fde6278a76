/// \file
/// \brief libFuzzer target for the small text-field parsers: parseRfc3339, parseDuration
/// (integrity/gnss/gnss_time.hpp) and parseSatId (integrity/gnss/satellite_id.hpp). The whole
/// input goes to each. They report bad text as nullopt, so nothing may throw. What they accept
/// must satisfy their documented results:
/// - RFC 3339: finite seconds of week in [0, 604800); formatRfc3339 → parseRfc3339 returns the
///   same instant to the printed millisecond (checked for UTC years 0000–9999, the years
///   RFC 3339 can write);
/// - duration: finite and > 0 ("nullopt when the text is not a positive duration");
/// - satellite id: PRN >= 1, and "G05"-style text of PRNs below 100 parses back to the same id.

#include "fuzz/fuzz_common.hpp"
#include "integrity/gnss/gnss_time.hpp"
#include "integrity/gnss/satellite_id.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace {

using namespace skylane;

/// Half a printed millisecond, plus round-off of seconds since 1980 in double (≈ 1e-5 s at year 9999).
constexpr double kRoundTripTolerance_s = 0.5e-3 + 1e-4;

void checkRfc3339(const std::string& text) {
  const auto t = integrity::parseRfc3339(text);
  if (!t) return;
  SKYLANE_FUZZ_CHECK(std::isfinite(t->sow) && t->sow >= 0.0 && t->sow < integrity::kSecondsPerWeek,
                     "week " + std::to_string(t->week) + " sow " + std::to_string(t->sow));
  const std::string printed = integrity::formatRfc3339(*t, 3);
  const int utc_year = integrity::utcFromGps(*t).year;
  if (utc_year < 0 || utc_year > 9999) return;
  const auto back = integrity::parseRfc3339(printed);
  SKYLANE_FUZZ_CHECK(back.has_value(), "formatRfc3339 wrote '" + printed + "', which does not parse");
  SKYLANE_FUZZ_CHECK(std::abs(*back - *t) <= kRoundTripTolerance_s,
                     "'" + printed + "' is " + std::to_string(*back - *t) + " s from the parsed instant");
}

void checkDuration(const std::string& text) {
  const auto d = integrity::parseDuration(text);
  if (!d) return;
  SKYLANE_FUZZ_CHECK(std::isfinite(*d) && *d > 0.0, "duration " + std::to_string(*d));
}

void checkSatId(const std::string& text) {
  const auto id = integrity::parseSatId(text);
  if (!id) return;
  SKYLANE_FUZZ_CHECK(id->prn >= 1, std::to_string(id->prn));
  const std::string printed = id->str();
  if (id->prn < 100) {
    const auto back = integrity::parseSatId(printed);
    SKYLANE_FUZZ_CHECK(back && *back == *id, "'" + printed + "' does not parse back to the same id");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  checkRfc3339(text);  // nothing is caught: an exception is a finding (fuzz_common.hpp)
  checkDuration(text);
  checkSatId(text);
  return 0;
}
