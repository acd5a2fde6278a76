#include "maps/decimal_text.hpp"

#include <nlohmann/json.hpp>

#include <charconv>
#include <cmath>
#include <cstdint>

namespace skylane::maps {
namespace {

constexpr double kScale[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8};
constexpr std::uint64_t kUnit[] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000, 100000000};

/// The decimal digits of v (v < 10^20), most significant first; returns the end.
char* writeDigits(char* p, std::uint64_t v) {
  char tmp[20];
  int n = 0;
  do {
    tmp[n++] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0);
  while (n > 0) *p++ = tmp[--n];
  return p;
}

/// count / 10^decimals as "[-]int[.frac]" without trailing zeros in the fraction; an integer
/// with ".0" after it when `point_zero` (as nlohmann writes one).
char* writeFixed(char* p, bool negative, std::uint64_t count, int decimals, bool point_zero = false) {
  if (negative) *p++ = '-';
  p = writeDigits(p, count / kUnit[decimals]);
  std::uint64_t frac = count % kUnit[decimals];
  if (frac == 0 && point_zero) {
    *p++ = '.';
    *p++ = '0';
  }
  if (frac == 0) return p;
  int width = decimals;
  while (frac % 10 == 0) {
    frac /= 10;
    --width;
  }
  *p++ = '.';
  for (int i = width - 1; i >= 0; --i, frac /= 10) p[i] = static_cast<char>('0' + frac % 10);
  return p + width;
}

}  // namespace

char* toCharsRounded(char* first, double v, int decimals) {
  const double a = std::fabs(v);
  if (decimals >= 0 && decimals <= 8 && a >= 1e-3 && a < 1e5) {
    const double count = std::round(a * kScale[decimals]);  // < 10^13: an exact integer
    if (count / kScale[decimals] == a) return writeFixed(first, v < 0, static_cast<std::uint64_t>(count), decimals);
  }
  return std::to_chars(first, first + kRoundedMaxChars, v).ptr;
}

char* jsonTextOfMillimetres(char* first, double v) {
  const double a = std::fabs(v);
  if (a >= 1e-3 && a < 1e5) {
    const double count = std::round(a * 1e3);
    if (count / 1e3 == a) return writeFixed(first, v < 0, static_cast<std::uint64_t>(count), 3, true);
  }
  return nlohmann::detail::to_chars(first, first + kRoundedMaxChars, v);
}

}  // namespace skylane::maps
