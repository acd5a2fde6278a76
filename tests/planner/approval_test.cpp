// Route planning and preflight approval (issue 7): OMPL paths in the mission frame, zones in
// space and time, rejections with reasons, reproducibility, and corridors that never meet an
// active prohibited zone (checked independently of the geofence).
#include "planner/approval.hpp"
#include "planner/operational_intent.hpp"
#include "planner/report_formats.hpp"
#include "planner/route_planner.hpp"

#include "geofence/fence.hpp"
#include "integrity/gnss/almanac.hpp"
#include "integrity/predict.hpp"
#include "maps/buildings.hpp"
#include "maps/sky_mask.hpp"
#include "maps/terrain.hpp"
#include "maps/parse_error.hpp"
#include "tests/test_util.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

namespace skylane::planner {
namespace {

using nlohmann::json;

// --- planPath on its own ---------------------------------------------------------------------

PathProblem openBox() {
  PathProblem p;
  p.lower_enu_m = Eigen::Vector3d(-100, -300, 0);
  p.upper_enu_m = Eigen::Vector3d(1100, 300, 100);
  p.start_enu_m = Eigen::Vector3d(0, 0, 50);
  p.goal_enu_m = Eigen::Vector3d(1000, 0, 50);
  p.resolution_m = 1.0;
  p.time_limit_s = 10.0;  // a safety net: the iteration budget ends the search (reproducible)
  p.max_iterations = 1500;
  return p;
}

/// A vertical cylinder of radius 150 m across the straight line.
bool outsidePillar(const Eigen::Vector3d& x) { return (x.head<2>() - Eigen::Vector2d(500, 0)).norm() > 150.0; }

TEST(PlannerPath, StraightLineWhenNothingIsInTheWay) {
  PathProblem p = openBox();
  p.is_valid = [](const Eigen::Vector3d&) { return true; };
  const PathResult r = planPath(p);
  EXPECT_EQ(r.status, PathStatus::kExact);
  EXPECT_TRUE(r.straight_line);
  ASSERT_EQ(r.points.size(), 2u);
  EXPECT_NEAR(r.length_m, 1000.0, 1e-9);
}

TEST(PlannerPath, EveryPlannerBendsAroundAnObstacleAndEveryMotionStaysValid) {
  for (PlannerKind k : {PlannerKind::kRrtStar, PlannerKind::kInformedRrtStar, PlannerKind::kBitStar, PlannerKind::kPrmStar}) {
    PathProblem p = openBox();
    p.is_valid = outsidePillar;
    p.planner = k;
    const PathResult r = planPath(p);
    ASSERT_EQ(r.status, PathStatus::kExact) << plannerName(k);
    EXPECT_FALSE(r.straight_line);
    EXPECT_GE(r.points.size(), 3u) << plannerName(k);
    // The shortest way round: two tangents and an arc, 2·√(500² − 150²) + 150·(π − 2·acos(150/500))·… ≥ 1000.
    const double tangent = std::sqrt(500.0 * 500.0 - 150.0 * 150.0);
    const double arc = 150.0 * (M_PI - 2.0 * std::acos(150.0 / 500.0));
    const double shortest = 2.0 * tangent + arc;
    EXPECT_GE(r.length_m, shortest - 1e-6) << plannerName(k);
    EXPECT_LE(r.length_m, 1.25 * shortest) << plannerName(k);
    EXPECT_TRUE(test::nearVec(r.points.front(), p.start_enu_m, 1e-9));
    EXPECT_TRUE(test::nearVec(r.points.back(), p.goal_enu_m, 1e-6));
    // Simplification never breaks validity: every 0.25 m of the final path is valid.
    for (std::size_t i = 1; i < r.points.size(); ++i) {
      const Eigen::Vector3d a = r.points[i - 1], b = r.points[i];
      const int n = static_cast<int>(std::ceil((b - a).norm() / 0.25));
      for (int s = 0; s <= n; ++s) {
        EXPECT_TRUE(outsidePillar(a + (b - a) * (static_cast<double>(s) / n))) << plannerName(k) << " segment " << i;
      }
    }
  }
}

TEST(PlannerPath, SameSeedSameRouteWithinOneProcess) {
  PathProblem p = openBox();
  p.is_valid = outsidePillar;
  p.seed = 42;
  const PathResult a = planPath(p);
  const PathResult other = [&] {
    PathProblem q = p;
    q.seed = 43;
    return planPath(q);
  }();
  const PathResult b = planPath(p);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) EXPECT_EQ(a.points[i], b.points[i]) << i;
  EXPECT_EQ(other.status, PathStatus::kExact);
}

TEST(PlannerPath, InvalidStartOrGoalIsSaid) {
  PathProblem p = openBox();
  p.is_valid = outsidePillar;
  p.goal_enu_m = Eigen::Vector3d(500, 0, 50);
  EXPECT_EQ(planPath(p).status, PathStatus::kInvalidGoal);
  p.start_enu_m = Eigen::Vector3d(500, 10, 50);
  EXPECT_EQ(planPath(p).status, PathStatus::kInvalidStart);
  p.resolution_m = 0;
  EXPECT_THROW((void)planPath(p), std::invalid_argument);
}

// --- approval -------------------------------------------------------------------------------

constexpr double kLat0 = 47.3712, kLon0 = 8.5320;

json circleZone(const std::string& id, double lat, double lon, double radius_m, const json& applicability) {
  return {{"identifier", id}, {"country", "CHE"}, {"name", id}, {"type", "COMMON"}, {"restriction", "PROHIBITED"},
          {"reason", {"OTHER"}}, {"applicability", applicability},
          {"geometry",
           {{{"uomDimensions", "M"}, {"lowerLimit", 0}, {"lowerVerticalReference", "AGL"}, {"upperLimit", 300},
             {"upperVerticalReference", "AGL"},
             {"horizontalProjection", {{"type", "Circle"}, {"center", {lon, lat}}, {"radius", radius_m}}}}}}};
}

json permanent() { return json::array({{{"permanent", "YES"}}}); }
json during(const std::string& from, const std::string& to) {
  return json::array({{{"permanent", "NO"}, {"startDateTime", from}, {"endDateTime", to}}});
}

/// A mission from (kLat0, kLon0) 1.5 km east, departing 2020-01-01T14:00Z, with these zones.
Mission missionWith(const std::vector<json>& zones, const std::string& name, double goal_dlon = 0.0198) {
  json z{{"formatVersion", "1.0.0"}, {"UASZoneList", zones}};
  const std::string zone_file = test::scratchPath(name + "_zones.json");
  std::ofstream(zone_file) << z.dump();
  json m{{"name", name},
         {"vehicle", {{"lateral_m", 1.2}, {"longitudinal_m", 1.0}, {"cruise_speed_mps", 12}}},
         {"k1", 1.2},
         {"k2", 150},
         {"start", {{"lat", kLat0}, {"lon", kLon0}}},
         {"goal", {{"lat", kLat0}, {"lon", kLon0 + goal_dlon}}},
         {"departure", "2020-01-01T14:00:00Z"},
         {"zones", {zone_file}},
         {"ground_amsl_m", 408},
         {"orbits", {test::dataPath("gnss/alm01jan2020.txt")}},
         {"integrity", {{"cost_weight", 0.0}}},
         {"planner", {{"time_limit_s", 10.0}, {"iterations", 600}, {"seed", 3}}}};
  return parseMission(m, name + ".json", ".");
}

double minDistanceToCentre(const ApprovalReport& r, const Eigen::Vector2d& centre) {
  double best = 1e300;
  for (const PredictedSample& s : r.predicted) best = std::min(best, (s.xyz.head<2>() - centre).norm());
  return best;
}

TEST(Approval, ClearRouteIsApprovedAsTheStraightLine) {
  Approver a(missionWith({}, "clear"));
  const ApprovalReport r = a.approve();
  ASSERT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
  EXPECT_TRUE(r.planner.straight_line);
  ASSERT_EQ(r.route.size(), 2u);
  // 1.5 km at 12 m/s: ETA at the goal from the route's own length.
  EXPECT_NEAR(r.route.back().eta_s, r.planner.length_m / 12.0, 1e-6);
  EXPECT_NEAR(r.planner.length_m, 1498.0, 5.0);
  // One sample per second plus the end, each with a PL inside level 2.
  EXPECT_EQ(r.predicted.size(), static_cast<std::size_t>(std::floor(r.route.back().eta_s)) + 2);
  for (const PredictedSample& s : r.predicted) {
    EXPECT_TRUE(s.pl_available);
    EXPECT_LE(s.hpl_m, r.limits.level2.hal_m);
  }
  EXPECT_NEAR(r.limits.level1.hal_m, 1.44, 1e-12);  // k₁ · lateral
  EXPECT_NEAR(r.limits.level2.val_m, 150.0, 1e-12);  // k₂ · longitudinal
}

TEST(Approval, IntegrityFdePredictsThePlsOfAReceiverThatExcludes) {
  // GIVEN the clear route, detection-only PLs and those of a receiver that excludes
  const ApprovalReport plain = Approver(missionWith({}, "clear_fd")).approve();
  Mission m = missionWith({}, "clear_fde");
  m.with_exclusion = true;
  const ApprovalReport fde = Approver(m).approve();
  ASSERT_EQ(plain.predicted.size(), fde.predicted.size());
  // THEN every sample's PL is the larger: the budget is shared among the exclusion outcomes
  for (std::size_t k = 0; k < plain.predicted.size(); ++k) {
    ASSERT_TRUE(plain.predicted[k].pl_available && fde.predicted[k].pl_available) << k;
    EXPECT_GT(fde.predicted[k].hpl_m, plain.predicted[k].hpl_m) << k;
    EXPECT_GT(fde.predicted[k].vpl_m, plain.predicted[k].vpl_m) << k;
  }
}

TEST(Approval, GoalInsideAProhibitedZoneIsRejectedWithItsIdentifier) {
  const double goal_lon = kLon0 + 0.0198;
  Approver a(missionWith({circleZone("EX-TEST-GOAL", kLat0, goal_lon, 100, permanent())}, "goal_in_zone"));
  const ApprovalReport r = a.approve();
  EXPECT_FALSE(r.approved);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_EQ(r.reasons.front().kind, "zone");
  EXPECT_EQ(r.reasons.front().subject, "EX-TEST-GOAL");
  EXPECT_NE(r.reasons.front().message.find("goal"), std::string::npos) << r.reasons.front().message;
}

TEST(Approval, RouteBendsAroundAProhibitedZoneOnTheDirectLine) {
  const double mid_lon = kLon0 + 0.0099;
  Approver a(missionWith({circleZone("EX-TEST-MID", kLat0, mid_lon, 150, permanent())}, "bend"));
  const ApprovalReport r = a.approve();
  ASSERT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
  EXPECT_FALSE(r.planner.straight_line);
  EXPECT_GT(r.route.size(), 2u);
  EXPECT_GT(r.planner.length_m, 1498.0 + 10.0);
  ASSERT_FALSE(r.zones.empty());
  EXPECT_EQ(r.zones.front().identifier, "EX-TEST-MID");
  EXPECT_GT(r.zones.front().min_clearance_m, 0.0);
}

TEST(Approval, ZoneActiveAtArrivalIsAvoidedAndOneExpiredBeforeArrivalIsNot) {
  const double mid_lon = kLon0 + 0.0099;
  // Active from 14:00:30Z: the vehicle reaches it about a minute after departure.
  Approver active(missionWith({circleZone("EX-TEST-LATER", kLat0, mid_lon, 150,
                                          during("2020-01-01T14:00:30Z", "2020-01-01T15:00:00Z"))},
                              "active_at_arrival"));
  const ApprovalReport ra = active.approve();
  ASSERT_TRUE(ra.approved);
  EXPECT_FALSE(ra.planner.straight_line);
  const maps::PlaneFrame frame(maps::deg2rad(kLat0), maps::deg2rad(kLon0));
  const Eigen::Vector2d centre = frame.toPlane(maps::deg2rad(kLat0), maps::deg2rad(mid_lon));
  EXPECT_GT(minDistanceToCentre(ra, centre), 150.0);
  // Over at 13:50Z, before departure: the straight line is flown through its old outline.
  Approver expired(missionWith({circleZone("EX-TEST-EARLIER", kLat0, mid_lon, 150,
                                           during("2020-01-01T12:00:00Z", "2020-01-01T13:50:00Z"))},
                               "expired"));
  const ApprovalReport re = expired.approve();
  ASSERT_TRUE(re.approved);
  EXPECT_TRUE(re.planner.straight_line);
  EXPECT_LT(minDistanceToCentre(re, centre), 10.0);
}

TEST(Approval, SameSeedSameRoute) {
  const double mid_lon = kLon0 + 0.0099;
  const std::vector<json> zones{circleZone("EX-TEST-MID", kLat0 + 0.0005, mid_lon, 150, permanent())};
  Approver a(missionWith(zones, "seed_a"));
  Approver b(missionWith(zones, "seed_b"));
  const ApprovalReport ra = a.approve(), rb = b.approve();
  ASSERT_EQ(ra.route.size(), rb.route.size());
  for (std::size_t i = 0; i < ra.route.size(); ++i) EXPECT_EQ(ra.route[i].xyz, rb.route[i].xyz) << i;
}

// Random airspaces: an approved route's level-1 corridor (the vehicle box along it) never meets
// a zone active while it is flown. Checked every metre against the circles' own centre and
// radius in the mission plane — an independent computation, not the fence's scene.
TEST(Approval, ApprovedCorridorsNeverMeetAnActiveProhibitedZone) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int approved = 0;
  for (int scene = 0; scene < 8; ++scene) {
    std::vector<json> zones;
    for (int k = 0; k < 6; ++k) {
      const double lat = kLat0 + (u(rng) - 0.5) * 0.006;
      const double lon = kLon0 + 0.003 + u(rng) * 0.014;
      zones.push_back(circleZone("Z" + std::to_string(scene) + "-" + std::to_string(k), lat, lon, 40 + 80 * u(rng), permanent()));
    }
    const std::string name = "random_" + std::to_string(scene);
    Mission m = missionWith(zones, name);
    Approver a(m);
    const ApprovalReport r = a.approve();
    if (!r.approved) continue;
    ++approved;
    // Walk the corridor against the zones as written in the file.
    const maps::PlaneFrame frame(maps::deg2rad(kLat0), maps::deg2rad(kLon0));
    for (std::size_t i = 1; i < r.route.size(); ++i) {
      const Eigen::Vector3d p0 = r.route[i - 1].xyz, p1 = r.route[i].xyz;
      const int n = static_cast<int>(std::ceil((p1 - p0).norm()));
      for (int s = 0; s <= n; ++s) {
        const double f = static_cast<double>(s) / n;
        const Eigen::Vector3d p = p0 + (p1 - p0) * f;
        for (const json& z : zones) {
          const auto& c = z["geometry"][0]["horizontalProjection"]["center"];
          const Eigen::Vector2d centre = frame.toPlane(maps::deg2rad(c[1].get<double>()), maps::deg2rad(c[0].get<double>()));
          const double radius = z["geometry"][0]["horizontalProjection"]["radius"].get<double>();
          EXPECT_GT((p.head<2>() - centre).norm(), radius + r.limits.level1.hal_m - 0.01)
              << name << " segment " << i << " zone " << z["identifier"];
        }
      }
    }
  }
  EXPECT_GE(approved, 5);
}

// An urban canyon: two 300 m walls 40 m apart along the middle of the direct line. Between them
// too few satellites are left for a protection level, so the integrity cost steers the route out
// to open sky (or, failing that, the samples in the canyon would reject it).
TEST(Approval, UrbanCanyonSendsTheRouteToBetterSky) {
  const maps::PlaneFrame frame(maps::deg2rad(kLat0), maps::deg2rad(kLon0));
  auto lonLat = [&frame](double x, double y) {
    const Eigen::Vector2d ll = frame.toLatLon(Eigen::Vector2d(x, y));
    return json::array({maps::rad2deg(ll.y()), maps::rad2deg(ll.x())});
  };
  json features = json::array();
  for (double side : {-1.0, 1.0}) {
    const double y0 = side * 20.0, y1 = side * 35.0;
    json ring = json::array({lonLat(450, y0), lonLat(1050, y0), lonLat(1050, y1), lonLat(450, y1), lonLat(450, y0)});
    features.push_back({{"type", "Feature"}, {"geometry", {{"type", "Polygon"}, {"coordinates", {ring}}}},
                        {"properties", {{"height", 300}}}});
  }
  const std::string buildings = test::scratchPath("canyon.geojson");
  std::ofstream(buildings) << json{{"type", "FeatureCollection"}, {"features", features}}.dump();
  Mission m = missionWith({}, "canyon");
  m.buildings_file = buildings;
  m.cost_weight = 1.0;
  m.cost_cell_m = 10.0;
  Approver a(m);
  const ApprovalReport r = a.approve();
  if (!r.approved) {
    ASSERT_FALSE(r.reasons.empty());
    EXPECT_EQ(r.reasons.front().kind, "integrity") << r.reasons.front().message;
    return;
  }
  // Approved: no sample flies between the walls, and every sample has a protection level.
  for (const PredictedSample& s : r.predicted) {
    EXPECT_FALSE(s.xyz.x() > 450 && s.xyz.x() < 1050 && std::abs(s.xyz.y()) < 20) << "t = " << s.t_s;
    EXPECT_TRUE(s.pl_available) << "t = " << s.t_s;
  }
  EXPECT_FALSE(r.planner.straight_line);
  // Between the walls, at the route's height and time, the sky leaves no protection level
  // (computed here from the buildings directly: sky mask, then the prediction).
  const maps::Terrain ground = maps::Terrain::flat(408.0);
  const std::vector<maps::Building> walls = maps::loadBuildings(buildings, ground);
  const maps::BuildingIndex index(walls, maps::Geodetic{maps::deg2rad(kLat0), maps::deg2rad(kLon0), 0.0});
  const Eigen::Vector2d mid = frame.toLatLon(Eigen::Vector2d(750, 0));
  integrity::PredictRequest req;
  req.place = {mid.x(), mid.y(), r.route.front().h_ell_m};
  maps::SkyMaskOptions opt;
  opt.floor_rad = maps::deg2rad(5.0);
  req.sky_mask = maps::computeSkyMask(req.place, &index, nullptr, opt);
  integrity::OrbitSource orbits;
  orbits.addAlmanac(integrity::loadAlmanac(test::dataPath("gnss/alm01jan2020.txt")));
  const integrity::PredictSample canyon = integrity::predictAt(orbits, req, r.departure.plus(60.0), integrity::IntegrityMethod::kRaim);
  EXPECT_GT(canyon.blocked, 3u);
  EXPECT_TRUE(!canyon.pl.pl_computed || canyon.pl.hpl_m > r.limits.level2.hal_m)
      << canyon.sats.size() << " satellites, HPL " << canyon.pl.hpl_m;
}

// A departure window: the goal lies under a zone until 14:20Z. The 14:00 and 14:10 departures
// cannot end there; the window's 14:20 departure is approved.
TEST(Approval, DepartureWindowFindsTheFirstDepartureThatPasses) {
  const double goal_lon = kLon0 + 0.0198;
  Mission m = missionWith({circleZone("EX-TEST-UNTIL-1420", kLat0, goal_lon, 100,
                                      during("2020-01-01T13:00:00Z", "2020-01-01T14:20:00Z"))},
                          "window");
  m.departure_latest = m.departure_earliest.plus(3600.0);
  m.departure_step_s = 600.0;
  Approver a(m);
  const ApprovalReport r = a.approve();
  ASSERT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
  EXPECT_EQ(maps::formatRfc3339(r.departure), "2020-01-01T14:20:00Z");
  EXPECT_EQ(r.planner.departures_tried, 3);
}

TEST(Approval, AnAlmanacYearsFromTheDepartureIsRefusedBeforePlanning) {
  // GIVEN the 2020 almanac and a departure in 2025
  Mission m = missionWith({}, "old_almanac");
  m.departure_earliest = m.departure_latest = *maps::parseRfc3339("2025-06-01T14:00:00Z");
  Approver a(m);
  // WHEN approving THEN a ParseError names the file, its epoch, the departure, the limit and the age
  const std::string msg = test::messageOf<maps::ParseError>([&] { (void)a.approve(); });
  for (const char* part : {"alm01jan2020.txt: field 'almanac epoch t_oa'", "GPS week 2086, 503808 s",
                           "within 90.0 days of the departure 2025-06-01T14:00:00Z", "1975.", "days from it"}) {
    EXPECT_NE(msg.find(part), std::string::npos) << part << " in: " << msg;
  }
}

TEST(Approval, AnAlmanacTenDaysFromTheDepartureIsAWarningOfTheReport) {
  // GIVEN the almanac of 2020-01-03 and a departure on 2020-01-14 (10.8 days later)
  Mission m = missionWith({}, "week_old_almanac");
  m.departure_earliest = m.departure_latest = *maps::parseRfc3339("2020-01-14T14:00:00Z");
  Approver a(m);
  // WHEN approving THEN the route is judged as usual and the report carries one warning
  const ApprovalReport r = a.approve();
  EXPECT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("alm01jan2020.txt: the almanac's t_oa 2020-01-03T19:56:30Z"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("beyond the 7.0 days warning limit"), std::string::npos) << r.warnings[0];
  const json j = r;
  EXPECT_EQ(j.at("warnings"), json(r.warnings));
  // AND a report without warnings has no "warnings" member (older reports stay as they were)
  EXPECT_FALSE(json(Approver(missionWith({}, "current_almanac")).approve()).contains("warnings"));
}

// --- a QGroundControl plan: speeds, hovers, heights and its geofence -----------------------------

/// A SimpleItem of a .plan: command, frame, the seven parameters.
json planItem(int command, int frame, const json& params) {
  return {{"type", "SimpleItem"}, {"command", command}, {"frame", frame}, {"autoContinue", true}, {"params", params}};
}
json planWaypoint(int command, int frame, double hover_s, double lat, double lon, double alt) {
  return planItem(command, frame, {hover_s, 0, 0, nullptr, lat, lon, alt});
}

/// A plan east of (kLat0, kLon0) with these items and fence, and a mission naming it (ground at
/// 408 m AMSL, cruise 12 m/s).
Mission missionWithPlan(const std::string& name, const std::vector<json>& items, const json& fence,
                        const json& altitude = json::object(), double sample_s = 1.0) {
  const json plan_doc{{"fileType", "Plan"},
                      {"geoFence", fence},
                      {"mission", {{"items", items}, {"plannedHomePosition", {kLat0, kLon0, 408}}}}};
  const std::string plan_file = test::scratchPath(name + ".plan");
  std::ofstream(plan_file) << plan_doc.dump();
  json m{{"name", name},
         {"vehicle", {{"lateral_m", 1.2}, {"longitudinal_m", 1.0}, {"cruise_speed_mps", 12}}},
         {"k1", 1.2},
         {"k2", 150},
         {"qgc_plan", plan_file},
         {"departure", "2020-01-01T14:00:00Z"},
         {"ground_amsl_m", 408},
         {"orbits", {test::dataPath("gnss/alm01jan2020.txt")}},
         {"integrity", {{"cost_weight", 0.0}, {"sample_s", sample_s}}},
         {"planner", {{"time_limit_s", 10.0}, {"iterations", 600}, {"seed", 3}}}};
  if (!altitude.empty()) m["altitude"] = altitude;
  return parseMission(m, name + ".json", ".");
}

json emptyFence() { return {{"circles", json::array()}, {"polygons", json::array()}, {"version", 2}}; }

/// The index of the route point at `p` (map frame); the route's size when none is.
std::size_t routeIndexAt(const ApprovalReport& r, const Eigen::Vector3d& p) {
  for (std::size_t i = 0; i < r.route.size(); ++i) {
    if ((r.route[i].xyz - p).norm() < 1e-6) return i;
  }
  return r.route.size();
}

TEST(Approval, QgcPlanSpeedChangeHoverHeightsAndGeofenceAreFollowed) {
  // GIVEN a plan: takeoff at home to 40 m (relative), a waypoint at 60 m (relative), a speed
  // change to 6 m/s, a 30 s timed loiter at 80 m above terrain, a waypoint at 458 m AMSL (50 m
  // above the 408 m ground), a land there; its fence: an exclusion circle 200 m north of the
  // first waypoint and an inclusion polygon round the route
  const double lon1 = kLon0 + 0.004, lon2 = kLon0 + 0.008, lon3 = kLon0 + 0.012;
  const std::vector<json> items{
      planWaypoint(22, 3, 0, kLat0, kLon0, 40),   planWaypoint(16, 3, 0, kLat0, lon1, 60),
      planItem(178, 2, {1, 6, -1, 0, 0, 0, 0}),   planWaypoint(19, 10, 30, kLat0, lon2, 80),
      planWaypoint(16, 0, 0, kLat0, lon3, 458),   planWaypoint(21, 3, 0, kLat0, lon3, 0)};
  json fence = emptyFence();
  fence["circles"] = {{{"inclusion", false}, {"circle", {{"center", {kLat0 + 0.0018, lon1}}, {"radius", 60}}}, {"version", 1}}};
  fence["polygons"] = {{{"inclusion", true},
                        {"polygon", {{kLat0 + 0.003, kLon0 - 0.002}, {kLat0 + 0.003, lon3 + 0.002},
                                     {kLat0 - 0.003, lon3 + 0.002}, {kLat0 - 0.003, kLon0 - 0.002}}},
                        {"version", 1}}};
  // (Samples every 10 s: a sample at a joint where the height's slope changes costs the level-1
  // corridor's branch and bound most; a hover at one repeats it.)
  const Mission mission = missionWithPlan("qgc_follow", items, fence, json::object(), 10.0);
  // WHEN it is approved
  Approver a(mission);
  const ApprovalReport r = a.approve();
  ASSERT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
  // THEN the route passes through every stop, each at its own height above the 408 m ground
  const std::vector<Eigen::Vector3d> stops = a.missionStops();
  ASSERT_EQ(stops.size(), 4u);  // the land item is on the last waypoint
  // (relative to home: above the ground at home; above terrain: the ground below; AMSL as written)
  const double home_ground_m = *a.groundHeight(stops[0].head<2>());
  const std::vector<double> h_ell_m{home_ground_m + 40, home_ground_m + 60, *a.groundHeight(stops[2].head<2>()) + 80};
  for (std::size_t s = 0; s < stops.size(); ++s) {
    const std::size_t k = routeIndexAt(r, stops[s]);
    ASSERT_LT(k, r.route.size()) << "stop " << s;
    if (s < h_ell_m.size()) {
      EXPECT_NEAR(r.route[k].h_ell_m, h_ell_m[s], 1e-9) << "stop " << s;
    }
  }
  EXPECT_NEAR(r.route[routeIndexAt(r, stops[3])].alt_amsl_m, 458.0, 1e-3);
  EXPECT_NEAR(r.route[routeIndexAt(r, stops[2])].alt_amsl_m, 408.0 + 80.0, 1e-3);  // flat ground at 408 m AMSL
  // AND the ETAs: the first leg at the 12 m/s cruise, the later ones at 6 m/s, the 30 s loiter
  // delaying the last; climbs at 3 m/s where they take longer
  ASSERT_EQ(r.route.size(), 4u);  // nothing in the way: straight legs
  const auto leg_s = [&](std::size_t i, double speed_mps) {
    const Eigen::Vector3d d = r.route[i].xyz - r.route[i - 1].xyz;
    return std::max(d.head<2>().norm() / speed_mps, std::abs(d.z()) / 3.0);
  };
  EXPECT_NEAR(r.route[1].eta_s, leg_s(1, 12.0), 1e-9);
  EXPECT_NEAR(r.route[2].eta_s - r.route[1].eta_s, leg_s(2, 6.0), 1e-9);
  EXPECT_NEAR(r.route[2].hover_s, 30.0, 1e-12);
  EXPECT_NEAR(r.route[3].eta_s - r.route[2].eta_s, 30.0 + leg_s(3, 6.0), 1e-9);
  EXPECT_GT(leg_s(2, 6.0), 2.0 * leg_s(1, 12.0) - 1.0);  // the legs are alike: 6 m/s takes twice as long
  // AND the samples hold the vehicle at the loiter point through the hover, from its start to
  // its end (both sampled, whatever the sample step)
  std::vector<double> hovering_t_s;
  for (const PredictedSample& s : r.predicted) {
    if (s.t_s < r.route[2].eta_s || s.t_s > r.route[2].eta_s + 30.0) continue;
    hovering_t_s.push_back(s.t_s);
    EXPECT_LT((s.xyz - r.route[2].xyz).norm(), 1e-9) << "t " << s.t_s;
    EXPECT_TRUE(s.pl_available) << "t " << s.t_s;
  }
  ASSERT_GE(hovering_t_s.size(), 4u);  // 30 s at a 10 s step, and its ends
  EXPECT_DOUBLE_EQ(hovering_t_s.front(), r.route[2].eta_s);
  EXPECT_DOUBLE_EQ(hovering_t_s.back(), r.route[2].eta_s + 30.0);
  EXPECT_NEAR(r.predicted.back().t_s, r.route[3].eta_s, 1e-9);
  // AND the plan's fences are zones of the approval, named by the plan, the exclusion reported
  // with its clearance
  int from_plan = 0;
  for (const airspace::Zone& z : a.obstructions().zones()) from_plan += z.source == mission.qgc_plan_file;
  EXPECT_EQ(from_plan, 2);
  const auto circle = std::find_if(r.zones.begin(), r.zones.end(), [](const ZoneApproach& z) { return z.identifier == "circle-1"; });
  ASSERT_NE(circle, r.zones.end());
  EXPECT_TRUE(circle->counted);
  EXPECT_GT(circle->min_clearance_m, 50.0);
  // AND the report's JSON form carries the hover for tracking, and the operational intent's
  // volume of the leg into the loiter point lasts through the hover
  const ApprovedFlight back = parseApprovalReport(json(r), "report.json");
  ASSERT_EQ(back.route.size(), r.route.size());
  EXPECT_NEAR(back.route[2].hover_s, 30.0, 1e-3);
  EXPECT_NEAR(back.route[3].eta_s, r.route[3].eta_s, 1e-3);
  const OperationalIntent intent = operationalIntent(r, a.frame());
  ASSERT_EQ(intent.volumes.size(), 3u);
  EXPECT_NEAR(intent.volumes[1].time_end - r.departure, r.route[2].eta_s + 30.0 + kIntentTimeBuffer_s, 1e-6);
}

TEST(Approval, QgcPlanHeightOutsideTheLimitsIsRefusedNamingTheItemAndTheLimit) {
  struct Case {
    std::string name;
    json item;  ///< the plan's second item, after a takeoff to 40 m
    json altitude;
    std::vector<std::string> expected;
  };
  const std::vector<Case> cases{
      {"above max_agl", planWaypoint(16, 3, 0, kLat0, kLon0 + 0.004, 150), json::object(),
       {"'$.mission.items[1].params[6]'", "got '150'", "150.0 m above the ground", "above altitude.max_agl_m 120"}},
      {"below min_agl", planWaypoint(16, 10, 0, kLat0, kLon0 + 0.004, 12), json::object(),
       {"'$.mission.items[1].params[6]'", "got '12'", "below altitude.min_agl_m 30"}},
      {"above max_amsl", planWaypoint(16, 0, 0, kLat0, kLon0 + 0.004, 500), {{"max_amsl_m", 480}},
       {"'$.mission.items[1].params[6]'", "500.0 m above mean sea level", "above altitude.max_amsl_m 480"}},
  };
  for (const Case& c : cases) {
    const Mission m = missionWithPlan("qgc_limit", {planWaypoint(22, 3, 0, kLat0, kLon0, 40), c.item}, emptyFence(), c.altitude);
    const std::string msg = test::messageOf<maps::ParseError>([&] { Approver a(m); });
    EXPECT_EQ(msg.rfind(m.qgc_plan_file + ": ", 0), 0u) << c.name << ": " << msg;
    for (const std::string& piece : c.expected) EXPECT_NE(msg.find(piece), std::string::npos) << c.name << ": " << msg;
  }
}

TEST(Mission, ErrorsNameTheField) {
  const json good{{"vehicle", {{"lateral_m", 1}, {"longitudinal_m", 1}, {"cruise_speed_mps", 10}}},
                  {"start", {{"lat", 47}, {"lon", 8}}},
                  {"goal", {{"lat", 47.01}, {"lon", 8}}},
                  {"departure", "2020-01-01T14:00:00Z"},
                  {"orbits", {"a.txt"}}};
  EXPECT_NO_THROW((void)parseMission(good, "m.json", "."));
  json lattice = good;
  lattice["planner"] = {{"algorithm", "lattice"}, {"lattice_fallback", false}};
  EXPECT_EQ(parseMission(lattice, "m.json", ".").planner, PlannerKind::kLattice);
  EXPECT_FALSE(parseMission(lattice, "m.json", ".").lattice_fallback);
  struct Case {
    std::function<void(json&)> edit;
    std::string expected;
  };
  const std::vector<Case> cases{
      {[](json& j) { j["wings"] = 2; }, "$.wings"},
      {[](json& j) { j.erase("goal"); }, "$.goal"},
      {[](json& j) { j["planner"] = {{"algorithm", "astar"}}; }, "\"prmstar\" or \"lattice\""},
      {[](json& j) { j["planner"] = {{"lattice_fallback", "yes"}}; }, "$.planner.lattice_fallback"},
      {[](json& j) { j["departure"] = "tomorrow"; }, "RFC 3339"},
      {[](json& j) { j["altitude"] = {{"cruise_agl_m", 200}}; }, "cruise_agl_m ≤ max_agl_m"},
      {[](json& j) { j["vehicle"]["cruise_speed_mps"] = 0; }, "$.vehicle.cruise_speed_mps"},
  };
  for (const Case& c : cases) {
    json j = good;
    c.edit(j);
    const std::string msg = test::messageOf<maps::ParseError>([&] { (void)parseMission(j, "m.json", "."); });
    EXPECT_NE(msg.find(c.expected), std::string::npos) << msg;
    EXPECT_EQ(msg.rfind("m.json", 0), 0u) << msg;
  }
}

}  // namespace
}  // namespace skylane::planner
