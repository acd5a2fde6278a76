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
#include "maps/plain_json.hpp"
#include "planner/tracking/track_fix.hpp"

#include <array>
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

/// One "key": value pair into `p`; false when it is not a plain field or not plain.
bool readPair(maps::PlainJsonCursor& c, PlainLine& p) {
  std::string_view key;
  if (!c.plainString(key) || !c.take(':')) return false;
  std::size_t k = 0;
  while (k < kFieldCount && kFieldNames[k] != key) ++k;
  if (k == kFieldCount || p.seen[k]) return false;
  p.seen[k] = true;
  if (k == kFlight) return c.plainString(p.flight);
  if (k == kVehicle) return c.plainString(p.vehicle);
  if (k == kTime) return c.plainString(p.time);
  bool integer = false;
  return c.number(p.number[k], integer);
}

bool readPlainLine(std::string_view text, PlainLine& p) {
  maps::PlainJsonCursor c(text);
  if (!c.take('{')) return false;
  do {
    if (!readPair(c, p)) return false;
  } while (c.take(','));
  return c.take('}') && c.atEnd();
}

/// Whether every value of a plain line is one the general way accepts as it is.
bool plainValuesAccepted(const PlainLine& p) {
  const auto& n = p.number;
  if (!p.seen[kTime] || !p.seen[kLat] || !p.seen[kLon] || !p.seen[kHeight]) return false;
  if (p.seen[kFlight] == p.seen[kVehicle] && p.seen[kFlight]) return false;
  if ((p.seen[kFlight] && p.flight.empty()) || (p.seen[kVehicle] && p.vehicle.empty())) return false;
  if (!p.seen[kHpl] || !p.seen[kVpl] || n[kHpl] < 0.0 || n[kVpl] < 0.0) return false;  // PLs from elsewhere: the general way
  if (std::abs(n[kLat]) > 90.0 || std::abs(n[kLon]) > 180.0 || std::abs(n[kHeight]) > 1e5) return false;
  if (p.seen[kBaro] && std::abs(n[kBaro]) > 1e5) return false;
  if (p.seen[kMag] && (n[kMag] < -360.0 || n[kMag] > 360.0)) return false;
  return true;
}

/// The fix of a plain line into `f` when every value is one the general way accepts as it is.
bool plainFix(const PlainLine& p, const std::string& source, TrackFix& f) {
  if (!plainValuesAccepted(p)) return false;
  const auto t = maps::parseRfc3339(p.time);
  if (!t) return false;
  const auto& n = p.number;
  clearTrackFix(f);
  f.source.assign(source);
  f.flight.assign(p.seen[kFlight] ? p.flight : p.vehicle);
  f.time = *t;
  f.lat_rad = maps::deg2rad(n[kLat]);
  f.lon_rad = maps::deg2rad(n[kLon]);
  f.h_ell_m = n[kHeight];
  f.hpl_m = n[kHpl];
  f.vpl_m = n[kVpl];
  if (p.seen[kBaro]) f.baro_h_m = n[kBaro];
  if (p.seen[kMag]) f.mag_heading_rad = maps::deg2rad(n[kMag]);
  return true;
}

}  // namespace

void clearTrackFix(TrackFix& fix) {
  std::string flight = std::move(fix.flight), source = std::move(fix.source), note = std::move(fix.note);
  fix = TrackFix{};
  flight.clear();
  source.clear();
  note.clear();
  fix.flight = std::move(flight);
  fix.source = std::move(source);
  fix.note = std::move(note);
}

bool parsePlainFixLine(std::string_view text, const std::string& source, TrackFix& out) {
  PlainLine p;
  if (text.size() > 4096 || !readPlainLine(text, p)) return false;
  return plainFix(p, source, out);
}

std::optional<TrackFix> parsePlainFixLine(std::string_view text, const std::string& source) {
  TrackFix f;
  if (!parsePlainFixLine(text, source, f)) return std::nullopt;
  return f;
}

void parseTrackFixLine(const std::string& text, const std::string& source, TrackFix& out) {
  if (parsePlainFixLine(text, source, out)) return;
  out = parseTrackFixJson(maps::parseJsonLine(text, source), source);
}

TrackFix parseTrackFixLine(const std::string& text, const std::string& source) {
  TrackFix f;
  parseTrackFixLine(text, source, f);
  return f;
}

}  // namespace skylane::planner
