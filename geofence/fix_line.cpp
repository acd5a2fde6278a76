#include "geofence/fix_line.hpp"

#include "maps/geodesy.hpp"
#include "maps/plain_json.hpp"

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

using Cursor = maps::PlainJsonCursor;

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
  Cursor c(text);
  out = PlainFix{};
  std::uint32_t seen = 0;
  if (!c.take('{')) return false;
  do {
    if (!readMember(c, out, seen)) return false;
  } while (c.take(','));
  if (!c.take('}') || !c.atEnd() || (seen & kRequired) != kRequired) return false;
  if (!(seen & kUntil)) out.t1 = out.t0;
  return out.t1 - out.t0 >= 0;
}

}  // namespace skylane::geofence
