#include "planner/tracking/tracker.hpp"

#include "integrity/ins/navigator.hpp"
#include "integrity/sim/scenario.hpp"
#include "integrity/sim/trajectory.hpp"
#include "maps/file_digest.hpp"
#include "maps/geodesy.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace skylane::planner {

using nlohmann::json;

namespace {

double roundMm(double v) { return std::round(v * 1e3) / 1e3; }
double roundDeg(double rad) { return std::round(maps::rad2deg(rad) * 1e8) / 1e8; }
json metres(double v) { return std::isfinite(v) ? json(roundMm(v)) : json(nullptr); }

constexpr int kLevels = 4;
/// The filter's initial position σ per axis at alignment: a snapshot's error is a few metres.
constexpr double kAlignPositionSigma_m = 10.0;
/// How far the IMU increments' span may differ from the time between two fixes (+0.1 %).
constexpr double kSpanTolerance_s = 0.02;

/// Pushes v into a window of at most n values and returns how many are true.
int pushWindow(std::vector<bool>& w, bool v, int n) {
  w.push_back(v);
  while (static_cast<int>(w.size()) > n) w.erase(w.begin());
  return static_cast<int>(std::count(w.begin(), w.end(), true));
}

TrackEvent event(const char* type, const std::string& flight, const maps::GpsTime& t) {
  TrackEvent e;
  e.type = type;
  e.flight = flight;
  e.time = t;
  return e;
}

}  // namespace

struct Tracker::Flight {
  std::string id;
  ApprovedFlight plan;
  std::shared_ptr<Approver> approver;
  std::unique_ptr<geofence::Corridor> level1, level2;
  std::vector<Eigen::Vector3d> stops;  ///< the mission's points (map frame)
  integrity::LiveFixConfig live;
  FlightState st;
  // GNSS/INS (seed 001's flow) for fixes with IMU increments. Not persisted: a restarted tracker
  // aligns the filter again at the next fix with velocity and attitude.
  std::unique_ptr<integrity::ins::Navigator> nav;
  int nav_grade = -1;
  maps::GpsTime nav_t0, nav_time;

  /// Seed 001's flow with the mission's error model and mask and the grade's IMU figures (the
  /// filter assumes the grade's datasheet values, integrity/sim/sensors.hpp; baro, magnetometer
  /// and clock the simulator's defaults).
  [[nodiscard]] integrity::ins::NavigatorConfig navigatorConfig(int grade) const {
    const auto g = static_cast<integrity::sim::ImuGrade>(grade);
    integrity::sim::SensorSpec sensors;
    sensors.imu = integrity::sim::imuSpec(g);
    sensors.model = live.model;
    sensors.elevation_mask_rad = live.elevation_mask_rad;
    integrity::ins::NavigatorConfig c;
    integrity::sim::matchFilterToSensors(c, sensors, g);
    c.ekf.initial_position_m = kAlignPositionSigma_m;
    c.compute_araim = false;  // the snapshot ARAIM beside the flow is not used here
    return c;
  }

  /// The fix's pseudoranges above the mask seen from r, with their satellites.
  [[nodiscard]] std::vector<integrity::ins::PseudorangeInput> navRanges(const TrackFix& fix, const Eigen::Vector3d& r) const {
    std::vector<integrity::SatId> missing;
    std::vector<integrity::ins::PseudorangeInput> out;
    for (const integrity::LocatedRange& l : integrity::locateRanges(fix.ranges, r, fix.time, &approver->orbits(), missing)) {
      if (maps::lookAngles(r, l.sat_ecef_m).elevation_rad < live.elevation_mask_rad) continue;
      out.push_back({l.sat, l.sat_ecef_m, l.pr_m});
    }
    return out;
  }

  /// One epoch of `n`: the fix's IMU increments, then its pseudoranges and aiding.
  integrity::ins::NavigatorEpoch runInsEpoch(integrity::ins::Navigator& n, const TrackFix& fix) const {
    for (const ImuIncrement& i : fix.imu->increments) n.propagate(i.dtheta_rad, i.dv_mps, i.dt_s);
    return n.epoch(fix.time - nav_t0, navRanges(fix, n.filter().nav().r_ecef_m), fix.baro_h_m, fix.mag_heading_rad);
  }

  /// The filter's epoch for a fix with IMU increments, when the filter is aligned and the
  /// increments continue it (they must span the time since its last epoch; else it aligns
  /// again). `before` keeps the filter as it was, for a monitoring rerun.
  std::optional<integrity::ins::NavigatorEpoch> insEpoch(const TrackFix& fix, std::string& note,
                                                         std::unique_ptr<integrity::ins::Navigator>& before) {
    if (!nav) return std::nullopt;
    const double gap = fix.time - nav_time, span = fix.imu->span_s();
    char buf[160];
    if (fix.imu->grade != nav_grade) {
      std::snprintf(buf, sizeof buf, "GNSS/INS: the IMU grade changed; the filter aligns again");
    } else if (std::abs(span - gap) > kSpanTolerance_s + 0.001 * gap) {
      std::snprintf(buf, sizeof buf, "GNSS/INS: the IMU increments span %.3f s but the fixes are %.3f s apart; the filter aligns again",
                    span, gap);
    } else {
      before = std::make_unique<integrity::ins::Navigator>(*nav);
      integrity::ins::NavigatorEpoch ep = runInsEpoch(*nav, fix);
      nav_time = fix.time;
      return ep;
    }
    nav.reset();
    note = buf;
    return std::nullopt;
  }

  /// The fix's epoch again from the filter as it was (`before`), with one more exclusion allowed
  /// (the monitoring rerun of the GNSS/INS flow); when it gives a PL the filter takes it.
  std::optional<integrity::ins::NavigatorEpoch> deeperEpoch(const integrity::ins::Navigator& before, const TrackFix& fix) try {
    auto deeper = std::make_unique<integrity::ins::Navigator>(before);  // (kept off the fix path's stack)
    const int max_exclusions = deeper->config().max_exclusions;
    deeper->setMaxExclusions(max_exclusions + 1);
    integrity::ins::NavigatorEpoch ep = runInsEpoch(*deeper, fix);
    if (!ep.seed001_available) return std::nullopt;
    deeper->setMaxExclusions(max_exclusions);
    nav = std::move(deeper);
    return ep;
  } catch (const std::exception&) {  // the rerun failed: the first pass stands
    return std::nullopt;
  }

  /// Aligns the filter at a snapshot solution with the fix's velocity and attitude.
  void align(const TrackFix& fix, const integrity::LiveFix& snap, std::string& note) {
    if (!fix.velocity_enu_mps || !fix.attitude_rad) {
      if (note.empty()) note = "GNSS/INS not aligned: the fix gives no velocity_enu_mps and attitude_deg";
      return;
    }
    integrity::ins::NavState s;
    s.r_ecef_m = snap.p_ecef;
    const Eigen::Matrix3d R_enu_ecef = maps::rotationEcefToEnu(snap.position.lat_rad, snap.position.lon_rad);
    s.v_ecef_mps = R_enu_ecef.transpose() * *fix.velocity_enu_mps;
    const Eigen::Vector3d& a = *fix.attitude_rad;
    s.C_ecef_body = R_enu_ecef.transpose() * integrity::sim::bodyToEnu(a.z(), a.y(), a.x());
    // The receiver clock: the mean residual of the satellites the snapshot used.
    std::vector<integrity::SatId> missing;
    double sum = 0.0;
    int count = 0;
    for (const integrity::LocatedRange& l : integrity::locateRanges(fix.ranges, s.r_ecef_m, fix.time, &approver->orbits(), missing)) {
      if (std::find(snap.used.begin(), snap.used.end(), l.sat) == snap.used.end()) continue;
      sum += l.pr_m - (l.sat_ecef_m - s.r_ecef_m).norm();
      ++count;
    }
    if (count == 0) return;
    nav = std::make_unique<integrity::ins::Navigator>(navigatorConfig(fix.imu->grade), s, sum / count, 0.0);
    nav_grade = fix.imu->grade;
    nav_t0 = nav_time = fix.time;
    if (note.empty()) note = "GNSS/INS aligned at the snapshot position with the fix's velocity and attitude";
  }

  void buildBoxes() {
    std::vector<Eigen::Vector3d> path;
    for (RoutePoint& p : plan.route) {
      const Eigen::Vector2d xy = approver->frame().toPlane(p.lat_rad, p.lon_rad);
      p.xyz = Eigen::Vector3d(xy.x(), xy.y(), p.h_ell_m);
      path.push_back(p.xyz);
    }
    level1 = std::make_unique<geofence::Corridor>(path, plan.level1);
    level2 = std::make_unique<geofence::Corridor>(path, plan.level2);
  }
};

Tracker::Tracker(TrackerOptions options) : options_(options) {
  if (options_.level1_m < 1 || options_.level1_n < options_.level1_m || options_.level2_m < 1 ||
      options_.level2_n < options_.level2_m) {
    throw std::invalid_argument("tracker: persistence needs 1 ≤ M ≤ N for both rules (level 1: " +
                                std::to_string(options_.level1_m) + " of " + std::to_string(options_.level1_n) +
                                ", level 2: " + std::to_string(options_.level2_m) + " of " +
                                std::to_string(options_.level2_n) + ")");
  }
  if (options_.recover_after < 1) throw std::invalid_argument("tracker: recover_after must be ≥ 1");
  if (options_.jump_confirm < 1) throw std::invalid_argument("tracker: jump_confirm must be ≥ 1");
  if (!(options_.stale_after_s > 0) || !(options_.max_time_jump_s > 0) || !(options_.replan_cooldown_s >= 0) ||
      !(options_.horizon_m >= 0 && std::isfinite(options_.horizon_m))) {
    throw std::invalid_argument("tracker: stale_after_s and max_time_jump_s must be > 0 s, replan_cooldown_s ≥ 0 s, horizon_m ≥ 0 m");
  }
}

Tracker::~Tracker() = default;

void Tracker::addFlight(const std::string& id, const ApprovedFlight& approval, std::shared_ptr<Approver> approver) {
  if (id.empty()) throw std::invalid_argument("tracker: a flight needs an identifier");
  if (flights_.count(id)) throw std::invalid_argument("tracker: flight \"" + id + "\" is already tracked");
  if (!approval.approved) throw std::invalid_argument("tracker: flight \"" + id + "\": its route was rejected, not approved");
  auto f = std::make_unique<Flight>();
  f->id = id;
  f->plan = approval;
  f->approver = std::move(approver);
  f->buildBoxes();
  f->stops = f->approver->missionStops();
  const Mission& m = f->approver->mission();
  f->live.method = m.method;
  f->live.model = m.model;
  f->live.elevation_mask_rad = maps::deg2rad(m.mask_deg);
  flights_.emplace(id, std::move(f));
}

std::string approvedMissionPath(const ApprovedFlight& plan, const std::string& report_path) {
  namespace fs = std::filesystem;
  // The mission as written (from here), where it was at approval time, or beside the report.
  fs::path mission = plan.mission_source;
  if (!fs::exists(mission) && !plan.mission_source_absolute.empty()) mission = plan.mission_source_absolute;
  if (!fs::exists(mission)) mission = fs::path(report_path).parent_path() / fs::path(plan.mission_source).filename();
  if (!fs::exists(mission)) {
    throw maps::ParseError(report_path, 0, "$.source", plan.mission_source,
                           "a mission file that exists (as written, at $.source_absolute, or beside the report)");
  }
  if (!plan.mission_sha256.empty() && maps::fileSha256Hex(mission.string()) != plan.mission_sha256) {
    throw maps::ParseError(report_path, 0, "$.inputs[role=mission].sha256", plan.mission_sha256,
                           "the digest of " + mission.string() + " (the mission changed since it was approved)");
  }
  return mission.string();
}

std::string Tracker::addApprovalFile(const std::string& report_path, const std::string& id) {
  return addApproval(maps::readJsonFile(report_path), report_path, id);
}

std::string Tracker::addApproval(const json& report, const std::string& report_path, const std::string& id) {
  const ApprovedFlight plan = parseApprovalReport(report, report_path);
  namespace fs = std::filesystem;
  const fs::path mission = approvedMissionPath(plan, report_path);
  const std::string key = fs::weakly_canonical(mission).string();
  if (!plan.approved) throw maps::ParseError(report_path, 0, "$.decision", "rejected", "an approved route");
  auto it = approvers_.find(key);
  if (it == approvers_.end()) it = approvers_.emplace(key, std::make_shared<Approver>(loadMission(mission.string()))).first;
  std::string name = id.empty() ? plan.mission_name : id;
  if (name.empty()) name = fs::path(report_path).stem().string();
  if (flights_.count(name)) {
    throw maps::ParseError(report_path, 0, "flight id", name, "an id not used by another approval (give ID=REPORT)");
  }
  addFlight(name, plan, it->second);
  return name;
}

std::vector<std::string> Tracker::flights() const {
  std::vector<std::string> out;
  for (const auto& [id, f] : flights_) out.push_back(id);
  return out;
}

std::string Tracker::onlyFlight() const { return flights_.size() == 1 ? flights_.begin()->first : std::string(); }

const FlightState& Tracker::state(const std::string& id) const { return flights_.at(id)->st; }

const Approver& Tracker::approver(const std::string& id) const { return *flights_.at(id)->approver; }

json Tracker::routeJson(const std::string& id) const {
  const Flight& f = *flights_.at(id);
  json route = json::array();
  for (const RoutePoint& p : f.plan.route) {
    route.push_back({{"lat", roundDeg(p.lat_rad)}, {"lon", roundDeg(p.lon_rad)}, {"h_ell_m", roundMm(p.h_ell_m)},
                     {"alt_amsl_m", roundMm(p.alt_amsl_m)}, {"eta_s", roundMm(p.eta_s)}});
  }
  return {{"departure", maps::formatRfc3339(f.plan.departure, 3)}, {"route", route}};
}

void Tracker::restore(const std::string& id, const FlightState& state, const json& route) {
  Flight& f = *flights_.at(id);
  f.st = state;
  if (route.is_object() && route.contains("route")) {
    const std::string source = "tracker database, flight " + id;
    const maps::JsonNode root{route, "$", source};
    const auto t = maps::parseRfc3339(root.at("departure").str());
    if (!t) root.at("departure").fail("an RFC 3339 date-time");
    std::vector<RoutePoint> pts;
    const maps::JsonNode list = root.at("route");
    for (std::size_t i = 0; i < list.array().size(); ++i) {
      const maps::JsonNode p = list.item(i);
      RoutePoint rp;
      rp.lat_rad = maps::deg2rad(p.at("lat").number());
      rp.lon_rad = maps::deg2rad(p.at("lon").number());
      rp.h_ell_m = p.at("h_ell_m").number();
      rp.alt_amsl_m = p.at("alt_amsl_m").number();
      rp.eta_s = p.at("eta_s").number();
      pts.push_back(rp);
    }
    if (pts.size() < 2) list.fail("a route of at least 2 points");
    f.plan.route = pts;
    f.plan.departure = *t;
    f.buildBoxes();
  }
}

TrackEvent Tracker::rejectedInput(const std::string& source, std::size_t line, const std::string& why) const {
  TrackEvent e;
  e.type = "rejected_input";
  e["source"] = source;
  e["error"] = why;
  if (line > 0) e["line"] = line;
  return e;
}

json TrackEvent::toJson() const {
  json j = body;
  j["event"] = type;
  if (!flight.empty()) j["flight"] = flight;
  if (time) j["time"] = maps::formatRfc3339(*time, 3);
  if (!fix) return j;
  const FixRecord& f = *fix;
  j["line"] = f.line;
  j["lat"] = roundDeg(f.lat_rad);
  j["lon"] = roundDeg(f.lon_rad);
  j["h_ell_m"] = roundMm(f.h_ell_m);
  j["hpl_m"] = metres(f.hpl_m);
  j["vpl_m"] = metres(f.vpl_m);
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
    if (c.level == geofence::Level::kCorridor || c.level == geofence::Level::kAirspace) {
      levels[geofence::levelName(c.level)] = {{"verdict", geofence::verdictName(c.verdict)},
                                             {"margin_h_m", metres(c.margin_h_m)},
                                             {"margin_v_m", metres(c.margin_v_m)},
                                             {"segment", c.index}};
    } else {
      near.push_back({{"level", geofence::levelName(c.level)},
                      {"subject", c.subject},
                      {"verdict", geofence::verdictName(c.verdict)},
                      {"clearance_m", metres(c.clearance_m.value_or(0.0))}});
    }
  }
  j["levels"] = levels;
  j["near"] = near;
  j["route_version"] = f.route_version;
  if (f.rerun) j["rerun"] = true;
  if (!f.note.empty()) j["note"] = f.note;
  return j;
}

namespace {

/// A JSON writer for the fix event: members in nlohmann's (sorted) order, numbers shortest
/// round-trip (std::to_chars), ±∞ and NaN as null, strings escaped per RFC 8259 §7.
class LineWriter {
 public:
  explicit LineWriter(std::string& out) : s_(out) {}
  void key(const char* k) {
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
  void number(double v) {
    if (!std::isfinite(v)) {
      s_ += "null";
    } else {
      char buf[32];
      const auto r = std::to_chars(buf, buf + sizeof buf, v);
      s_.append(buf, r.ptr);
    }
    need_comma_ = true;
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
  void metres(double v) { number(std::isfinite(v) ? roundMm(v) : v); }

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

std::string TrackEvent::jsonLine() const {
  const bool plain = fix && validUtf8(flight) && validUtf8(fix->note) &&
                     std::all_of(fix->verdict.checks.begin(), fix->verdict.checks.end(),
                                 [](const geofence::Check& c) { return validUtf8(c.subject); });
  if (!plain) return toJson().dump(-1, ' ', false, json::error_handler_t::replace);
  const FixRecord& f = *fix;
  std::string out;
  out.reserve(512);
  LineWriter w(out);
  w.open('{');
  w.key("event");
  w.string(type);
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
  if (!flight.empty()) {
    w.key("flight");
    w.string(flight);
  }
  w.key("h_ell_m");
  w.number(roundMm(f.h_ell_m));
  w.key("hpl_m");
  w.metres(f.hpl_m);
  if (f.ins_degraded) {
    w.key("ins_degraded");
    w.boolean(*f.ins_degraded);
  }
  w.key("lat");
  w.number(roundDeg(f.lat_rad));
  w.key("levels");
  w.open('{');
  for (const geofence::Check& c : f.verdict.checks) {
    if (c.level != geofence::Level::kCorridor && c.level != geofence::Level::kAirspace) continue;
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
  w.key("line");
  w.integer(static_cast<long long>(f.line));
  w.key("lon");
  w.number(roundDeg(f.lon_rad));
  w.key("near");
  w.open('[');
  for (const geofence::Check& c : f.verdict.checks) {
    if (c.level == geofence::Level::kCorridor || c.level == geofence::Level::kAirspace) continue;
    w.item();
    w.open('{');
    w.key("clearance_m");
    w.metres(c.clearance_m.value_or(0.0));
    w.key("level");
    w.string(geofence::levelName(c.level));
    w.key("subject");
    w.string(c.subject);
    w.key("verdict");
    w.string(geofence::verdictName(c.verdict));
    w.close('}');
  }
  w.close(']');
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
  if (time) {
    w.key("time");
    w.string(maps::formatRfc3339(*time, 3));
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
  w.close('}');
  return out;
}

std::vector<json> Tracker::processJson(const TrackFix& fix) {
  std::vector<json> out;
  for (const TrackEvent& e : process(fix)) out.push_back(e.toJson());
  return out;
}

std::vector<TrackEvent> Tracker::sweepStale(const maps::GpsTime& now) {
  std::vector<TrackEvent> out;
  for (auto& [id, f] : flights_) {
    // A flight whose last fix was at its goal has arrived: its silence is expected.
    if (!f->st.last_time || f->st.stale_reported || f->st.arrived) continue;
    const double gap = now - f->st.last_time->plus(-f->st.clock_offset_s);
    if (gap <= options_.stale_after_s) continue;
    TrackEvent e = event("stale", id, now);
    e["last_fix"] = maps::formatRfc3339(*f->st.last_time, 3);
    e["gap_s"] = std::round(gap * 1e3) / 1e3;
    e["expected_within_s"] = options_.stale_after_s;
    out.push_back(std::move(e));
    f->st.stale_reported = true;
  }
  last_sweep_ = now;
  return out;
}

std::vector<TrackEvent> Tracker::process(const TrackFix& fix) {
  std::vector<TrackEvent> out;
  const std::string id = fix.flight.empty() ? onlyFlight() : fix.flight;
  const auto it = flights_.find(id);
  if (it == flights_.end()) {
    out.push_back(rejectedInput(fix.source, fix.line,
                                fix.flight.empty() ? "the fix names no flight and " + std::to_string(flights_.size()) +
                                                         " flights are tracked (give \"flight\")"
                                                   : "unknown flight \"" + fix.flight + "\" (no approval loaded for it)"));
    return out;
  }
  Flight& f = *it->second;
  FlightState& st = f.st;
  // Order: against the last accepted fix, or (the first fix) the approved departure and flight.
  std::string jump_note;
  std::optional<double> jump_s;
  std::optional<double> new_offset;
  std::string jump_from;
  if (st.last_time) {
    const double dt = fix.time - *st.last_time;
    std::string why;
    if (std::abs(dt) > options_.max_time_jump_s) {
      jump_s = dt;
      jump_from = "the last accepted fix";
    } else if (dt == 0.0) {
      why = "duplicate time " + maps::formatRfc3339(fix.time, 3) + " (already accepted for flight " + id + ")";
    } else if (dt < 0.0) {
      why = "out of order: " + maps::formatRfc3339(fix.time, 3) + " is before the last accepted fix " +
            maps::formatRfc3339(*st.last_time, 3);
    }
    if (!why.empty()) {
      TrackEvent e = rejectedInput(fix.source, fix.line, why);
      e.flight = id;
      out.push_back(std::move(e));
      return out;
    }
  } else {
    const double from_departure = fix.time - f.plan.departure;
    if (from_departure < -options_.max_time_jump_s ||
        from_departure > f.plan.route.back().eta_s + options_.max_time_jump_s) {
      jump_s = from_departure;
      jump_from = "the approved departure " + maps::formatRfc3339(f.plan.departure);
    }
  }
  if (jump_s) {
    // A jump of the receiver's clock, a long outage, a late flight: the fix is refused unless it
    // continues a run of jump_confirm fixes in order on the new timeline (then that is taken).
    const bool continues = st.jump_candidate && fix.time - *st.jump_candidate > 0 &&
                           fix.time - *st.jump_candidate <= options_.max_time_jump_s;
    st.jump_count = continues ? st.jump_count + 1 : 1;
    st.jump_candidate = fix.time;
    const std::string size = "time jump of " + std::to_string(static_cast<long long>(*jump_s)) + " s from " + jump_from;
    if (st.jump_count < options_.jump_confirm) {
      TrackEvent e = rejectedInput(fix.source, fix.line,
                                   size + " (more than " + std::to_string(static_cast<long long>(options_.max_time_jump_s)) +
                                       " s; " + std::to_string(st.jump_count) + " of " +
                                       std::to_string(options_.jump_confirm) + " fixes in order to take the new timeline)");
      e.flight = id;
      out.push_back(std::move(e));
      return out;
    }
    jump_note = "a new timeline after a " + size + ", confirmed by " + std::to_string(st.jump_count) + " fixes in order";
    // The flight's clock from here on is the stream's plus an offset: the fix is "now" (taken
    // once the fix is accepted, after the sweep has seen the flight's gap on its old clock).
    if (st.last_time && stream_time_) new_offset = fix.time - *stream_time_;
  }
  st.jump_candidate.reset();
  st.jump_count = 0;

  // Protection levels and position.
  const maps::PlaneFrame& frame = f.approver->frame();
  maps::Geodetic pos{fix.lat_rad, fix.lon_rad, fix.h_ell_m};
  std::optional<double> hpl = fix.hpl_m, vpl = fix.vpl_m;
  // The source of the PLs used: skylane's own (raw ranges solved), else what the fix gave.
  // (A RINEX replay's fixes carry skylane's own PLs already: their source stays "raw".)
  PlSource source = fix.ranges.empty() ? fix.pl_source : PlSource::kOnboard;
  if (!fix.hpl_m && fix.ins) source = PlSource::kIns;
  std::optional<integrity::LiveFix> first;
  std::string note;
  std::optional<integrity::ins::NavigatorEpoch> ins_ep;
  std::unique_ptr<integrity::ins::Navigator> ins_before;  // the filter before this epoch (GNSS/INS)
  std::vector<TrackEvent> pre_events;  // written once the fix is accepted
  bool early_rerun = false;
  if (fix.imu && !fix.ranges.empty()) {
    try {
      ins_ep = f.insEpoch(fix, note, ins_before);
    } catch (const std::exception& err) {  // e.g. a covariance gone non-positive: align again
      f.nav.reset();
      ins_ep.reset();
      ins_before.reset();
      note = std::string("GNSS/INS filter failed (") + err.what() + "); the filter aligns again";
    }
    if (ins_ep && !ins_ep->seed001_available && ins_ep->gnss_fault_detected && ins_before) {
      // A fault detected and not excluded: the monitoring rerun at once, one more exclusion allowed.
      if (auto again = f.deeperEpoch(*ins_before, fix)) {
        TrackEvent e = event("monitoring_rerun", id, fix.time);
        e["fault_detected"] = true;
        json ex = json::array();
        for (const integrity::SatId& s : again->excluded) ex.push_back(s.str());
        e["excluded"] = ex;
        e["hpl_before_m"] = nullptr;
        e["vpl_before_m"] = nullptr;
        e["hpl_after_m"] = metres(again->seed001_hpl_m);
        e["vpl_after_m"] = metres(again->seed001_vpl_m);
        e["note"] = "GNSS/INS: a fault detected and not excluded; the epoch again with one more exclusion";
        e["line"] = fix.line;
        pre_events.push_back(std::move(e));
        ins_ep = again;
        early_rerun = true;
      }
    }
    if (ins_ep && !ins_ep->seed001_available) {
      const bool unresolved = ins_ep->gnss_fault_detected && ins_ep->excluded.empty();
      note = ins_ep->outage ? "GNSS/INS: no pseudorange above the mask (dead reckoning, no integrity); the snapshot is used"
                            : "GNSS/INS gave no protection level (" +
                                  std::string(unresolved ? "a fault detected and not excluded" : "too few satellites or no fault-mode PL") +
                                  "); the snapshot is used";
      ins_ep.reset();
    }
  }
  if (ins_ep) {
    if (ins_ep->baro_refused || ins_ep->heading_refused) {
      note = std::string("GNSS/INS refused the ") +
             (ins_ep->baro_refused ? (ins_ep->heading_refused ? "barometer and magnetometer" : "barometer") : "magnetometer") +
             " reading (its innovation failed the gate)";
    }
    pos = maps::ecefToGeodetic(ins_ep->r_ecef_m);
    hpl = ins_ep->seed001_hpl_m;
    vpl = ins_ep->seed001_vpl_m;
    source = PlSource::kGnssIns;
  } else if (!fix.ranges.empty()) {
    first = integrity::solveLiveFix(fix.ranges, pos, fix.time, f.live, false, &f.approver->orbits());
    if (first->solved && first->pl.pl_computed) {
      pos = first->position;
      hpl = first->pl.hpl_m;
      vpl = first->pl.vpl_m;
      source = PlSource::kRaw;
      if (fix.imu && !f.nav && !first->fault_detected) f.align(fix, *first, note);
    } else {
      note = "raw pseudoranges gave no PL (" + first->note + (first->pl.reason.empty() ? "" : "; " + first->pl.reason) + ")";
      first.reset();
    }
  }
  if (fix.ins) {
    const auto [h, v] = insNominalPl(*fix.ins);
    hpl = std::max(hpl.value_or(0.0), h);
    vpl = std::max(vpl.value_or(0.0), v);
  }
  if (!hpl || !vpl) {
    TrackEvent e = rejectedInput(fix.source, fix.line, "no protection level for the fix: " + (note.empty() ? "none given" : note));
    e.flight = id;
    out.push_back(std::move(e));
    return out;
  }
  auto volumeAt = [&](const maps::Geodetic& g, double h, double v) {
    const Eigen::Vector2d xy = frame.toPlane(g.lat_rad, g.lon_rad);
    return geofence::TimedVolume{fix.time, fix.time, {Eigen::Vector3d(xy.x(), xy.y(), g.h_ell_m), h, v}};
  };
  geofence::TimedVolume vol = volumeAt(pos, *hpl, *vpl);
  geofence::FenceVerdict verdict;
  try {
    verdict = geofence::checkVolume(*f.level1, *f.level2, f.approver->obstructions(), vol, options_.horizon_m);
  } catch (const std::invalid_argument& e) {  // e.g. a volume beyond the modelled heights
    TrackEvent r = rejectedInput(fix.source, fix.line, std::string("the fix cannot be checked: ") + e.what());
    r.flight = id;
    out.push_back(std::move(r));
    return out;
  }
  // Accepted. Stream time moves on with accepted fixes only (a refused one cannot push it
  // ahead); the sweep sees this flight's gap before its time is updated.
  const maps::GpsTime on_stream = fix.time.plus(-new_offset.value_or(st.clock_offset_s));
  if (!stream_time_ || on_stream - *stream_time_ > 0) stream_time_ = on_stream;
  if (!last_sweep_ || *stream_time_ - *last_sweep_ >= 1.0 || *stream_time_ - *last_sweep_ < 0.0) {
    for (TrackEvent& e : sweepStale(*stream_time_)) out.push_back(std::move(e));
  }
  for (TrackEvent& e : pre_events) out.push_back(std::move(e));
  if (early_rerun) ++st.rerun_count;
  if (new_offset) st.clock_offset_s = *new_offset;
  st.last_time = fix.time;
  st.stale_reported = false;
  ++st.fixes;
  auto levelVerdict = [](const geofence::FenceVerdict& v, geofence::Level l) {
    geofence::Verdict worst = geofence::Verdict::kInside;
    for (const geofence::Check& c : v.checks) {
      if (c.level != l || c.verdict == geofence::Verdict::kInside) continue;
      if (c.verdict == geofence::Verdict::kOutside || worst == geofence::Verdict::kInside) worst = c.verdict;
    }
    return worst;
  };

  // Monitoring rerun: FDE over the raw measurements when level 1 is not held.
  bool rerun = early_rerun;  // (GNSS/INS: already rerun for a fault it could not exclude)
  std::vector<integrity::SatId> excluded;
  if (ins_ep) excluded = ins_ep->excluded;
  if ((first || ins_ep) && !early_rerun && levelVerdict(verdict, geofence::Level::kCorridor) != geofence::Verdict::kInside) {
    // The rerun's solution: raw ranges, the method's FDE; GNSS/INS, the epoch again from the
    // filter as it was with one more exclusion allowed (step 1 of the flow already ran its FDE).
    struct Again {
      bool ok = false;
      maps::Geodetic pos;
      double hpl_m = 0.0, vpl_m = 0.0;
      std::vector<integrity::SatId> excluded;
      std::string note;
    } again;
    const bool detected = ins_ep ? ins_ep->gnss_fault_detected : first->fault_detected;
    if (ins_ep) {
      again = {true, pos, *hpl, *vpl, ins_ep->excluded, ""};
      if (detected && ins_before) {
        if (auto ep2 = f.deeperEpoch(*ins_before, fix)) {
          again = {true, maps::ecefToGeodetic(ep2->r_ecef_m), ep2->seed001_hpl_m, ep2->seed001_vpl_m, ep2->excluded, ""};
          ins_ep = ep2;
        } else {
          again.note = "the epoch with one more exclusion gave no PL; the first pass stands";
        }
      }
    } else {
      // Without a detected fault the FDE would give the first pass back (nothing to exclude),
      // so it is not computed again.
      const integrity::LiveFix lf = detected ? integrity::solveLiveFix(fix.ranges, pos, fix.time, f.live, true, &f.approver->orbits())
                                             : *first;
      again.ok = lf.solved && lf.pl.pl_computed;
      again.pos = lf.position;
      again.hpl_m = lf.pl.hpl_m;
      again.vpl_m = lf.pl.vpl_m;
      again.excluded = lf.excluded;
      again.note = lf.note + lf.pl.reason;
      // A filter not yet aligned can start from the solution without the faulty satellite.
      if (fix.imu && !f.nav && again.ok && lf.fault_excluded) f.align(fix, lf, note);
    }
    rerun = true;
    ++st.rerun_count;
    // Its event is written on a detection and at the start of a level-1 episode (a PL that never
    // fits HAL₁ would otherwise repeat it at every fix).
    const bool write = detected || !st.violated[static_cast<int>(geofence::Level::kCorridor)];
    TrackEvent e = event("monitoring_rerun", id, fix.time);
    e["fault_detected"] = detected;
    json ex = json::array();
    for (const integrity::SatId& s : again.excluded) ex.push_back(s.str());
    e["excluded"] = ex;
    e["hpl_before_m"] = metres(*hpl);
    e["vpl_before_m"] = metres(*vpl);
    e["verdict_before"] = geofence::verdictName(levelVerdict(verdict, geofence::Level::kCorridor));
    if (again.ok) {
      pos = again.pos;
      hpl = again.hpl_m;
      vpl = again.vpl_m;
      excluded = again.excluded;
      const geofence::TimedVolume vol2 = volumeAt(pos, *hpl, *vpl);
      try {
        verdict = geofence::checkVolume(*f.level1, *f.level2, f.approver->obstructions(), vol2, options_.horizon_m);
        vol = vol2;
      } catch (const std::invalid_argument& err) {
        e["note"] = std::string("the rerun's volume cannot be checked: ") + err.what();
      }
      e["hpl_after_m"] = metres(*hpl);
      e["vpl_after_m"] = metres(*vpl);
      e["verdict_after"] = geofence::verdictName(levelVerdict(verdict, geofence::Level::kCorridor));
      if (!again.note.empty() && !e.body.contains("note")) e["note"] = again.note;
    } else {
      e["hpl_after_m"] = nullptr;
      e["vpl_after_m"] = nullptr;
      e["verdict_after"] = e.body["verdict_before"];
      e["note"] = again.note;
    }
    e["line"] = fix.line;
    if (write) out.push_back(std::move(e));
  }

  // Persistence per level.
  std::array<geofence::Verdict, kLevels> lv{};
  for (int l = 0; l < kLevels; ++l) lv[l] = levelVerdict(verdict, static_cast<geofence::Level>(l));
  const bool bad1 = lv[0] != geofence::Verdict::kInside;
  const bool bad2 = lv[1] != geofence::Verdict::kInside || lv[2] != geofence::Verdict::kInside ||
                    lv[3] != geofence::Verdict::kInside;
  const bool pl_cause = *hpl > f.plan.level1.hal_m || *vpl > f.plan.level1.val_m;
  // The level-1 window counts the violations a replan can mend (by the position; also by the
  // PLs with replan_on_pl_exceedance), so PL excursions do not make a drift look persistent.
  const bool mendable1 = bad1 && (!pl_cause || options_.replan_on_pl_exceedance);
  const int count1 = pushWindow(st.level1_window, mendable1, options_.level1_n);
  const int count2 = pushWindow(st.level2_window, bad2, options_.level2_n);
  std::optional<geofence::Level> trigger;
  for (int l = 0; l < kLevels; ++l) {
    const auto level = static_cast<geofence::Level>(l);
    const bool bad = lv[l] != geofence::Verdict::kInside;
    if (bad) {
      st.inside_streak[l] = 0;
      if (!st.violated[l]) {
        st.violated[l] = true;
        TrackEvent e = event("violation", id, fix.time);
        e["level"] = geofence::levelName(level);
        e["verdict"] = geofence::verdictName(lv[l]);
        for (const geofence::Check& c : verdict.checks) {
          if (c.level != level || c.verdict == geofence::Verdict::kInside) continue;
          e["subject"] = c.subject;
          e["margin_h_m"] = metres(c.margin_h_m);
          e["margin_v_m"] = metres(c.margin_v_m);
          if (c.clearance_m) e["clearance_m"] = metres(*c.clearance_m);
          break;
        }
        if (level == geofence::Level::kCorridor) {
          e["cause"] = pl_cause ? "protection_level" : "position";
          e["rerun"] = rerun;
        }
        e["hpl_m"] = metres(*hpl);
        e["vpl_m"] = metres(*vpl);
        e["line"] = fix.line;
        out.push_back(std::move(e));
      }
    } else if (st.violated[l] && ++st.inside_streak[l] >= options_.recover_after) {
      st.violated[l] = false;
      TrackEvent e = event("recovered", id, fix.time);
      e["level"] = geofence::levelName(level);
      e["after_fixes"] = st.inside_streak[l];
      e["line"] = fix.line;
      out.push_back(std::move(e));
    }
  }
  if (count2 >= options_.level2_m && bad2) {
    trigger = lv[1] != geofence::Verdict::kInside ? geofence::Level::kAirspace
              : lv[2] != geofence::Verdict::kInside ? geofence::Level::kZone
                                                    : geofence::Level::kObstacle;
  } else if (count1 >= options_.level1_m && mendable1) {
    trigger = geofence::Level::kCorridor;
  }

  // Progress along the mission's points.
  const Eigen::Vector3d p_map = vol.volume.p_map;
  while (st.next_stop + 1 < f.stops.size() &&
         (f.stops[st.next_stop] - p_map).head<2>().norm() <= options_.waypoint_radius_m) {
    ++st.next_stop;
  }
  st.arrived = st.next_stop + 1 == f.stops.size() &&
               (f.stops.back() - p_map).head<2>().norm() <= options_.waypoint_radius_m;

  // The fix event.
  TrackEvent e = event("fix", id, fix.time);
  FixRecord rec;
  rec.line = fix.line;
  rec.lat_rad = pos.lat_rad;
  rec.lon_rad = pos.lon_rad;
  rec.h_ell_m = pos.h_ell_m;
  rec.hpl_m = *hpl;
  rec.vpl_m = *vpl;
  rec.pl_source = source;
  if (first) rec.fault_detected = first->fault_detected;
  if (ins_ep) {
    rec.fault_detected = ins_ep->gnss_fault_detected;
    rec.ins_degraded = ins_ep->degraded;
  }
  rec.excluded = std::move(excluded);
  rec.route_version = st.route_version;
  rec.rerun = rerun;
  rec.note = jump_note.empty() ? note : (note.empty() ? jump_note : jump_note + "; " + note);
  rec.verdict = std::move(verdict);
  e.fix = std::move(rec);
  out.push_back(std::move(e));

  // Replan from where the vehicle is.
  // (At the goal there is nowhere left to replan to: the violation stands.)
  if (trigger && options_.replan && !st.arrived &&
      (!st.last_replan || fix.time - *st.last_replan >= options_.replan_cooldown_s)) {
    st.last_replan = fix.time;
    ++st.replans;
    TrackEvent rp = event("replan", id, fix.time);
    rp["trigger"] = geofence::levelName(*trigger);
    rp["from"] = {{"lat", roundDeg(pos.lat_rad)}, {"lon", roundDeg(pos.lon_rad)}, {"h_ell_m", roundMm(pos.h_ell_m)}};
    rp["line"] = fix.line;
    ApprovalReport r;
    try {
      r = f.approver->replanFrom(p_map, fix.time, st.next_stop);
      rp["report"] = approvalReportJson(r, f.approver->mission());  // digests the input files again
    } catch (const std::exception& err) {  // the fix stays accepted; the replan is what failed
      rp["decision"] = "error";
      rp["error"] = err.what();
      rp["route_version"] = st.route_version;
      out.push_back(std::move(rp));
      return out;
    }
    rp["decision"] = r.approved ? "approved" : "rejected";
    rp.body["report"].erase("predicted");  // the samples stay in the tracker's database with the route
    if (r.approved) {
      rp["operational_intent"] = {{"volumes", operationalIntentVolumes(r, frame, 2, 30.0)},
                                  {"state", "Accepted"},
                                  {"priority", 0}};
      rp["corridor_volumes"] = operationalIntentVolumes(r, frame, 1, 30.0);
      f.plan.route = r.route;
      f.plan.departure = r.departure;
      f.buildBoxes();
      ++st.route_version;
      // The new corridor starts with empty persistence windows; a level still marked violated
      // is `recovered` once the fixes are inside the new boxes.
      st.level1_window.clear();
      st.level2_window.clear();
    }
    rp["route_version"] = st.route_version;
    rp["planning_time_s"] = std::round(r.elapsed_s * 1e4) / 1e4;
    out.push_back(std::move(rp));
  }
  return out;
}

json flightStateJson(const FlightState& s) {
  json j;
  j["last_time"] = s.last_time ? json(maps::formatRfc3339(*s.last_time, 3)) : json(nullptr);
  j["level1_window"] = s.level1_window;
  j["level2_window"] = s.level2_window;
  j["violated"] = s.violated;
  j["inside_streak"] = s.inside_streak;
  j["last_replan"] = s.last_replan ? json(maps::formatRfc3339(*s.last_replan, 3)) : json(nullptr);
  j["stale_reported"] = s.stale_reported;
  j["arrived"] = s.arrived;
  j["next_stop"] = s.next_stop;
  j["route_version"] = s.route_version;
  j["fixes"] = s.fixes;
  j["reruns"] = s.rerun_count;
  j["replans"] = s.replans;
  j["clock_offset_s"] = s.clock_offset_s;
  return j;
}

FlightState parseFlightState(const json& j, const std::string& source) {
  const maps::JsonNode root{j, "$", source};
  FlightState s;
  try {
    auto time = [&](const char* key) -> std::optional<maps::GpsTime> {
      if (!root.has(key)) return std::nullopt;
      const auto t = maps::parseRfc3339(root.at(key).str());
      if (!t) root.at(key).fail("an RFC 3339 date-time");
      return t;
    };
    s.last_time = time("last_time");
    s.last_replan = time("last_replan");
    s.level1_window = j.at("level1_window").get<std::vector<bool>>();
    s.level2_window = j.at("level2_window").get<std::vector<bool>>();
    s.violated = j.at("violated").get<std::array<bool, 4>>();
    s.inside_streak = j.at("inside_streak").get<std::array<int, 4>>();
    s.stale_reported = j.at("stale_reported").get<bool>();
    s.arrived = j.value("arrived", false);
    s.next_stop = j.at("next_stop").get<std::size_t>();
    s.route_version = j.at("route_version").get<int>();
    s.fixes = j.at("fixes").get<std::uint64_t>();
    s.rerun_count = j.at("reruns").get<std::uint64_t>();
    s.replans = j.at("replans").get<std::uint64_t>();
    s.clock_offset_s = j.value("clock_offset_s", 0.0);
  } catch (const nlohmann::json::exception& e) {
    throw maps::ParseError(source, 0, "$", maps::quoteJson(j), std::string("a tracker flight state (") + e.what() + ")");
  }
  return s;
}

}  // namespace skylane::planner
