#include "planner/tracking/track_event.hpp"

#include "geofence/verdict_json.hpp"
#include "maps/decimal_text.hpp"
#include "maps/json_node.hpp"
#include "maps/json_numbers.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

namespace skylane::planner {

using nlohmann::json;
using maps::metresOrNull;
using maps::roundToDeg8;
using maps::roundToMm;
using geofence::isBoxLevel;

TrackEvent trackEvent(const char* type, const std::string& flight, const maps::GpsTime& t) {
  TrackEvent e;
  e.type = type;
  e.flight = flight;
  e.time = t;
  return e;
}

TrackEvent rejectedInputEvent(const std::string& source, std::size_t line, const std::string& why) {
  TrackEvent e;
  e.type = "rejected_input";
  e["source"] = source;
  e["error"] = why;
  if (line > 0) e["line"] = line;
  return e;
}

TrackEvent inputDroppedEvent(const std::string& source, std::uint64_t count, std::uint64_t total) {
  TrackEvent e;
  e.type = "input_dropped";
  e["source"] = source;
  e["count"] = count;
  e["total"] = total;
  return e;
}

void to_json(json& j, const FixRecord& f) {
  j["line"] = f.line;
  j["lat"] = roundToDeg8(f.lat_rad);
  j["lon"] = roundToDeg8(f.lon_rad);
  j["h_ell_m"] = roundToMm(f.h_ell_m);
  j["hpl_m"] = metresOrNull(f.hpl_m);
  j["vpl_m"] = metresOrNull(f.vpl_m);
  j["pl_source"] = plSourceName(f.pl_source);
  if (f.fault_detected) j["fault_detected"] = *f.fault_detected;
  if (!f.excluded.empty()) {
    json ex = json::array();
    for (const integrity::SatId& s : f.excluded) ex.push_back(s.str());
    j["excluded"] = ex;
  }
  if (f.ins_degraded) j["ins_degraded"] = *f.ins_degraded;
  j["verdict"] = geofence::verdictName(f.verdict.verdict);
  j["violated"] = f.verdict.violated ? json(geofence::levelName(*f.verdict.violated)) : json(nullptr);
  json levels = json::object();
  json near = json::array();
  for (const geofence::Check& c : f.verdict.checks) {
    const json check = c;  // the one form (geofence/verdict_json.hpp); the fix event shows a part
    if (isBoxLevel(c)) {
      levels[geofence::levelName(c.level)] = geofence::pickMembers(check, {"verdict", "margin_h_m", "margin_v_m", "segment"});
    } else if (c.level == geofence::Level::kKeepIn) {
      levels[geofence::levelName(c.level)] =
          geofence::pickMembers(check, {"verdict", "margin_h_m", "margin_v_m", "subject", "name", "restriction"});
    } else {
      near.push_back(geofence::pickMembers(check, {"level", "subject", "verdict", "clearance_m", "name", "restriction"}));
    }
  }
  j["levels"] = levels;
  j["near"] = near;
  j["route_version"] = f.route_version;
  if (f.rerun) j["rerun"] = true;
  if (!f.note.empty()) j["note"] = f.note;
}

json TrackEvent::toJson() const {
  json j = body;
  j["event"] = type;
  if (!flight.empty()) j["flight"] = flight;
  if (time) j["time"] = maps::formatRfc3339(*time, 3);
  if (fix) to_json(j, *fix);
  return j;
}

namespace {

const std::string kEventSource = "track event";
/// The event types the engine writes (TrackEvent::type points at one of them).
constexpr std::array<const char*, 8> kEventTypes{"fix",   "violation",      "recovered",    "monitoring_rerun",
                                                 "replan", "stale", "rejected_input", "input_dropped"};

const char* eventTypeOf(const maps::JsonNode& n) {
  const std::string s = n.str();
  for (const char* t : kEventTypes) {
    if (s == t) return t;
  }
  n.fail("fix, violation, recovered, monitoring_rerun, replan, stale, rejected_input or input_dropped");
}

PlSource plSourceOf(const maps::JsonNode& n) {
  const std::string s = n.str();
  for (PlSource p : {PlSource::kOnboard, PlSource::kRaw, PlSource::kNmeaGst, PlSource::kIns, PlSource::kGnssIns,
                     PlSource::kMavlinkAccuracy, PlSource::kUbxPl, PlSource::kUbxAccuracy}) {
    if (s == plSourceName(p)) return p;
  }
  n.fail("onboard, raw, nmea_gst, ins, gnss_ins, mavlink_accuracy, ubx_pl or ubx_accuracy");
}

/// A box level's part of the fix event ({verdict, margins, segment}) as a check of `level`; the
/// keep-in part ({verdict, margins, subject, name, restriction}) as it is.
geofence::Check boxCheckOf(const json& part, geofence::Level level) {
  json whole = part;
  whole["level"] = geofence::levelName(level);
  if (level != geofence::Level::kKeepIn) {
    whole["subject"] = "segment " + std::to_string(part.value("segment", 0));
    whole["across_joint"] = false;
  }
  return whole.get<geofence::Check>();
}

/// A zone's or obstacle's part ({level, subject, verdict, clearance_m}) as a check.
geofence::Check nearCheckOf(const json& part) {
  json whole = part;
  whole["margin_h_m"] = nullptr;
  whole["margin_v_m"] = nullptr;
  whole["exact"] = false;
  return whole.get<geofence::Check>();
}

/// The members of a fix event that are not the FixRecord's.
const std::array<const char*, 17> kFixMembers{"line", "lat", "lon", "h_ell_m", "hpl_m", "vpl_m", "pl_source",
                                              "fault_detected", "excluded", "ins_degraded", "verdict", "violated",
                                              "levels", "near", "route_version", "rerun", "note"};

}  // namespace

void from_json(const json& j, FixRecord& f) {
  const maps::JsonNode n{j, "$", kEventSource};
  f = FixRecord{};
  f.line = static_cast<std::size_t>(n.at("line").number());
  f.lat_rad = maps::deg2rad(n.at("lat").number());
  f.lon_rad = maps::deg2rad(n.at("lon").number());
  f.h_ell_m = n.at("h_ell_m").number();
  f.hpl_m = n.has("hpl_m") ? n.at("hpl_m").number() : std::numeric_limits<double>::infinity();
  f.vpl_m = n.has("vpl_m") ? n.at("vpl_m").number() : std::numeric_limits<double>::infinity();
  f.pl_source = plSourceOf(n.at("pl_source"));
  if (n.has("fault_detected")) f.fault_detected = n.at("fault_detected").boolean();
  if (n.has("excluded")) {
    const maps::JsonNode ex = n.at("excluded");
    for (std::size_t i = 0; i < ex.array().size(); ++i) {
      const auto sat = integrity::parseSatId(ex.item(i).str());
      if (!sat) ex.item(i).fail("a satellite such as G05 or E11");
      f.excluded.push_back(*sat);
    }
  }
  if (n.has("ins_degraded")) f.ins_degraded = n.at("ins_degraded").boolean();
  json verdict{{"verdict", j.at("verdict")}, {"violated", j.value("violated", json())}, {"checks", json::array()}};
  const maps::JsonNode levels = n.at("levels");
  for (geofence::Level level : {geofence::Level::kCorridor, geofence::Level::kAirspace, geofence::Level::kKeepIn}) {
    if (levels.has(geofence::levelName(level))) verdict["checks"].push_back(boxCheckOf(levels.at(geofence::levelName(level)).j, level));
  }
  for (const json& part : n.at("near").array()) verdict["checks"].push_back(nearCheckOf(part));
  f.verdict = verdict.get<geofence::FenceVerdict>();
  f.route_version = static_cast<int>(n.at("route_version").number());
  f.rerun = n.has("rerun") && n.at("rerun").boolean();
  if (n.has("note")) f.note = n.at("note").str();
}

void from_json(const json& j, TrackEvent& e) {
  const maps::JsonNode n{j, "$", kEventSource};
  if (!j.is_object()) n.fail("an event object");
  e = TrackEvent{};
  e.type = eventTypeOf(n.at("event"));
  if (n.has("flight")) e.flight = n.at("flight").str();
  if (n.has("time")) {
    const auto t = maps::parseRfc3339(n.at("time").str());
    if (!t) n.at("time").fail("an RFC 3339 date-time");
    e.time = *t;
  }
  json body = j;
  for (const char* k : {"event", "flight", "time"}) body.erase(k);
  if (e.is("fix")) {
    e.fix = j.get<FixRecord>();
    for (const char* k : kFixMembers) body.erase(k);
  }
  if (!body.empty()) e.body = std::move(body);
}

namespace {

/// A JSON writer for the fix event: members in nlohmann's (sorted) order, numbers rounded
/// (maps/json_numbers.hpp) and written shortest round-trip (std::to_chars' text,
/// maps/decimal_text.hpp), ±∞ and NaN as null, strings escaped per RFC 8259 §7.
class LineWriter {
 public:
  explicit LineWriter(std::string& out) : s_(out) {}
  void key(std::string_view k) {
    if (need_comma_) s_ += ',';
    s_ += '"';
    s_ += k;
    s_ += "\":";
    need_comma_ = false;
  }
  void open(char c) {
    s_ += c;
    need_comma_ = false;
  }
  void close(char c) {
    s_ += c;
    need_comma_ = true;
  }
  void item() {
    if (need_comma_) s_ += ',';
    need_comma_ = false;
  }
  void integer(long long v) {
    char buf[24];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    s_.append(buf, r.ptr);
    need_comma_ = true;
  }
  void boolean(bool v) {
    s_ += v ? "true" : "false";
    need_comma_ = true;
  }
  void null() {
    s_ += "null";
    need_comma_ = true;
  }
  void string(std::string_view v) {
    s_ += '"';
    for (const char ch : v) {
      const auto c = static_cast<unsigned char>(ch);
      if (c == '"' || c == '\\') {
        s_ += '\\';
        s_ += ch;
      } else if (c < 0x20) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\u%04x", c);
        s_ += buf;
      } else {
        s_ += ch;
      }
    }
    s_ += '"';
    need_comma_ = true;
  }
  /// An RFC 3339 time to the millisecond (maps::formatRfc3339's text, written without a string
  /// of its own: the text has no character to escape).
  void time(const maps::GpsTime& t) {
    char buf[maps::kRfc3339MaxChars];
    const char* end = maps::formatRfc3339To(buf, t, 3);
    if (end == nullptr) {
      string(maps::formatRfc3339(t, 3));  // a year outside 1–9998: the general form
      return;
    }
    s_ += '"';
    s_.append(static_cast<const char*>(buf), end);
    s_ += '"';
    need_comma_ = true;
  }
  /// A value rounded to `decimals` places (roundToMm, roundToDeg8), as std::to_chars writes it.
  void rounded(double v, int decimals) {
    char buf[maps::kRoundedMaxChars];
    s_.append(buf, maps::toCharsRounded(buf, v, decimals));
    need_comma_ = true;
  }
  void metres(double v) {
    if (std::isfinite(v)) {
      rounded(roundToMm(v), 3);
    } else {
      null();
    }
  }
  void degrees(double rad) { rounded(roundToDeg8(rad), 8); }

 private:
  std::string& s_;
  bool need_comma_ = false;
};

/// Whether the text is well-formed UTF-8 (RFC 3629 §4: no overlong forms, no surrogates, nothing
/// above U+10FFFF), so it can be written as it is.
bool validUtf8(std::string_view v) {
  const auto at = [&v](std::size_t i) { return static_cast<unsigned char>(v[i]); };
  std::size_t i = 0;
  while (i < v.size()) {
    const unsigned char c = at(i);
    if (c < 0x80) {
      ++i;
      continue;
    }
    std::size_t n = 0;
    unsigned char lo = 0x80, hi = 0xBF;  // the range of the second byte
    if (c >= 0xC2 && c <= 0xDF) n = 1;
    else if (c == 0xE0) n = 2, lo = 0xA0;
    else if (c >= 0xE1 && c <= 0xEC) n = 2;
    else if (c == 0xED) n = 2, hi = 0x9F;
    else if (c >= 0xEE && c <= 0xEF) n = 2;
    else if (c == 0xF0) n = 3, lo = 0x90;
    else if (c >= 0xF1 && c <= 0xF3) n = 3;
    else if (c == 0xF4) n = 3, hi = 0x8F;
    else return false;
    if (i + n >= v.size() || at(i + 1) < lo || at(i + 1) > hi) return false;
    for (std::size_t k = 2; k <= n; ++k) {
      if (at(i + k) < 0x80 || at(i + k) > 0xBF) return false;
    }
    i += n + 1;
  }
  return true;
}

}  // namespace

namespace {

/// The keep-in part of "levels" (its members in sorted order).
void writeKeepIn(LineWriter& w, const geofence::Check& c) {
  w.key(geofence::levelName(c.level));
  w.open('{');
  w.key("margin_h_m");
  w.metres(c.margin_h_m);
  w.key("margin_v_m");
  w.metres(c.margin_v_m);
  w.key("name");
  w.string(c.name);
  w.key("restriction");
  w.string(c.restriction);
  w.key("subject");
  w.string(c.subject);
  w.key("verdict");
  w.string(geofence::verdictWord(c.level, c.verdict));
  w.close('}');
}

/// The two box levels and the keep-in check of a fix event, as the object "levels" (keep_in
/// sorts before level1).
void writeLevels(LineWriter& w, const FixRecord& f) {
  w.key("levels");
  w.open('{');
  for (const geofence::Check& c : f.verdict.checks) {
    if (c.level == geofence::Level::kKeepIn) writeKeepIn(w, c);
  }
  for (const geofence::Check& c : f.verdict.checks) {
    if (!isBoxLevel(c)) continue;
    w.key(geofence::levelName(c.level));
    w.open('{');
    w.key("margin_h_m");
    w.metres(c.margin_h_m);
    w.key("margin_v_m");
    w.metres(c.margin_v_m);
    w.key("segment");
    w.integer(static_cast<long long>(c.index));
    w.key("verdict");
    w.string(geofence::verdictName(c.verdict));
    w.close('}');
  }
  w.close('}');
}

/// The zones and obstacles near a fix, as the array "near".
void writeNear(LineWriter& w, const FixRecord& f) {
  w.key("near");
  w.open('[');
  for (const geofence::Check& c : f.verdict.checks) {
    if (geofence::isContainmentLevel(c.level)) continue;
    w.item();
    w.open('{');
    w.key("clearance_m");
    if (c.clearance_m) {
      w.metres(*c.clearance_m);
    } else {
      w.null();
    }
    w.key("level");
    w.string(geofence::levelName(c.level));
    if (c.level == geofence::Level::kZone) {
      w.key("name");
      w.string(c.name);
      w.key("restriction");
      w.string(c.restriction);
    }
    w.key("subject");
    w.string(c.subject);
    w.key("verdict");
    w.string(geofence::verdictWord(c.level, c.verdict));
    w.close('}');
  }
  w.close(']');
}

/// The members from "event" to "lat" (nlohmann's sorted order).
void writeFixHead(LineWriter& w, const TrackEvent& e, const FixRecord& f) {
  w.key("event");
  w.string(e.type);
  if (!f.excluded.empty()) {
    w.key("excluded");
    w.open('[');
    for (const integrity::SatId& s : f.excluded) {
      w.item();
      w.string(s.str());
    }
    w.close(']');
  }
  if (f.fault_detected) {
    w.key("fault_detected");
    w.boolean(*f.fault_detected);
  }
  if (!e.flight.empty()) {
    w.key("flight");
    w.string(e.flight);
  }
  w.key("h_ell_m");
  w.metres(f.h_ell_m);
  w.key("hpl_m");
  w.metres(f.hpl_m);
  if (f.ins_degraded) {
    w.key("ins_degraded");
    w.boolean(*f.ins_degraded);
  }
  w.key("lat");
  w.degrees(f.lat_rad);
}

/// The members from "line" to "vpl_m".
void writeFixTail(LineWriter& w, const TrackEvent& e, const FixRecord& f) {
  w.key("line");
  w.integer(static_cast<long long>(f.line));
  w.key("lon");
  w.degrees(f.lon_rad);
  writeNear(w, f);
  if (!f.note.empty()) {
    w.key("note");
    w.string(f.note);
  }
  w.key("pl_source");
  w.string(plSourceName(f.pl_source));
  if (f.rerun) {
    w.key("rerun");
    w.boolean(true);
  }
  w.key("route_version");
  w.integer(f.route_version);
  if (e.time) {
    w.key("time");
    w.time(*e.time);
  }
  w.key("verdict");
  w.string(geofence::verdictName(f.verdict.verdict));
  w.key("violated");
  if (f.verdict.violated) {
    w.string(geofence::levelName(*f.verdict.violated));
  } else {
    w.null();
  }
  w.key("vpl_m");
  w.metres(f.vpl_m);
}

}  // namespace

std::string TrackEvent::jsonLine() const {
  std::string out;
  appendJsonLine(out);
  return out;
}

void TrackEvent::appendJsonLine(std::string& out) const {
  const bool plain = fix && validUtf8(flight) && validUtf8(fix->note) &&
                     std::all_of(fix->verdict.checks.begin(), fix->verdict.checks.end(),
                                 [](const geofence::Check& c) {
                                   return validUtf8(c.subject) && validUtf8(c.name) && validUtf8(c.restriction);
                                 });
  if (!plain) {
    out += toJson().dump(-1, ' ', false, json::error_handler_t::replace);
    return;
  }
  out.reserve(out.size() + 512);
  LineWriter w(out);
  w.open('{');
  writeFixHead(w, *this, *fix);
  writeLevels(w, *fix);
  writeFixTail(w, *this, *fix);
  w.close('}');
}

}  // namespace skylane::planner
