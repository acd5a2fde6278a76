/// \file
/// \brief Reading a JSON-lines fix without building a JSON document, for the common line: one
/// flat object of the plain fields (flight or vehicle, time, position, onboard PLs, barometric
/// height, magnetic heading) with ASCII strings without escapes and plain numbers. Anything else
/// — nesting, escapes, literals, other fields, a repeated field, a value out of range, a syntax
/// error — goes the general way (maps::parseJsonLine + parseTrackFixJson), so every error
/// message and every accepted value is the one that way gives; the fast way only ever returns
/// the fix the general way would (tests/planner/fix_line_test.cpp compares the two on every
/// example and on generated lines, and fuzz_track on every input it makes).

#include "maps/json_node.hpp"
#include "planner/tracking/track_fix.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>

namespace skylane::planner {

namespace {

/// The plain fields and where they land while the line is read.
enum Field { kFlight, kVehicle, kTime, kLat, kLon, kHeight, kHpl, kVpl, kBaro, kMag, kFieldCount };

constexpr std::array<std::string_view, kFieldCount> kFieldNames = {"flight", "vehicle", "time", "lat", "lon", "h_ell_m",
                                                                   "hpl_m", "vpl_m", "baro_h_m", "mag_heading_deg"};

struct PlainLine {
  std::array<bool, kFieldCount> seen{};
  std::array<double, kFieldCount> number{};
  std::string_view flight, vehicle, time;
};

/// A cursor over the line; every step false when the line is not plain.
class Cursor {
 public:
  explicit Cursor(std::string_view s) : s_(s) {}
  void space() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\r' || s_[i_] == '\n')) ++i_;
  }
  bool take(char c) {
    space();
    if (i_ >= s_.size() || s_[i_] != c) return false;
    ++i_;
    return true;
  }
  [[nodiscard]] bool atEnd() {
    space();
    return i_ == s_.size();
  }
  [[nodiscard]] char peek() {
    space();
    return i_ < s_.size() ? s_[i_] : '\0';
  }
  /// A string of printable ASCII without escapes.
  bool string(std::string_view& out) {
    if (!take('"')) return false;
    const std::size_t start = i_;
    while (i_ < s_.size() && s_[i_] != '"') {
      const auto c = static_cast<unsigned char>(s_[i_]);
      if (c < 0x20 || c > 0x7e || c == '\\') return false;
      ++i_;
    }
    if (i_ >= s_.size()) return false;
    out = s_.substr(start, i_ - start);
    ++i_;
    return true;
  }
  /// A number in JSON's grammar (-?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?), at most 15
  /// digits when it is an integer (so its double is the one strtod gives as well).
  bool number(double& out) {
    space();
    const std::size_t start = i_;
    if (i_ < s_.size() && s_[i_] == '-') ++i_;
    const std::size_t int_start = i_;
    if (!digits()) return false;
    if (s_[int_start] == '0' && i_ - int_start > 1) return false;
    bool integer = true;
    if (i_ < s_.size() && s_[i_] == '.') {
      ++i_;
      integer = false;
      if (!digits()) return false;
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      ++i_;
      integer = false;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      if (!digits()) return false;
    }
    if (integer && i_ - int_start > 15) return false;
    const auto r = std::from_chars(s_.data() + start, s_.data() + i_, out);
    return r.ec == std::errc() && r.ptr == s_.data() + i_ && std::isfinite(out);
  }

 private:
  bool digits() {
    const std::size_t start = i_;
    while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
    return i_ > start;
  }
  std::string_view s_;
  std::size_t i_ = 0;
};

/// One "key": value pair into `p`; false when it is not a plain field or not plain.
bool readPair(Cursor& c, PlainLine& p) {
  std::string_view key;
  if (!c.string(key) || !c.take(':')) return false;
  std::size_t k = 0;
  while (k < kFieldCount && kFieldNames[k] != key) ++k;
  if (k == kFieldCount || p.seen[k]) return false;
  p.seen[k] = true;
  if (k == kFlight) return c.string(p.flight);
  if (k == kVehicle) return c.string(p.vehicle);
  if (k == kTime) return c.string(p.time);
  return c.number(p.number[k]);
}

bool readPlainLine(std::string_view text, PlainLine& p) {
  Cursor c(text);
  if (!c.take('{')) return false;
  if (c.peek() == '}') return false;  // {} is the general way's error
  do {
    if (!readPair(c, p)) return false;
  } while (c.take(','));
  return c.take('}') && c.atEnd();
}

/// The fix of a plain line when every value is one the general way accepts as it is.
std::optional<TrackFix> plainFix(const PlainLine& p, const std::string& source) {
  const auto& n = p.number;
  if (!p.seen[kTime] || !p.seen[kLat] || !p.seen[kLon] || !p.seen[kHeight]) return std::nullopt;
  if (p.seen[kFlight] == p.seen[kVehicle] && p.seen[kFlight]) return std::nullopt;
  if ((p.seen[kFlight] && p.flight.empty()) || (p.seen[kVehicle] && p.vehicle.empty())) return std::nullopt;
  if (!p.seen[kHpl] || !p.seen[kVpl] || n[kHpl] < 0.0 || n[kVpl] < 0.0) return std::nullopt;  // PLs from elsewhere: the general way
  if (std::abs(n[kLat]) > 90.0 || std::abs(n[kLon]) > 180.0 || std::abs(n[kHeight]) > 1e5) return std::nullopt;
  if (p.seen[kBaro] && std::abs(n[kBaro]) > 1e5) return std::nullopt;
  if (p.seen[kMag] && (n[kMag] < -360.0 || n[kMag] > 360.0)) return std::nullopt;
  const auto t = maps::parseRfc3339(std::string(p.time));
  if (!t) return std::nullopt;
  TrackFix f;
  f.source = source;
  f.flight = std::string(p.seen[kFlight] ? p.flight : p.vehicle);
  f.time = *t;
  f.lat_rad = maps::deg2rad(n[kLat]);
  f.lon_rad = maps::deg2rad(n[kLon]);
  f.h_ell_m = n[kHeight];
  f.hpl_m = n[kHpl];
  f.vpl_m = n[kVpl];
  if (p.seen[kBaro]) f.baro_h_m = n[kBaro];
  if (p.seen[kMag]) f.mag_heading_rad = maps::deg2rad(n[kMag]);
  return f;
}

}  // namespace

std::optional<TrackFix> parsePlainFixLine(std::string_view text, const std::string& source) {
  PlainLine p;
  if (text.size() > 4096 || !readPlainLine(text, p)) return std::nullopt;
  return plainFix(p, source);
}

TrackFix parseTrackFixLine(const std::string& text, const std::string& source) {
  if (std::optional<TrackFix> f = parsePlainFixLine(text, source)) return std::move(*f);
  return parseTrackFixJson(maps::parseJsonLine(text, source), source);
}

}  // namespace skylane::planner
