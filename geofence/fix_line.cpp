#include "geofence/fix_line.hpp"

#include "maps/geodesy.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>

namespace skylane::geofence {
namespace {

/// Members of a fix (geofence/fix.hpp), one bit each: a second one is not plain.
enum Member : std::uint32_t { kId = 1, kTime = 2, kUntil = 4, kLat = 8, kLon = 16, kH = 32, kHpl = 64, kVpl = 128 };
constexpr std::uint32_t kRequired = kTime | kLat | kLon | kH | kHpl | kVpl;
/// Longest integer id echoed as written (nlohmann reads up to 19 digits as an integer).
constexpr std::size_t kMaxIdDigits = 18;

/// A cursor over the line; every read returns false on anything outside the plain form.
struct Cursor {
  const char* p;
  const char* end;

  void skipSpace() {
    while (p != end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) ++p;
  }
  bool take(char c) {
    skipSpace();
    if (p == end || *p != c) return false;
    ++p;
    return true;
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
  /// A JSON number (RFC 8259 §6 grammar), read as the nearest double; `integer` tells whether
  /// it had neither fraction nor exponent.
  bool number(double& out, bool& integer) {
    skipSpace();
    const char* start = p;
    if (p != end && *p == '-') ++p;
    if (p == end || *p < '0' || *p > '9') return false;
    if (*p == '0') {
      ++p;
    } else {
      while (p != end && *p >= '0' && *p <= '9') ++p;
    }
    integer = true;
    if (p != end && *p == '.') {
      integer = false;
      const char* digits = ++p;
      while (p != end && *p >= '0' && *p <= '9') ++p;
      if (p == digits) return false;
    }
    if (p != end && (*p == 'e' || *p == 'E')) {
      integer = false;
      ++p;
      if (p != end && (*p == '+' || *p == '-')) ++p;
      const char* digits = p;
      while (p != end && *p >= '0' && *p <= '9') ++p;
      if (p == digits) return false;
    }
    const auto [at, ec] = std::from_chars(start, p, out);
    return ec == std::errc() && at == p && std::isfinite(out);
  }
};

bool readTime(Cursor& c, maps::GpsTime& out) {
  std::string_view text;
  if (!c.plainString(text)) return false;
  const auto t = maps::parseRfc3339(text);
  if (!t) return false;
  out = *t;
  return true;
}

/// The id: a plain string or an integer nlohmann writes back as it is written.
bool readId(Cursor& c, std::string_view& out) {
  c.skipSpace();
  const char* start = c.p;
  if (c.p != c.end && *c.p == '"') {
    std::string_view text;
    if (!c.plainString(text)) return false;
  } else {
    double v = 0;
    bool integer = false;
    if (!c.number(v, integer) || !integer) return false;
    const std::size_t digits = static_cast<std::size_t>(c.p - start) - (*start == '-' ? 1 : 0);
    if (digits > kMaxIdDigits || (*start == '-' && v == 0.0)) return false;  // "-0" is written 0
  }
  out = std::string_view(start, static_cast<std::size_t>(c.p - start));
  return true;
}

/// One "key": value member into `out`; its bit in `seen`.
bool readMember(Cursor& c, PlainFix& out, std::uint32_t& seen) {
  std::string_view key;
  if (!c.plainString(key) || !c.take(':')) return false;
  double v = 0;
  bool integer = false;
  const auto once = [&seen](Member m) {
    if (seen & m) return false;
    seen |= m;
    return true;
  };
  if (key == "id") return once(kId) && readId(c, out.id_json);
  if (key == "time") return once(kTime) && readTime(c, out.t0);
  if (key == "until") return once(kUntil) && readTime(c, out.t1);
  if (!c.number(v, integer)) return false;
  if (key == "lat") return once(kLat) && std::abs(v) <= 90 && (out.lat_rad = maps::deg2rad(v), true);
  if (key == "lon") return once(kLon) && std::abs(v) <= 180 && (out.lon_rad = maps::deg2rad(v), true);
  if (key == "h_ell_m") return once(kH) && (out.h_ell_m = v, true);
  if (key == "hpl_m") return once(kHpl) && v >= 0 && (out.hpl_m = v, true);
  if (key == "vpl_m") return once(kVpl) && v >= 0 && (out.vpl_m = v, true);
  return false;  // another member: parseFix names it
}

}  // namespace

bool readPlainFixLine(std::string_view text, PlainFix& out) {
  Cursor c{text.data(), text.data() + text.size()};
  out = PlainFix{};
  std::uint32_t seen = 0;
  if (!c.take('{')) return false;
  do {
    if (!readMember(c, out, seen)) return false;
  } while (c.take(','));
  if (!c.take('}')) return false;
  c.skipSpace();
  if (c.p != c.end || (seen & kRequired) != kRequired) return false;
  if (!(seen & kUntil)) out.t1 = out.t0;
  return out.t1 - out.t0 >= 0;
}

}  // namespace skylane::geofence
