// The rounded-number writers give the text of the conversion they stand in for, byte for byte:
// std::to_chars' for the track event lines, nlohmann's dump() for the fence verdict lines — on
// every millimetre count up to 2 km, on random values of every magnitude, at the edges of the
// fast range and for the values handed on to the general conversion.
#include "maps/decimal_text.hpp"
#include "maps/json_numbers.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <charconv>
#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace skylane::maps {
namespace {

std::string fast(double v, int decimals) {
  char buf[kRoundedMaxChars];
  return std::string(buf, toCharsRounded(buf, v, decimals));
}

std::string reference(double v) {
  char buf[64];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

/// How many millimetre counts of ±2 km `writer` writes otherwise than `expected` (the first
/// five reported).
template <class Writer, class Expected>
int differingMillimetreCounts(Writer writer, Expected expected) {
  int differ = 0;
  for (long n = -2000000; n <= 2000000; ++n) {
    const double v = static_cast<double>(n) / 1e3;
    if (writer(v) != expected(v) && ++differ <= 5) ADD_FAILURE() << n << ": " << writer(v) << " vs " << expected(v);
  }
  return differ;
}

TEST(DecimalText, EveryMillimetreCountUpToTwoKilometresIsToCharsText) {
  EXPECT_EQ(differingMillimetreCounts([](double v) { return fast(v, 3); }, reference), 0);
}

TEST(DecimalText, RandomRoundedValuesOfEveryMagnitudeAreToCharsText) {
  std::mt19937_64 rng(20261203);
  std::uniform_real_distribution<double> exponent(-6.0, 7.0), unit(-1.0, 1.0);
  int differ = 0;
  for (int i = 0; i < 1000000; ++i) {
    const double raw = unit(rng) * std::pow(10.0, exponent(rng));
    for (const auto& [v, d] : {std::pair{roundToMm(raw), 3}, std::pair{roundToDeg8(raw * M_PI / 180.0), 8},
                               std::pair{std::round(raw * 1e6) / 1e6, 6}, std::pair{std::round(raw), 0}}) {
      if (fast(v, d) != reference(v) && ++differ <= 5) ADD_FAILURE() << v << " (" << d << "): " << fast(v, d);
    }
  }
  EXPECT_EQ(differ, 0);
}

TEST(DecimalText, EdgesOfTheFastRangeAndOtherValuesAreToCharsText) {
  const double max = std::numeric_limits<double>::max(), tiny = std::numeric_limits<double>::denorm_min();
  for (double v : {0.0, -0.0, 1e-3, -1e-3, 0.0015, 99999.999, -99999.999, 1e5, 1e6, 2e6, 1.5e6, 1e15, 123456789.125,
                   0.1 + 0.2, 1.0 / 3.0, 47.123456785, 1e-8, 5e-4, max, -max, tiny, 180.0, -179.99999999}) {
    for (int d : {0, 3, 8}) EXPECT_EQ(fast(v, d), reference(v)) << v << " (" << d << ")";
  }
  // Well-known texts, so that the comparison is not with itself.
  EXPECT_EQ(fast(roundToMm(12.3456), 3), "12.346");
  EXPECT_EQ(fast(roundToMm(-0.0004), 3), "-0");
  EXPECT_EQ(fast(roundToMm(120.0), 3), "120");
  EXPECT_EQ(fast(roundToDeg8(47.30000001 * M_PI / 180.0), 8), "47.30000001");
  EXPECT_EQ(fast(1e6, 3), "1e+06");
}

std::string fastJson(double v) {
  char buf[kRoundedMaxChars];
  return std::string(buf, jsonTextOfMillimetres(buf, v));
}

std::string nlohmannText(double v) {
  char buf[64];
  return std::string(buf, nlohmann::detail::to_chars(buf, buf + sizeof buf, v));
}

TEST(DecimalText, EveryMillimetreCountUpToTwoKilometresIsNlohmannsText) {
  EXPECT_EQ(differingMillimetreCounts(fastJson, nlohmannText), 0);
}

TEST(DecimalText, RandomMillimetreValuesAndEdgesAreNlohmannsText) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> exponent(-6.0, 9.0), unit(-1.0, 1.0);
  int differ = 0;
  for (int i = 0; i < 1000000; ++i) {
    const double v = roundToMm(unit(rng) * std::pow(10.0, exponent(rng)));
    if (fastJson(v) != nlohmannText(v) && ++differ <= 5) ADD_FAILURE() << v << ": " << fastJson(v);
  }
  EXPECT_EQ(differ, 0);
  for (double v : {0.0, -0.0, 1e-3, -1e-3, 99999.999, 1e5, 123456.789, 1e15, 1e16, 0.1 + 0.2, 5e-4}) {
    EXPECT_EQ(fastJson(v), nlohmannText(v)) << v;
  }
  EXPECT_EQ(fastJson(120.0), "120.0");  // nlohmann's mark of a floating-point integer
  EXPECT_EQ(fastJson(-0.25), "-0.25");
  EXPECT_EQ(fastJson(0.0), "0.0");
  EXPECT_EQ(nlohmann::json(roundToMm(-3.2004)).dump(), fastJson(roundToMm(-3.2004)));
}

}  // namespace
}  // namespace skylane::maps
