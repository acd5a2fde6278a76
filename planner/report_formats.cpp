#include "planner/report_formats.hpp"

#include "geofence/verdict_json.hpp"
#include "maps/json_node.hpp"
#include "maps/json_numbers.hpp"

#include <cmath>
#include <sstream>

namespace skylane::planner {

namespace {

using nlohmann::json;

using maps::roundToDeg8;
using maps::roundToMm;

nlohmann::json lonLat(const maps::PlaneFrame& frame, const Eigen::Vector2d& xy) {
  const Eigen::Vector2d ll = frame.toLatLon(xy);
  return {roundToDeg8(ll.y()), roundToDeg8(ll.x())};
}

double deg(double rad) { return roundToDeg8(rad); }

nlohmann::json reasonJson(const Reason& r, const maps::GpsTime& dep) {
  json j;
  j["kind"] = r.kind;
  j["subject"] = r.subject;
  j["message"] = r.message;
  if (r.t_s) j["time"] = maps::formatRfc3339(dep.plus(*r.t_s), 1);
  if (r.lat_rad) j["lat"] = deg(*r.lat_rad);
  if (r.lon_rad) j["lon"] = deg(*r.lon_rad);
  if (r.h_ell_m) j["h_ell_m"] = roundToMm(*r.h_ell_m);
  if (r.value_m) j["value_m"] = roundToMm(*r.value_m);
  if (r.limit_m) j["limit_m"] = roundToMm(*r.limit_m);
  return j;
}

json routeJson(const ApprovalReport& r) {
  json route = json::array();
  for (const RoutePoint& p : r.route) {
    route.push_back({{"lat", deg(p.lat_rad)},
                     {"lon", deg(p.lon_rad)},
                     {"h_ell_m", roundToMm(p.h_ell_m)},
                     {"alt_amsl_m", roundToMm(p.alt_amsl_m)},
                     {"eta", maps::formatRfc3339(r.departure.plus(p.eta_s), 1)},
                     {"eta_s", roundToMm(p.eta_s)}});
    if (p.hover_s > 0.0) route.back()["hover_s"] = roundToMm(p.hover_s);  // written only where it hovers
  }
  return route;
}

/// One predicted sample with its levels, the alert limits and the airspace margins.
json predictedSampleJson(const PredictedSample& s, const ApprovalReport& r) {
  json p{{"time", maps::formatRfc3339(r.departure.plus(s.t_s), 1)},
         {"lat", deg(s.lat_rad)},
         {"lon", deg(s.lon_rad)},
         {"h_ell_m", roundToMm(s.h_ell_m)},
         {"satellites", s.satellites},
         {"blocked", s.blocked},
         {"hpl_m", s.pl_available ? json(roundToMm(s.hpl_m)) : json(nullptr)},
         {"vpl_m", s.pl_available ? json(roundToMm(s.vpl_m)) : json(nullptr)},
         {"hal1_m", roundToMm(r.limits.level1.hal_m)},
         {"val1_m", roundToMm(r.limits.level1.val_m)},
         {"hal2_m", roundToMm(r.limits.level2.hal_m)},
         {"val2_m", roundToMm(r.limits.level2.val_m)}};
  if (s.three_hypothesis_hpl_m) p["three_hypothesis_hpl_m"] = roundToMm(*s.three_hypothesis_hpl_m);
  if (s.three_hypothesis_vpl_m) p["three_hypothesis_vpl_m"] = roundToMm(*s.three_hypothesis_vpl_m);
  for (const geofence::Check& c : s.fence.checks) {
    // The sample shows the level-2 check's margins (geofence/verdict_json.hpp's form).
    if (c.level == geofence::Level::kAirspace) p.update(geofence::pickMembers(json(c), {"margin_h_m", "margin_v_m"}));
  }
  return p;
}

/// The navigation the PLs were predicted for (the mission's `navigation` block).
json navigationJson(const NavigationModel& n) {
  json j{{"kind", navigationKindName(n.kind)}};
  if (n.kind == NavigationKind::kGnssIns) j["imu"] = std::string(integrity::ins::imuGradeName(n.imu));
  if (n.kind == NavigationKind::kReceiver) {
    j["hpl_m"] = roundToMm(n.hpl_m);
    j["vpl_m"] = roundToMm(n.vpl_m);
  }
  return j;
}

/// One level's availability over the route's samples, with its worst stretch (null: none fails).
json availabilityJson(const LevelAvailability& a, int level, const maps::GpsTime& dep) {
  json j{{"level", level},
         {"hal_m", roundToMm(a.limits.hal_m)},
         {"val_m", roundToMm(a.limits.val_m)},
         {"samples", a.samples},
         {"held", a.held},
         {"fraction", std::round(a.fraction * 1e6) / 1e6},
         {"worst_stretch", nullptr}};
  if (const auto& w = a.worst_stretch) {
    j["worst_stretch"] = {{"samples", w->samples},
                          {"start", maps::formatRfc3339(dep.plus(w->t_start_s), 1)},
                          {"end", maps::formatRfc3339(dep.plus(w->t_end_s), 1)},
                          {"start_t_s", roundToMm(w->t_start_s)},
                          {"end_t_s", roundToMm(w->t_end_s)},
                          {"duration_s", roundToMm(w->duration_s())},
                          {"start_lat", deg(w->lat_start_rad)},
                          {"start_lon", deg(w->lon_start_rad)},
                          {"end_lat", deg(w->lat_end_rad)},
                          {"end_lon", deg(w->lon_end_rad)}};
  }
  return j;
}

std::string metres(double v) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << v << " m";
  return s.str();
}

json zonesJson(const ApprovalReport& r) {
  json zones = json::array();
  for (const ZoneApproach& z : r.zones) {
    zones.push_back({{"id", z.identifier}, {"restriction", z.restriction}, {"counted", z.counted},
                     {"min_clearance_m", roundToMm(z.min_clearance_m)}});
  }
  return zones;
}

json plannerJson(const ApprovalReport& r) {
  json j = {{"algorithm", r.planner.algorithm},
          {"status", r.planner.status},
          {"straight_line", r.planner.straight_line},
          {"planning_time_s", std::round(r.planner.planning_time_s * 1e4) / 1e4},
          {"length_m", roundToMm(r.planner.length_m)},
          {"attempts", r.planner.attempts},
          {"iterations", r.planner.iterations},
          {"stopped_by_time", r.planner.stopped_by_time},
          {"departures_tried", r.planner.departures_tried},
          {"seed", r.mission.seed}};
  // Only when some leg searched the lattice seed (planner/lattice_search.hpp): reports of routes
  // the OMPL search found read as before.
  if (r.planner.lattice_legs_searched > 0) {
    j["lattice"] = {{"legs_searched", r.planner.lattice_legs_searched},
                    {"legs_seeded", r.planner.lattice_legs_seeded},
                    {"state_checks", r.planner.lattice_state_checks},
                    {"last_step_m", r.planner.lattice_step_m}};
  }
  return j;
}

/// The inputs' digests: the approval can be audited and replayed against exactly these files.
json inputsJson(const MissionRecord& m) {
  json inputs = json::array();
  for (const InputDigest& d : m.inputs) inputs.push_back({{"role", d.role}, {"file", d.file}, {"sha256", d.sha256}});
  return inputs;
}

}  // namespace

void to_json(nlohmann::json& j, const ApprovalReport& r) {
  const MissionRecord& m = r.mission;
  j = json::object();
  j["mission"] = m.name;
  j["source"] = m.source;
  if (!m.source_absolute.empty()) j["source_absolute"] = m.source_absolute;
  j["decision"] = r.approved ? "approved" : "rejected";
  j["reasons"] = json::array();
  for (const Reason& x : r.reasons) j["reasons"].push_back(reasonJson(x, r.departure));
  if (!r.warnings.empty()) j["warnings"] = r.warnings;  // absent when none
  j["departure"] = maps::formatRfc3339(r.departure);
  if (r.earliest_passing_departure) j["earliest_passing_departure"] = maps::formatRfc3339(*r.earliest_passing_departure);
  j["route"] = routeJson(r);
  j["corridor"] = {{"level", 1}, {"hal_m", roundToMm(r.limits.level1.hal_m)}, {"val_m", roundToMm(r.limits.level1.val_m)},
                   {"k", m.k1}, {"centre_line", "route"}};
  j["airspace"] = {{"level", 2}, {"hal_m", roundToMm(r.limits.level2.hal_m)}, {"val_m", roundToMm(r.limits.level2.val_m)},
                   {"k", m.k2}, {"centre_line", "route"}};
  json predicted = json::array();
  for (const PredictedSample& s : r.predicted) predicted.push_back(predictedSampleJson(s, r));
  j["predicted"] = predicted;
  j["level1_exceedances"] = r.level1_exceedances;
  j["navigation"] = navigationJson(m.navigation);
  if (m.policy.min_level1_availability) {
    j["policy"] = {{"min_level1_availability", *m.policy.min_level1_availability}};
  }
  j["availability"] = {{"level1", availabilityJson(r.level1_availability, 1, r.departure)},
                       {"level2", availabilityJson(r.level2_availability, 2, r.departure)}};
  j["summary"] = approvalSummary(r);
  j["zones"] = zonesJson(r);
  j["planner"] = plannerJson(r);
  j["elapsed_s"] = std::round(r.elapsed_s * 1e3) / 1e3;
  j["inputs"] = inputsJson(m);
  j["software"] = {{"name", "skylane"}, {"planner_seed", m.seed}};
}

std::string availabilityPercent(double fraction) {
  const double v = 100.0 * fraction;
  std::ostringstream s;
  s.setf(std::ios::fixed);
  const double whole = std::round(v);
  if (fraction <= 0.0 || fraction >= 1.0 || (whole > 0.0 && whole < 100.0)) {
    s.precision(0);
    s << (fraction <= 0.0 ? 0.0 : fraction >= 1.0 ? 100.0 : whole);
  } else {
    s.precision(1);
    s << (whole >= 100.0 ? std::floor(v * 10.0) / 10.0 : std::ceil(v * 10.0) / 10.0);
  }
  s << " %";
  return s.str();
}

std::string approvalSummary(const ApprovalReport& r) {
  std::string line = r.approved ? "APPROVED" : "REJECTED";
  if (!r.approved && !r.reasons.empty()) line += " — " + r.reasons.front().message;
  if (r.predicted.empty()) return line;  // no route was timed: nothing was predicted
  const LevelAvailability& a = r.level1_availability;
  line += std::string(r.approved ? " — " : "; ") + "corridor ±" + metres(a.limits.hal_m) + " / ±" + metres(a.limits.val_m) +
          " held at " + availabilityPercent(a.fraction) + " of samples";
  if (a.held == a.samples) return line;
  if (a.held == 0) return line + ": expect a monitoring rerun at every fix";
  line += ": expect monitoring reruns";
  if (const auto& w = a.worst_stretch) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(0);
    s << ", the longest for " << w->samples << " samples (" << w->duration_s() << " s) from t+" << w->t_start_s << " s";
    line += s.str();
  }
  return line;
}

std::vector<Eigen::Vector2d> segmentOutline(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double hal_m) {
  Eigen::Vector2d d = (b - a).head<2>();
  const double len = d.norm();
  d = len > 1e-9 ? Eigen::Vector2d(d / len) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d n(-d.y(), d.x());
  const Eigen::Vector2d p0 = a.head<2>() - d * hal_m, p1 = b.head<2>() + d * hal_m;
  return {p0 - n * hal_m, p1 - n * hal_m, p1 + n * hal_m, p0 + n * hal_m};
}

namespace {

/// What a route's GeoJSON is made of: an approval's report or a tracked flight's current route.
struct RouteDrawing {
  const std::vector<RoutePoint>& route;
  maps::GpsTime departure;
  const geofence::AlertLimits& level1;
  const geofence::AlertLimits& level2;
  nlohmann::json header;  ///< the route feature's properties
  bool has_xyz = false;   ///< the points' map positions are set (a report's); else taken from lat/lon
};

/// The route line and its points.
void addRouteLine(const RouteDrawing& d, nlohmann::json& features) {
  using nlohmann::json;
  json line = json::array();
  for (const RoutePoint& p : d.route) line.push_back({deg(p.lon_rad), deg(p.lat_rad), roundToMm(p.alt_amsl_m)});
  features.push_back({{"type", "Feature"}, {"geometry", {{"type", "LineString"}, {"coordinates", line}}}, {"properties", d.header}});
  for (std::size_t i = 0; i < d.route.size(); ++i) {
    const RoutePoint& p = d.route[i];
    features.push_back(
        {{"type", "Feature"},
         {"geometry", {{"type", "Point"}, {"coordinates", {deg(p.lon_rad), deg(p.lat_rad), roundToMm(p.alt_amsl_m)}}}},
         {"properties",
          {{"kind", "route_point"}, {"index", i}, {"eta", maps::formatRfc3339(d.departure.plus(p.eta_s), 1)},
           {"h_ell_m", roundToMm(p.h_ell_m)}, {"alt_amsl_m", roundToMm(p.alt_amsl_m)}}}});
  }
}

/// Both box levels, one polygon per segment (positions taken into the map frame from lat/lon).
void addRouteBoxes(const RouteDrawing& d, const maps::PlaneFrame& frame, nlohmann::json& features) {
  using nlohmann::json;
  for (int level : {2, 1}) {
    const geofence::AlertLimits& lim = level == 1 ? d.level1 : d.level2;
    for (std::size_t i = 1; i < d.route.size(); ++i) {
      const RoutePoint &a = d.route[i - 1], &b = d.route[i];
      const Eigen::Vector2d pa = d.has_xyz ? Eigen::Vector2d(a.xyz.head<2>()) : frame.toPlane(a.lat_rad, a.lon_rad);
      const Eigen::Vector2d pb = d.has_xyz ? Eigen::Vector2d(b.xyz.head<2>()) : frame.toPlane(b.lat_rad, b.lon_rad);
      json ring = json::array();
      for (const Eigen::Vector2d& v : segmentOutline({pa.x(), pa.y(), 0.0}, {pb.x(), pb.y(), 0.0}, lim.hal_m)) ring.push_back(lonLat(frame, v));
      ring.push_back(ring.front());
      features.push_back({{"type", "Feature"},
                          {"geometry", {{"type", "Polygon"}, {"coordinates", {ring}}}},
                          {"properties",
                           {{"kind", level == 1 ? "corridor" : "airspace"},
                            {"level", level},
                            {"segment", i - 1},
                            {"hal_m", roundToMm(lim.hal_m)},
                            {"val_m", roundToMm(lim.val_m)},
                            {"h_ell_lower_m", roundToMm(std::min(a.h_ell_m, b.h_ell_m) - lim.val_m)},
                            {"h_ell_upper_m", roundToMm(std::max(a.h_ell_m, b.h_ell_m) + lim.val_m)}}}});
    }
  }
}

nlohmann::json routeHeader(const Mission& mission, bool approved, const maps::GpsTime& departure) {
  nlohmann::json h = {{"kind", "route"},
                      {"mission", mission.name},
                      {"decision", approved ? "approved" : "rejected"},
                      {"departure", maps::formatRfc3339(departure)},
                      {"heights", "AMSL (EGM96) metres"}};
  if (mission.terrain_file.empty()) h["ground_amsl_m"] = roundToMm(mission.ground_amsl_m);
  return h;
}

}  // namespace

nlohmann::json routeGeoJson(const ApprovalReport& report, const Mission& mission, const maps::PlaneFrame& frame) {
  using nlohmann::json;
  json features = json::array();
  const RouteDrawing d{report.route, report.departure, report.limits.level1, report.limits.level2,
                       routeHeader(mission, report.approved, report.departure), true};
  addRouteLine(d, features);
  addRouteBoxes(d, frame, features);
  for (const Reason& r : report.reasons) {
    if (!r.lat_rad || !r.lon_rad) continue;
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "Point"}, {"coordinates", {deg(*r.lon_rad), deg(*r.lat_rad)}}}},
                        {"properties", {{"kind", "reason"}, {"reason", r.kind}, {"subject", r.subject}, {"message", r.message}}}});
  }
  return {{"type", "FeatureCollection"}, {"features", features}};
}

nlohmann::json routeGeoJson(const ApprovedFlight& flight, const Mission& mission, const maps::PlaneFrame& frame) {
  nlohmann::json features = nlohmann::json::array();
  const RouteDrawing d{flight.route, flight.departure, flight.level1, flight.level2, routeHeader(mission, flight.approved, flight.departure)};
  addRouteLine(d, features);
  addRouteBoxes(d, frame, features);
  return {{"type", "FeatureCollection"}, {"features", features}};
}

void from_json(const nlohmann::json& j, ApprovedFlight& f) { f = parseApprovalReport(j, "approval report"); }

ApprovedFlight parseApprovalReport(const nlohmann::json& doc, const std::string& source) {
  const maps::JsonNode root{doc, "$", source};
  if (!doc.is_object()) root.fail("an approval report (a JSON object written by skylane approve)");
  ApprovedFlight f;
  f.report_source = source;
  f.mission_name = root.has("mission") ? root.at("mission").str() : std::string();
  f.mission_source = root.at("source").str();
  if (root.has("source_absolute")) f.mission_source_absolute = root.at("source_absolute").str();
  const std::string decision = root.at("decision").str();
  if (decision != "approved" && decision != "rejected") root.at("decision").fail("\"approved\" or \"rejected\"");
  f.approved = decision == "approved";
  const auto time = [](const maps::JsonNode& n) {
    const auto t = maps::parseRfc3339(n.str());
    if (!t) n.fail("an RFC 3339 date-time");
    return *t;
  };
  f.departure = time(root.at("departure"));
  const maps::JsonNode route = root.at("route");
  if (route.array().size() < 2) route.fail("a route of at least 2 points");
  for (std::size_t i = 0; i < route.j.size(); ++i) {
    const maps::JsonNode p = route.item(i);
    RoutePoint rp;
    const double lat = p.at("lat").number(), lon = p.at("lon").number();
    if (std::abs(lat) > 90.0) p.at("lat").fail("a latitude in [-90, 90] degrees");
    if (std::abs(lon) > 180.0) p.at("lon").fail("a longitude in [-180, 180] degrees");
    rp.lat_rad = maps::deg2rad(lat);
    rp.lon_rad = maps::deg2rad(lon);
    rp.h_ell_m = p.at("h_ell_m").number();
    rp.alt_amsl_m = p.has("alt_amsl_m") ? p.at("alt_amsl_m").number() : rp.h_ell_m;
    rp.eta_s = p.at("eta_s").number();
    if (!f.route.empty() && rp.eta_s < f.route.back().eta_s + f.route.back().hover_s) {
      p.at("eta_s").fail("an ETA not before the previous point's departure (its ETA plus its hover)");
    }
    rp.hover_s = p.has("hover_s") ? p.at("hover_s").number() : 0.0;
    if (!(rp.hover_s >= 0.0)) p.at("hover_s").fail("a hover time ≥ 0 s");
    f.route.push_back(rp);
  }
  const auto limits = [](const maps::JsonNode& n) {
    geofence::AlertLimits l;
    l.hal_m = n.at("hal_m").number();
    l.val_m = n.at("val_m").number();
    if (!(l.hal_m > 0.0)) n.at("hal_m").fail("an alert limit > 0 m");
    if (!(l.val_m > 0.0)) n.at("val_m").fail("an alert limit > 0 m");
    return l;
  };
  f.level1 = limits(root.at("corridor"));
  f.level2 = limits(root.at("airspace"));
  if (root.has("inputs")) {
    const maps::JsonNode inputs = root.at("inputs");
    for (std::size_t i = 0; i < inputs.array().size(); ++i) {
      const maps::JsonNode in = inputs.item(i);
      if (in.has("role") && in.at("role").str() == "mission" && in.has("sha256")) f.mission_sha256 = in.at("sha256").str();
    }
  }
  return f;
}


}  // namespace skylane::planner
