#pragma once
/// \file
/// \brief A cursor over one line of JSON in its plain form — the fast readers of fix lines
/// (geofence/fix_line.cpp, planner/tracking/fix_line.cpp) read flat objects of ASCII strings
/// without escapes and numbers with it, and hand anything else to nlohmann. Every read returns
/// false on what is outside the plain form; what it accepts it reads as nlohmann would.

#include <charconv>
#include <cmath>
#include <string_view>
#include <system_error>

namespace skylane::maps {

struct PlainJsonCursor {
  const char* p;
  const char* end;

  explicit PlainJsonCursor(std::string_view s) : p(s.data()), end(s.data() + s.size()) {}

  /// JSON's whitespace (RFC 8259 §2).
  void skipSpace() {
    while (p != end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) ++p;
  }
  bool take(char c) {
    skipSpace();
    if (p == end || *p != c) return false;
    ++p;
    return true;
  }
  /// Nothing but whitespace left.
  bool atEnd() {
    skipSpace();
    return p == end;
  }
  /// A string of printable ASCII without escapes: its characters (quotes excluded).
  bool plainString(std::string_view& out) {
    if (!take('"')) return false;
    const char* start = p;
    while (p != end && *p != '"') {
      const auto c = static_cast<unsigned char>(*p);
      if (c < 0x20 || c >= 0x7f || c == '\\') return false;
      ++p;
    }
    if (p == end) return false;
    out = std::string_view(start, static_cast<std::size_t>(p - start));
    ++p;
    return true;
  }
  /// A JSON number (RFC 8259 §6 grammar) as the nearest double, as nlohmann reads it: an
  /// integer (`integer`: neither fraction nor exponent) exactly converted, so "-0" is +0.
  bool number(double& out, bool& integer) {
    skipSpace();
    const char* start = p;
    if (p != end && *p == '-') ++p;
    if (p == end || *p < '0' || *p > '9') return false;
    if (*p == '0') {
      ++p;
    } else {
      digits();
    }
    integer = true;
    if (p != end && *p == '.') {
      integer = false;
      ++p;
      if (!digits()) return false;
    }
    if (p != end && (*p == 'e' || *p == 'E')) {
      integer = false;
      ++p;
      if (p != end && (*p == '+' || *p == '-')) ++p;
      if (!digits()) return false;
    }
    const auto [at, ec] = std::from_chars(start, p, out);
    if (integer && out == 0.0) out = 0.0;  // nlohmann keeps "-0" as the integer 0
    return ec == std::errc() && at == p && std::isfinite(out);
  }

 private:
  bool digits() {
    const char* start = p;
    while (p != end && *p >= '0' && *p <= '9') ++p;
    return p != start;
  }
};

}  // namespace skylane::maps
