#include "planner/tracking/tracker.hpp"

#include "maps/file_digest.hpp"
#include "maps/geodesy.hpp"
#include "maps/json_node.hpp"
#include "maps/json_numbers.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"
#include "planner/tracking/fix_steps.hpp"
#include "planner/tracking/tracked_flight.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace skylane::planner {

using nlohmann::json;
using maps::roundToDeg8;
using maps::roundToMm;

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
  auto f = std::make_unique<TrackedFlight>();
  f->id = id;
  f->plan = approval;
  f->approver = std::move(approver);
  // A flight of the same approver on the same route, not replanned since: its boxes serve both.
  std::string key = f->routeKey();
  const TrackedFlight* twin = nullptr;
  if (const auto t = same_route_.find(key); t != same_route_.end()) {
    const auto it = flights_.find(t->second);
    if (it != flights_.end() && it->second->st.route_version == 0) twin = it->second.get();
  }
  f->buildBoxes(twin);
  same_route_[std::move(key)] = id;
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

void Tracker::reloadZones(const std::string& id) { flights_.at(id)->approver->reloadZones(); }

std::vector<std::string> Tracker::flights() const {
  std::vector<std::string> out;
  for (const auto& [id, f] : flights_) out.push_back(id);
  return out;
}

std::string Tracker::onlyFlight() const { return flights_.size() == 1 ? flights_.begin()->first : std::string(); }

void Tracker::handoffResult(const std::string& id, int route_version, bool acknowledged, const maps::GpsTime& t) {
  const auto it = flights_.find(id);
  if (it == flights_.end()) return;
  FlightState& st = it->second->st;
  if (route_version != st.route_version || !st.handoff_awaits_link) return;
  st.handoff_awaits_link = false;
  st.handoff_inside = 0;
  if (acknowledged) {
    st.handoff_since = t;  // the vehicle flies to the new route now: it has join_timeout_s to get there
  } else {
    st.handoff_since.reset();
  }
}

const FlightState& Tracker::state(const std::string& id) const { return flights_.at(id)->st; }

const Approver& Tracker::approver(const std::string& id) const { return *flights_.at(id)->approver; }

json Tracker::routeJson(const std::string& id) const {
  const TrackedFlight& f = *flights_.at(id);
  json route = json::array();
  for (const RoutePoint& p : f.plan.route) {
    route.push_back({{"lat", roundToDeg8(p.lat_rad)}, {"lon", roundToDeg8(p.lon_rad)}, {"h_ell_m", roundToMm(p.h_ell_m)},
                     {"alt_amsl_m", roundToMm(p.alt_amsl_m)}, {"eta_s", roundToMm(p.eta_s)}});
    if (p.hover_s > 0.0) route.back()["hover_s"] = roundToMm(p.hover_s);
  }
  return {{"departure", maps::formatRfc3339(f.plan.departure, 3)}, {"route", route}};
}

json Tracker::routeGeoJson(const std::string& id) const {
  const TrackedFlight& f = *flights_.at(id);
  json j = planner::routeGeoJson(f.plan, f.approver->mission(), f.approver->frame());
  j["features"][0]["properties"]["flight"] = id;
  j["features"][0]["properties"]["route_version"] = f.st.route_version;
  return j;
}

void Tracker::restore(const std::string& id, const FlightState& state, const json& route) {
  TrackedFlight& f = *flights_.at(id);
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
      if (p.has("hover_s")) rp.hover_s = p.at("hover_s").number();  // absent in databases written before hovers
      pts.push_back(rp);
    }
    if (pts.size() < 2) list.fail("a route of at least 2 points");
    f.plan.route = pts;
    f.plan.departure = *t;
    f.buildBoxes();
  }
}

TrackEvent Tracker::rejectedInput(const std::string& source, std::size_t line, const std::string& why) const {
  return rejectedInputEvent(source, line, why);
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
    TrackEvent e = trackEvent("stale", id, now);
    e["last_fix"] = maps::formatRfc3339(*f->st.last_time, 3);
    e["gap_s"] = std::round(gap * 1e3) / 1e3;
    e["expected_within_s"] = options_.stale_after_s;
    out.push_back(std::move(e));
    f->st.stale_reported = true;
  }
  last_sweep_ = now;
  return out;
}

void Tracker::acceptFix(TrackedFlight& f, FixWork& w) {
  FlightState& st = f.st;
  // Stream time moves on with accepted fixes only (a refused one cannot push it ahead); the
  // sweep sees this flight's gap before its time is updated.
  const maps::GpsTime on_stream = w.fix.time.plus(-w.new_offset.value_or(st.clock_offset_s));
  if (!stream_time_ || on_stream - *stream_time_ > 0) stream_time_ = on_stream;
  if (!last_sweep_ || *stream_time_ - *last_sweep_ >= 1.0 || *stream_time_ - *last_sweep_ < 0.0) {
    for (TrackEvent& e : sweepStale(*stream_time_)) w.out.push_back(std::move(e));
  }
  for (TrackEvent& e : w.pre_events) w.out.push_back(std::move(e));
  if (w.early_rerun) ++st.rerun_count;
  if (w.new_offset) st.clock_offset_s = *w.new_offset;
  st.last_time = w.fix.time;
  st.stale_reported = false;
  ++st.fixes;
}

std::vector<TrackEvent> Tracker::process(const TrackFix& fix) {
  std::vector<TrackEvent> events;
  process(fix, events);
  return events;
}

namespace {

/// The storage of the previous fix's events for this fix: the list itself and the fix event's
/// checks (the fence check fills the verdict in place, its checks' strings reused), so a stream
/// of fixes allocates nothing once grown.
void takeStorage(std::vector<TrackEvent>& events, FixWork& w) {
  for (TrackEvent& e : events) {
    if (e.fix) {
      w.verdict.checks.swap(e.fix->verdict.checks);
      break;
    }
  }
  events.clear();
  w.out.swap(events);
}

}  // namespace

void Tracker::process(const TrackFix& fix, std::vector<TrackEvent>& events) {
  std::string only;  // the flight when the fix names none
  if (fix.flight.empty()) only = onlyFlight();
  const std::string& id = fix.flight.empty() ? only : fix.flight;
  const auto it = flights_.find(id);
  if (it == flights_.end()) {
    TrackEvent e = rejectedInput(fix.source, fix.line,
                                 fix.flight.empty() ? "the fix names no flight and " + std::to_string(flights_.size()) +
                                                          " flights are tracked (give \"flight\")"
                                                    : "unknown flight \"" + fix.flight + "\" (no approval loaded for it)");
    e.flight = fix.flight;  // the flight the line named, known or not
    events.clear();
    events.push_back(std::move(e));
    return;
  }
  FixWork w(fix);
  takeStorage(events, w);
  runFixSteps(*it->second, w);
  events.swap(w.out);
}

void Tracker::runFixSteps(TrackedFlight& f, FixWork& w) {
  const TrackFix& fix = w.fix;
  w.note = fix.note;
  w.pos = {fix.lat_rad, fix.lon_rad, fix.h_ell_m};
  w.hpl_m = fix.hpl_m;
  w.vpl_m = fix.vpl_m;
  // The PLs' source: skylane's own when raw ranges are solved (a RINEX replay's fixes carry
  // skylane's own PLs already: their source stays "raw"), else what the fix gave.
  w.source = fix.ranges.empty() ? fix.pl_source : PlSource::kOnboard;
  if (!fix.hpl_m && fix.ins) w.source = PlSource::kIns;
  if (!checkOrder(options_, f, w, stream_time_)) return;
  runGnssInsEpoch(f, w);
  solveSnapshot(f, w);
  applyInsNominalPl(w);
  if (!requireProtectionLevels(f, w) || !checkFence(options_, f, w)) return;
  acceptFix(f, w);
  rerunMonitoring(options_, f, w);
  updatePersistence(options_, f, w);
  updateProgress(options_, f, w);
  holdReplanForHandoff(options_, f, w);
  writeFixEvent(f, w);
  replanIfPersistent(options_, f, w);
}

}  // namespace skylane::planner
