/// \file
/// \brief libFuzzer target for the mission file of `skylane approve` (planner/mission.hpp):
/// every input is parsed twice, as a QGroundControl .plan (`parseQgcPlanRoute`) and as a
/// mission file (`parseMission`). Syntax errors are nlohmann's business and skipped.
///
/// A mission's `qgc_plan` is not read from disk (a fuzzed name could be /dev/zero): the reader
/// hands back one of a few fixed plans chosen by the name's ending — "rtl.plan" a return to
/// launch with mixed heights, "survey.plan" a plan with a ComplexItem (refused), "gone.plan" the
/// error of an unreadable file, "timed.plan" a speed change, a delay, a timed loiter and a
/// geofence, anything else three waypoints at 70 m relative to home — so the
/// mission's own checks around the plan (either route, the cruise height against the limits,
/// an unreadable plan) are reached. A ParseError must name the mission ("fuzz.json") or, for
/// an error inside the plan, the plan's resolved path.
///
/// A route that parses has ≥ 2 points, finite, within ±89° latitude and ±180° longitude (in
/// radians), no two consecutive ones equal in place and height, one flight per point (a finite
/// height with its field named; a leg speed 0 < v ≤ kMaxPlanSpeed_mps with its field named; a
/// hover ≥ 0 and finite), and a finite cruise height with its field named exactly when there is
/// one. A mission that parses has all that, plus: positive speeds and
/// vehicle sizes, min_agl ≤ cruise_agl ≤ max_agl with cruise_agl > 0, every number finite, the
/// latest departure not before the earliest, a positive departure step, sample step, cost
/// cell, time limit, resolution and margin, a cost weight ≥ 0, 0–20 replans and at least one
/// orbit file; its plan file is the one the reader was asked for, its point flights are the
/// plan's (none without a plan), and the plan is among the zone files at most once.

#include "fuzz/fuzz_common.hpp"
#include "planner/mission.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace {

using namespace skylane;
using nlohmann::json;

/// The latitude limit of mission points, in radians (89°).
const double kMaxLatitude_rad = maps::deg2rad(89.0);

json simpleItem(int command, int frame, double lat, double lon, double alt) {
  return {{"type", "SimpleItem"}, {"command", command}, {"frame", frame}, {"params", {0, 0, 0, nullptr, lat, lon, alt}}};
}

json planWith(const json& items) {
  return {{"fileType", "Plan"}, {"mission", {{"items", items}, {"plannedHomePosition", {47.3712, 8.532, 408}}}}};
}

/// The plan a mission's qgc_plan stands for (see the file comment).
json planFor(const std::string& path) {
  const auto endsWith = [&](const std::string& tail) {
    return path.size() >= tail.size() && path.compare(path.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (endsWith("gone.plan")) throw maps::ParseError(path, 0, "file", "", "a readable file");
  if (endsWith("rtl.plan")) {
    return planWith({simpleItem(22, 3, 47.3715, 8.5325, 30), simpleItem(16, 3, 47.375, 8.54, 50),
                     simpleItem(16, 0, 47.38, 8.548, 470), simpleItem(20, 2, 0, 0, 0)});
  }
  if (endsWith("timed.plan")) {
    json plan = planWith({simpleItem(22, 3, 47.3715, 8.5325, 40), simpleItem(178, 2, 0, 0, 0),
                          simpleItem(16, 3, 47.375, 8.54, 60), simpleItem(93, 2, 0, 0, 0),
                          simpleItem(19, 10, 47.38, 8.548, 80), simpleItem(21, 3, 0, 0, 0)});
    json& items = plan["mission"]["items"];
    items[1]["params"][0] = 1;   // DO_CHANGE_SPEED: ground speed
    items[1]["params"][1] = 6;   // 6 m/s
    items[3]["params"][0] = 20;  // NAV_DELAY 20 s
    items[4]["params"][0] = 30;  // NAV_LOITER_TIME 30 s
    const json circle = {{"inclusion", false}, {"circle", {{"center", {47.376, 8.545}}, {"radius", 50}}}};
    plan["geoFence"] = {{"circles", json::array({circle})}};
    return plan;
  }
  if (endsWith("survey.plan")) {
    return planWith({simpleItem(16, 3, 47.375, 8.54, 70), {{"type", "ComplexItem"}, {"complexItemType", "survey"}}});
  }
  return planWith({simpleItem(16, 3, 47.375, 8.54, 70), simpleItem(16, 3, 47.38, 8.548, 70),
                   simpleItem(16, 3, 47.383, 8.553, 70)});
}

void checkPoints(const std::vector<planner::MissionPoint>& points, const std::string& source) {
  SKYLANE_FUZZ_CHECK(points.size() >= 2, source);
  for (const planner::MissionPoint& p : points) {
    SKYLANE_FUZZ_CHECK(std::isfinite(p.lat_rad) && std::isfinite(p.lon_rad), source);
    SKYLANE_FUZZ_CHECK(std::abs(p.lat_rad) <= kMaxLatitude_rad && std::abs(p.lon_rad) <= M_PI, source);
  }
}

void checkFlight(const planner::PointFlight& f, const std::string& source) {
  SKYLANE_FUZZ_CHECK(!f.height || (std::isfinite(f.height->value_m) && !f.height->field.empty()), source);
  SKYLANE_FUZZ_CHECK(!f.speed_mps || (*f.speed_mps > 0 && *f.speed_mps <= planner::kMaxPlanSpeed_mps), source);
  SKYLANE_FUZZ_CHECK(f.speed_mps.has_value() == !f.speed_field.empty(), source);
  SKYLANE_FUZZ_CHECK(f.hover_s >= 0 && std::isfinite(f.hover_s), source);
}

bool sameHeight(const std::optional<planner::PointHeight>& a, const std::optional<planner::PointHeight>& b) {
  if (!a || !b) return !a && !b;
  return a->reference == b->reference && a->value_m == b->value_m;
}

void checkRoute(const planner::QgcPlanRoute& r, const std::string& source) {
  checkPoints(r.points, source);
  SKYLANE_FUZZ_CHECK(r.flights.size() == r.points.size(), source);
  for (const planner::PointFlight& f : r.flights) checkFlight(f, source);
  for (std::size_t i = 1; i < r.points.size(); ++i) {
    const bool same_place =
        r.points[i].lat_rad == r.points[i - 1].lat_rad && r.points[i].lon_rad == r.points[i - 1].lon_rad;
    SKYLANE_FUZZ_CHECK(!same_place || !sameHeight(r.flights[i].height, r.flights[i - 1].height),
                       source + ": point " + std::to_string(i) + " repeats the one before");
  }
  SKYLANE_FUZZ_CHECK(!r.cruise_agl_m || std::isfinite(*r.cruise_agl_m), source);
  SKYLANE_FUZZ_CHECK(r.cruise_agl_m.has_value() == !r.cruise_agl_field.empty(), source);
}

void checkMission(const planner::Mission& m, const std::string& source, const std::string& plan_path) {
  checkPoints(m.points, source);
  SKYLANE_FUZZ_CHECK(m.qgc_plan_file == plan_path, source + ": plan file '" + m.qgc_plan_file + "'");
  SKYLANE_FUZZ_CHECK(m.point_flights.size() == (plan_path.empty() ? 0u : m.points.size()), source);
  SKYLANE_FUZZ_CHECK(plan_path.empty() || std::count(m.zone_files.begin(), m.zone_files.end(), plan_path) <= 1, source);
  SKYLANE_FUZZ_CHECK(m.vehicle.lateral_m > 0 && m.vehicle.longitudinal_m > 0 && m.vehicle.height_m >= 0, source);
  SKYLANE_FUZZ_CHECK(std::isfinite(m.vehicle.lateral_m) && std::isfinite(m.vehicle.longitudinal_m) &&
                         std::isfinite(m.vehicle.height_m),
                     source);
  SKYLANE_FUZZ_CHECK(m.cruise_speed_mps > 0 && std::isfinite(m.cruise_speed_mps), source);
  SKYLANE_FUZZ_CHECK(m.climb_speed_mps > 0 && std::isfinite(m.climb_speed_mps), source);
  SKYLANE_FUZZ_CHECK(std::isfinite(m.levels.k1) && std::isfinite(m.levels.k2), source);
  SKYLANE_FUZZ_CHECK(std::isfinite(m.min_agl_m) && std::isfinite(m.max_agl_m) && std::isfinite(m.cruise_agl_m), source);
  SKYLANE_FUZZ_CHECK(m.cruise_agl_m > 0 && m.min_agl_m <= m.cruise_agl_m && m.cruise_agl_m <= m.max_agl_m,
                     source + ": " + std::to_string(m.min_agl_m) + " ≤ " + std::to_string(m.cruise_agl_m) + " ≤ " +
                         std::to_string(m.max_agl_m));
  SKYLANE_FUZZ_CHECK(!m.max_amsl_m || std::isfinite(*m.max_amsl_m), source);
  const double window_s = m.departure_latest - m.departure_earliest;
  SKYLANE_FUZZ_CHECK(std::isfinite(window_s) && window_s >= 0, source);
  SKYLANE_FUZZ_CHECK(m.departure_step_s > 0 && std::isfinite(m.departure_step_s), source);
  SKYLANE_FUZZ_CHECK(std::isfinite(m.ground_amsl_m) && std::isfinite(m.mask_deg), source);
  SKYLANE_FUZZ_CHECK(m.sample_s > 0 && std::isfinite(m.sample_s), source);
  SKYLANE_FUZZ_CHECK(m.cost_weight >= 0 && std::isfinite(m.cost_weight), source);
  SKYLANE_FUZZ_CHECK(m.cost_cell_m > 0 && std::isfinite(m.cost_cell_m), source);
  SKYLANE_FUZZ_CHECK(m.time_limit_s > 0 && std::isfinite(m.time_limit_s), source);
  SKYLANE_FUZZ_CHECK(m.resolution_m > 0 && std::isfinite(m.resolution_m), source);
  SKYLANE_FUZZ_CHECK(m.margin_m > 0 && std::isfinite(m.margin_m), source);
  SKYLANE_FUZZ_CHECK(m.max_replans >= 0 && m.max_replans <= 20, source);
  SKYLANE_FUZZ_CHECK(!m.orbit_files.empty(), source);
  fuzz::keepAlive(m.levels.k1 + m.levels.k2 + window_s);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const json doc = json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return 0;

  // As a QGroundControl .plan.
  const std::string plan_source = "fuzz.plan";
  fuzz::parseThenUse(plan_source, [&] { return planner::parseQgcPlanRoute(doc, plan_source); },
                     [&](const planner::QgcPlanRoute& r) { checkRoute(r, plan_source); });

  // As a mission file (its plan, if any, from planFor).
  const std::string source = "fuzz.json";
  std::string plan_path;
  const planner::JsonFileReader reader = [&](const std::string& path) {
    plan_path = path;
    return planFor(path);
  };
  std::optional<planner::Mission> mission;
  try {
    mission.emplace(planner::parseMission(doc, source, ".", reader));
  } catch (const integrity::ParseError& e) {
    fuzz::checkParseError(e, !plan_path.empty() && e.source() == plan_path ? plan_path : source);
    return 0;
  }
  checkMission(*mission, source, plan_path);
  return 0;
}
