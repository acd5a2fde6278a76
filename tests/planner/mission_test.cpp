// The mission file of `skylane approve` (planner/mission.hpp): QGroundControl .plan routes
// (points, cruise height, refusals naming the JSON path), the choice between qgc_plan and
// start/goal, defaults, and file names resolved against the mission's folder.
#include "planner/mission.hpp"

#include "maps/geodesy.hpp"
#include "maps/parse_error.hpp"
#include "tests/test_util.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace skylane::planner {
namespace {

using nlohmann::json;

/// Degrees → radians is one multiplication: the points must match it to rounding.
constexpr double kAngleTolerance_rad = 1e-12;

// --- helpers -----------------------------------------------------------------------------------

/// A QGroundControl SimpleItem as QGC 4 writes it (param4, yaw, is NaN → null).
json simpleItem(int command, int frame, const json& lat, const json& lon, double alt) {
  static int jump_id = 0;
  return {{"AMSLAltAboveTerrain", nullptr},
          {"Altitude", alt},
          {"AltitudeMode", 1},
          {"autoContinue", true},
          {"command", command},
          {"doJumpId", ++jump_id},
          {"frame", frame},
          {"params", {0, 0, 0, nullptr, lat, lon, alt}},
          {"type", "SimpleItem"}};
}
json takeoff(double lat, double lon, double alt) { return simpleItem(22, 3, lat, lon, alt); }
json waypoint(double lat, double lon, double alt, int frame = 3) { return simpleItem(16, frame, lat, lon, alt); }
json land(const json& lat, const json& lon) { return simpleItem(21, 3, lat, lon, 0); }
json returnToLaunch() { return simpleItem(20, 2, 0, 0, 0); }
/// A SimpleItem without a position (frame 2, "mission") with these seven parameters.
json commandItem(int command, const json& params) {
  json item = simpleItem(command, 2, 0, 0, 0);
  item["params"] = params;
  return item;
}
json changeSpeed(const json& type, const json& speed_mps) { return commandItem(178, {type, speed_mps, -1, 0, 0, 0, 0}); }
json delay(const json& seconds) { return commandItem(93, {seconds, -1, -1, -1, 0, 0, 0}); }
json loiterTime(double seconds, const json& lat, const json& lon, double alt, int frame = 3) {
  json item = simpleItem(19, frame, lat, lon, alt);
  item["params"][0] = seconds;
  return item;
}
json holdAt(double lat, double lon, double alt, double hold_s) {
  json item = waypoint(lat, lon, alt);
  item["params"][0] = hold_s;
  return item;
}

constexpr double kHomeLat = 47.3712, kHomeLon = 8.5320;

/// A .plan document with these items and a planned home at (kHomeLat, kHomeLon). (A vector:
/// a braced list of one json would be copied, not wrapped in an array.)
json plan(const std::vector<json>& items) {
  return {{"fileType", "Plan"},
          {"groundStation", "QGroundControl"},
          {"version", 1},
          {"geoFence", {{"circles", json::array()}, {"polygons", json::array()}, {"version", 2}}},
          {"mission",
           {{"cruiseSpeed", 15},
            {"firmwareType", 12},
            {"hoverSpeed", 5},
            {"items", items},
            {"plannedHomePosition", {kHomeLat, kHomeLon, 408}},
            {"vehicleType", 2},
            {"version", 2}}},
          {"rallyPoints", {{"points", json::array()}, {"version", 2}}}};
}

/// The smallest valid mission, route left out.
json missionWithoutRoute() {
  return {{"vehicle", {{"lateral_m", 1.2}, {"longitudinal_m", 1.0}, {"cruise_speed_mps", 12}}},
          {"departure", "2020-01-01T14:00:00Z"},
          {"orbits", {"alm.txt"}}};
}

/// Writes `j` to the scratch file `name` (sub-folders created) and returns its path.
std::string writeScratch(const std::string& name, const json& j) {
  const std::string path = test::scratchPath(name);
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream(path) << j.dump(2);
  return path;
}

/// Writes the plan and a mission naming it (in the same folder), and loads the mission.
Mission loadWithPlan(const std::string& stem, const json& plan_doc, const json& extra = json::object()) {
  writeScratch(stem + "/route.plan", plan_doc);
  json m = missionWithoutRoute();
  m["qgc_plan"] = "route.plan";
  m.update(extra);
  return loadMission(writeScratch(stem + "/mission.json", m));
}

::testing::AssertionResult samePoint(const MissionPoint& p, double lat_deg, double lon_deg) {
  const double dlat = p.lat_rad - maps::deg2rad(lat_deg), dlon = p.lon_rad - maps::deg2rad(lon_deg);
  if (std::abs(dlat) <= kAngleTolerance_rad && std::abs(dlon) <= kAngleTolerance_rad) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(" << p.lat_rad << ", " << p.lon_rad << ") rad vs (" << lat_deg << ", "
                                       << lon_deg << ") deg";
}

std::string planError(const json& plan_doc) {
  return test::messageOf<maps::ParseError>([&] { (void)parseQgcPlanRoute(plan_doc, "route.plan"); });
}

// --- QGroundControl routes -----------------------------------------------------------------------

TEST(MissionQgcRoute, TakeoffThreeWaypointsAndLandGiveThePointsAndTheCruiseHeight) {
  // GIVEN a plan: takeoff next to home, three waypoints at 70 m relative to home, land elsewhere
  const std::vector<json> items = {takeoff(47.3715, 8.5325, 30), waypoint(47.3750, 8.5400, 70), waypoint(47.3800, 8.5480, 70),
                      waypoint(47.3830, 8.5530, 70), land(47.3840, 8.5560)};
  // WHEN a mission names it
  const Mission m = loadWithPlan("qgc_valid", plan(items));
  // THEN the points are takeoff, the waypoints in order and the land position, in radians
  ASSERT_EQ(m.points.size(), 5u);
  EXPECT_TRUE(samePoint(m.points[0], 47.3715, 8.5325));
  EXPECT_TRUE(samePoint(m.points[1], 47.3750, 8.5400));
  EXPECT_TRUE(samePoint(m.points[2], 47.3800, 8.5480));
  EXPECT_TRUE(samePoint(m.points[3], 47.3830, 8.5530));
  EXPECT_TRUE(samePoint(m.points[4], 47.3840, 8.5560));
  // AND the common waypoint height becomes the cruise height (takeoff and land heights do not count)
  EXPECT_DOUBLE_EQ(m.cruise_agl_m, 70.0);
  EXPECT_EQ(m.qgc_plan_file, test::scratchPath("qgc_valid/route.plan"));
}

TEST(MissionQgcRoute, TakeoffWithoutPositionStartsAtThePlannedHome) {
  for (const json& here : {json(nullptr), json(0)}) {  // QGC's NaN, ArduPilot's 0, 0
    const QgcPlanRoute r =
        parseQgcPlanRoute(plan({simpleItem(22, 3, here, here, 30), waypoint(47.38, 8.55, 50)}), "route.plan");
    ASSERT_EQ(r.points.size(), 2u) << here;
    EXPECT_TRUE(samePoint(r.points[0], kHomeLat, kHomeLon)) << here;
    EXPECT_TRUE(samePoint(r.points[1], 47.38, 8.55)) << here;
  }
  // No takeoff item at all: the home too.
  const QgcPlanRoute r = parseQgcPlanRoute(plan({waypoint(47.38, 8.55, 50)}), "route.plan");
  ASSERT_EQ(r.points.size(), 2u);
  EXPECT_TRUE(samePoint(r.points[0], kHomeLat, kHomeLon));
}

TEST(MissionQgcRoute, ReturnToLaunchEndsAtHome) {
  const QgcPlanRoute r = parseQgcPlanRoute(
      plan({takeoff(47.3715, 8.5325, 30), waypoint(47.38, 8.55, 60), waypoint(47.39, 8.56, 60), returnToLaunch()}),
      "route.plan");
  ASSERT_EQ(r.points.size(), 4u);
  EXPECT_TRUE(samePoint(r.points[0], 47.3715, 8.5325));
  EXPECT_TRUE(samePoint(r.points.back(), kHomeLat, kHomeLon));
  ASSERT_TRUE(r.cruise_agl_m.has_value());
  EXPECT_DOUBLE_EQ(*r.cruise_agl_m, 60.0);
  EXPECT_EQ(r.cruise_agl_field, "$.mission.items[1].params[6]");
}

TEST(MissionQgcRoute, LandWithoutPositionLandsAtTheLastWaypoint) {
  const QgcPlanRoute r =
      parseQgcPlanRoute(plan({waypoint(47.38, 8.55, 60), waypoint(47.39, 8.56, 60), land(nullptr, nullptr)}), "route.plan");
  ASSERT_EQ(r.points.size(), 3u);
  EXPECT_TRUE(samePoint(r.points.back(), 47.39, 8.56));
}

TEST(MissionQgcRoute, PayloadCommandsAreSkippedAndRepeatedPlacesCountOnce) {
  // GIVEN a camera trigger distance (206) and a gimbal command (1000) between the waypoints, and
  // a land item on top of the last waypoint
  const std::vector<json> items = {waypoint(47.38, 8.55, 60), simpleItem(206, 2, 0, 0, 0), simpleItem(1000, 2, 0, 0, 0),
                      waypoint(47.39, 8.56, 60), land(47.39, 8.56)};
  const QgcPlanRoute r = parseQgcPlanRoute(plan(items), "route.plan");
  ASSERT_EQ(r.points.size(), 3u);  // home, two waypoints
  EXPECT_TRUE(samePoint(r.points[1], 47.38, 8.55));
  EXPECT_TRUE(samePoint(r.points[2], 47.39, 8.56));
}

TEST(MissionQgcRoute, TerrainFrameHeightsCountAsAboveGroundAndAmslOrMixedHeightsDoNot) {
  struct Case {
    std::string name;
    std::vector<json> items;
    std::optional<double> cruise_agl_m;
  };
  const std::vector<Case> cases{
      {"terrain frame, equal", {waypoint(47.38, 8.55, 45, 10), waypoint(47.39, 8.56, 45, 10)}, 45.0},
      {"relative and terrain, equal", {waypoint(47.38, 8.55, 45, 3), waypoint(47.39, 8.56, 45, 10)}, 45.0},
      {"integer frame twins", {waypoint(47.38, 8.55, 45, 6), waypoint(47.39, 8.56, 45, 11)}, 45.0},
      {"relative, different", {waypoint(47.38, 8.55, 50), waypoint(47.39, 8.56, 60)}, std::nullopt},
      {"AMSL", {waypoint(47.38, 8.55, 470, 0), waypoint(47.39, 8.56, 470, 0)}, std::nullopt},
      {"AMSL and relative", {waypoint(47.38, 8.55, 60, 0), waypoint(47.39, 8.56, 60, 3)}, std::nullopt},
      {"no waypoint (RTL only)", {takeoff(47.3715, 8.5325, 30), returnToLaunch()}, std::nullopt},
  };
  for (const Case& c : cases) {
    const QgcPlanRoute r = parseQgcPlanRoute(plan(c.items), "route.plan");
    EXPECT_EQ(r.cruise_agl_m, c.cruise_agl_m) << c.name;
    EXPECT_EQ(r.cruise_agl_field.empty(), !c.cruise_agl_m.has_value()) << c.name;
  }
}

TEST(MissionQgcRoute, MissionAltitudeBlockWinsAndMixedPlanHeightsLeaveTheMissionsCruise) {
  const json equal = plan({waypoint(47.38, 8.55, 70), waypoint(47.39, 8.56, 70)});
  EXPECT_DOUBLE_EQ(loadWithPlan("qgc_block", equal, {{"altitude", {{"cruise_agl_m", 50}}}}).cruise_agl_m, 50.0);
  // A block without cruise_agl_m: the plan's height, checked against the block's limits.
  EXPECT_DOUBLE_EQ(loadWithPlan("qgc_limits", equal, {{"altitude", {{"max_agl_m", 100}}}}).cruise_agl_m, 70.0);
  const json mixed = plan({waypoint(47.38, 8.55, 50), waypoint(47.39, 8.56, 90)});
  EXPECT_DOUBLE_EQ(loadWithPlan("qgc_mixed", mixed).cruise_agl_m, 60.0);  // the default
  EXPECT_DOUBLE_EQ(loadWithPlan("qgc_mixed_block", mixed, {{"altitude", {{"cruise_agl_m", 80}}}}).cruise_agl_m, 80.0);
}

TEST(MissionQgcRoute, PlanHeightOutsideTheMissionLimitsIsNotTheCruiseHeight) {
  // The waypoints' own heights are checked by the approval, which knows the ground
  // (tests/planner/approval_test.cpp, QgcPlanHeightOutsideTheLimitsIsRefusedNamingTheItemAndTheLimit).
  const json high = plan({waypoint(47.38, 8.55, 150), waypoint(47.39, 8.56, 150)});
  const Mission m = loadWithPlan("qgc_high", high);
  EXPECT_DOUBLE_EQ(m.cruise_agl_m, 60.0);  // the default, not the plan's 150 m
  ASSERT_EQ(m.point_flights.size(), 3u);
  ASSERT_TRUE(m.point_flights[1].height.has_value());
  EXPECT_DOUBLE_EQ(m.point_flights[1].height->value_m, 150.0);
  EXPECT_EQ(m.point_flights[1].height->field, "$.mission.items[0].params[6]");
}

// --- speeds, hovers and heights ------------------------------------------------------------------

TEST(MissionQgcRoute, SpeedChangeSetsTheSpeedOfTheLegsAfterIt) {
  // GIVEN a speed change to 5 m/s after the first waypoint, then a "no change" (-1), then 8 m/s
  // as airspeed (taken as ground speed)
  const QgcPlanRoute r = parseQgcPlanRoute(
      plan({takeoff(47.3715, 8.5325, 40), waypoint(47.375, 8.54, 60), changeSpeed(1, 5), waypoint(47.38, 8.548, 60),
            changeSpeed(1, -1), waypoint(47.383, 8.553, 60), changeSpeed(0, 8), land(47.384, 8.556)}),
      "route.plan");
  ASSERT_EQ(r.flights.size(), 5u);
  // THEN the legs before the change have none (the mission's cruise speed) and the later ones the new speed
  EXPECT_FALSE(r.flights[0].speed_mps.has_value());
  EXPECT_FALSE(r.flights[1].speed_mps.has_value());
  EXPECT_EQ(r.flights[2].speed_mps, 5.0);
  EXPECT_EQ(r.flights[2].speed_field, "$.mission.items[2].params[1]");
  EXPECT_EQ(r.flights[3].speed_mps, 5.0);  // -1: no change
  EXPECT_EQ(r.flights[4].speed_mps, 8.0);
  EXPECT_EQ(r.flights[4].speed_field, "$.mission.items[6].params[1]");
}

TEST(MissionQgcRoute, BadSpeedChangesAreRefusedNamingTheParameter) {
  struct Case {
    std::string name;
    json item;
    std::vector<std::string> expected;
  };
  const std::vector<Case> cases{
      {"zero", changeSpeed(1, 0), {"'$.mission.items[1].params[1]'", "got '0'", "> 0 and ≤ 40"}},
      {"negative", changeSpeed(1, -3), {"'$.mission.items[1].params[1]'", "got '-3'", "-1: no change"}},
      {"too fast", changeSpeed(1, 120), {"'$.mission.items[1].params[1]'", "got '120'", "≤ 40"}},
      {"not a number", changeSpeed(1, "fast"), {"'$.mission.items[1].params[1]'", "a speed in m/s"}},
      {"climb speed", changeSpeed(2, 2), {"'$.mission.items[1].params[0]'", "got '2'", "climb and descent"}},
      {"time-of-day delay", delay(-1), {"'$.mission.items[1].params[0]'", "time-of-day form", "in seconds"}},
      {"negative delay", delay(-5), {"'$.mission.items[1].params[0]'", "got '-5'", "a time in seconds"}},
      {"endless delay", delay(1e6), {"'$.mission.items[1].params[0]'", "0 … 3600"}},
      {"negative loiter", loiterTime(-2, 47.38, 8.55, 60), {"'$.mission.items[1].params[0]'", "a time in seconds"}},
  };
  for (const Case& c : cases) {
    const std::string msg = planError(plan({waypoint(47.375, 8.54, 60), c.item, waypoint(47.38, 8.55, 60)}));
    EXPECT_EQ(msg.rfind("route.plan: ", 0), 0u) << c.name << ": " << msg;
    for (const std::string& piece : c.expected) EXPECT_NE(msg.find(piece), std::string::npos) << c.name << ": " << msg;
  }
}

TEST(MissionQgcRoute, LoiterTimeDelayAndHoldTimeAreHoversAtTheirPoints) {
  // GIVEN a delay before takeoff, a waypoint held 5 s, a delay there, a timed loiter at a new
  // place, a timed loiter without a position (where the vehicle is), and a land
  const QgcPlanRoute r = parseQgcPlanRoute(
      plan({delay(12), takeoff(47.3715, 8.5325, 40), holdAt(47.375, 8.54, 60, 5), delay(20),
            loiterTime(30, 47.38, 8.548, 70), loiterTime(10, nullptr, nullptr, 0), land(47.384, 8.556)}),
      "route.plan");
  ASSERT_EQ(r.points.size(), 4u);
  // THEN each hover is on the point the vehicle is at
  EXPECT_DOUBLE_EQ(r.flights[0].hover_s, 12.0);       // before takeoff: at the start
  EXPECT_DOUBLE_EQ(r.flights[1].hover_s, 5.0 + 20.0);  // hold time and delay
  EXPECT_TRUE(samePoint(r.points[2], 47.38, 8.548));
  EXPECT_DOUBLE_EQ(r.flights[2].hover_s, 30.0 + 10.0);  // the loiter and the one in place
  ASSERT_TRUE(r.flights[2].height.has_value());
  EXPECT_DOUBLE_EQ(r.flights[2].height->value_m, 70.0);
  EXPECT_DOUBLE_EQ(r.flights[3].hover_s, 0.0);
}

TEST(MissionQgcRoute, EveryPointKeepsItsOwnHeightAndReference) {
  // GIVEN heights relative to home, above mean sea level and above terrain, a climb on the spot,
  // and a land and a return that keep the last height
  const QgcPlanRoute r = parseQgcPlanRoute(
      plan({takeoff(47.3715, 8.5325, 35), waypoint(47.375, 8.54, 50), waypoint(47.375, 8.54, 90),
            waypoint(47.38, 8.548, 470, 0), waypoint(47.383, 8.553, 45, 10), returnToLaunch()}),
      "route.plan");
  struct Expected {
    HeightReference reference;
    double value_m;
    std::string field;
  };
  const std::vector<Expected> expected{
      {HeightReference::kAboveHome, 35, "$.mission.items[0].params[6]"},
      {HeightReference::kAboveHome, 50, "$.mission.items[1].params[6]"},
      {HeightReference::kAboveHome, 90, "$.mission.items[2].params[6]"},  // same place, higher: its own point
      {HeightReference::kAmsl, 470, "$.mission.items[3].params[6]"},
      {HeightReference::kAboveGround, 45, "$.mission.items[4].params[6]"},
      {HeightReference::kAboveGround, 45, "$.mission.items[4].params[6]"},  // RTL at the height it had
  };
  ASSERT_EQ(r.flights.size(), expected.size());
  ASSERT_EQ(r.points.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_TRUE(r.flights[i].height.has_value()) << i;
    EXPECT_EQ(r.flights[i].height->reference, expected[i].reference) << i;
    EXPECT_DOUBLE_EQ(r.flights[i].height->value_m, expected[i].value_m) << i;
    EXPECT_EQ(r.flights[i].height->field, expected[i].field) << i;
  }
  EXPECT_TRUE(samePoint(r.home, kHomeLat, kHomeLon));
  EXPECT_TRUE(samePoint(r.points.back(), kHomeLat, kHomeLon));
  // Without a takeoff item the start (the home) has no height of its own: the mission's cruise AGL.
  const QgcPlanRoute no_takeoff = parseQgcPlanRoute(plan({waypoint(47.38, 8.55, 50)}), "route.plan");
  EXPECT_FALSE(no_takeoff.flights.front().height.has_value());
}

TEST(MissionQgcRoute, PlanGeofenceJoinsTheZoneFilesOnce) {
  json fenced = plan({waypoint(47.38, 8.55, 60)});
  fenced["geoFence"]["circles"] = {{{"inclusion", false}, {"circle", {{"center", {47.376, 8.545}}, {"radius", 50}}}, {"version", 1}}};
  // GIVEN a plan with a fence and a mission that does not list it under zones
  const Mission m = loadWithPlan("qgc_fence", fenced, {{"zones", {"other.json"}}});
  // THEN it is read as a zone file after the listed ones
  ASSERT_EQ(m.zone_files.size(), 2u);
  EXPECT_EQ(m.zone_files[0], test::scratchPath("qgc_fence/other.json"));
  EXPECT_EQ(m.zone_files[1], test::scratchPath("qgc_fence/route.plan"));
  // Listed under zones as well (another spelling of the same file): once.
  const Mission twice = loadWithPlan("qgc_fence_twice", fenced, {{"zones", {"./route.plan"}}});
  ASSERT_EQ(twice.zone_files.size(), 1u);
  // A plan with an empty geoFence adds nothing.
  EXPECT_TRUE(loadWithPlan("qgc_no_fence", plan({waypoint(47.38, 8.55, 60)})).zone_files.empty());
}

TEST(MissionQgcRoute, ComplexItemIsRefusedNamingItsIndex) {
  std::vector<json> items = {takeoff(47.3715, 8.5325, 30), waypoint(47.38, 8.55, 60)};
  items.push_back({{"type", "ComplexItem"}, {"complexItemType", "survey"}, {"version", 5}});
  items.push_back(land(47.39, 8.56));
  const std::string msg = planError(plan(items));
  EXPECT_EQ(msg.rfind("route.plan: field '$.mission.items[2]'", 0), 0u) << msg;
  EXPECT_NE(msg.find("survey"), std::string::npos) << msg;
  EXPECT_NE(msg.find("not supported"), std::string::npos) << msg;
}

TEST(MissionQgcRoute, BadItemsAreRefusedNamingTheJsonPathTheValueAndWhatWasExpected) {
  struct Case {
    std::string name;
    std::function<void(json&)> edit;  ///< on the items takeoff, waypoint, waypoint, land
    std::vector<std::string> expected;  ///< pieces of the message
  };
  const std::vector<Case> cases{
      {"params missing", [](json& p) { p["mission"]["items"][1].erase("params"); },
       {"'$.mission.items[1].params' is missing"}},
      {"params too short", [](json& p) { p["mission"]["items"][1]["params"] = {0, 0, 0, 0, 47.38}; },
       {"'$.mission.items[1].params'", "7 parameters"}},
      {"latitude not a number", [](json& p) { p["mission"]["items"][2]["params"][4] = "47.4N"; },
       {"'$.mission.items[2].params[4]'", "got '47.4N'", "a latitude in degrees"}},
      {"longitude null on a waypoint", [](json& p) { p["mission"]["items"][1]["params"][5] = nullptr; },
       {"'$.mission.items[1].params[5]'", "got 'null'", "a longitude"}},
      {"latitude out of range", [](json& p) { p["mission"]["items"][3]["params"][4] = 91.5; },
       {"'$.mission.items[3].params[4]'", "91.5", "±89°"}},
      {"waypoint at 0, 0",
       [](json& p) {
         p["mission"]["items"][1]["params"][4] = 0;
         p["mission"]["items"][1]["params"][5] = 0;
       },
       {"'$.mission.items[1].params[4]'", "give the place"}},
      {"altitude not a number", [](json& p) { p["mission"]["items"][1]["params"][6] = "high"; },
       {"'$.mission.items[1].params[6]'", "an altitude in metres"}},
      {"frame 2 (mission) on a waypoint", [](json& p) { p["mission"]["items"][1]["frame"] = 2; },
       {"'$.mission.items[1].frame'", "got '2'", "0 (AMSL), 3 (relative to home) or 10 (terrain)"}},
      {"unsupported command", [](json& p) { p["mission"]["items"][2]["command"] = 30; },
       {"'$.mission.items[2].command'", "got '30'", "16 NAV_WAYPOINT", "not supported"}},
      {"DO_JUMP", [](json& p) { p["mission"]["items"][2]["command"] = 177; },
       {"'$.mission.items[2].command'", "got '177'", "DO_JUMP is not supported", "unroll the loop"}},
      {"unlimited loiter", [](json& p) { p["mission"]["items"][2]["command"] = 17; },
       {"'$.mission.items[2].command'", "NAV_LOITER_UNLIM is not supported", "without end"}},
      {"loiter turns", [](json& p) { p["mission"]["items"][2]["command"] = 18; },
       {"'$.mission.items[2].command'", "NAV_LOITER_TURNS is not supported", "NAV_LOITER_TIME"}},
      {"fractional command", [](json& p) { p["mission"]["items"][2]["command"] = 16.5; },
       {"'$.mission.items[2].command'", "a MAVLink command number"}},
      {"unknown item type", [](json& p) { p["mission"]["items"][2]["type"] = "Pattern"; },
       {"'$.mission.items[2].type'", "SimpleItem"}},
      {"takeoff after a waypoint", [](json& p) { std::swap(p["mission"]["items"][0], p["mission"]["items"][1]); },
       {"'$.mission.items[1]'", "a NAV_TAKEOFF before every other positional item"}},
      {"waypoint after RTL",
       [](json& p) { p["mission"]["items"].insert(p["mission"]["items"].begin() + 2, returnToLaunch()); },
       {"'$.mission.items[3]'", "no NAV_WAYPOINT after RETURN_TO_LAUNCH"}},
      {"no home when the start needs it",
       [](json& p) {
         p["mission"].erase("plannedHomePosition");
         p["mission"]["items"][0]["params"][4] = nullptr;
         p["mission"]["items"][0]["params"][5] = nullptr;
       },
       {"'$.mission.plannedHomePosition' is missing", "at $.mission.items[0]"}},
      {"home not a position", [](json& p) { p["mission"]["plannedHomePosition"] = json::array({47.0}); },
       {"'$.mission.plannedHomePosition'", "[lat, lon, alt]"}},
      {"no items", [](json& p) { p["mission"]["items"] = json::array(); },
       {"'$.mission.items'", "at least one NAV_WAYPOINT"}},
      {"items not an array", [](json& p) { p["mission"]["items"] = 3; }, {"'$.mission.items'", "an array"}},
      {"not a plan", [](json& p) { p["fileType"] = "Mission"; }, {"'$.fileType'", "\"Plan\""}},
      {"no mission", [](json& p) { p.erase("mission"); }, {"'$.mission' is missing"}},
  };
  const json good = plan({takeoff(47.3715, 8.5325, 30), waypoint(47.38, 8.55, 60), waypoint(47.39, 8.56, 60),
                          land(47.3905, 8.5605)});
  ASSERT_NO_THROW((void)parseQgcPlanRoute(good, "route.plan"));
  for (const Case& c : cases) {
    json p = good;
    c.edit(p);
    const std::string msg = planError(p);
    EXPECT_EQ(msg.rfind("route.plan: ", 0), 0u) << c.name << ": " << msg;
    for (const std::string& piece : c.expected) EXPECT_NE(msg.find(piece), std::string::npos) << c.name << ": " << msg;
  }
}

TEST(MissionQgcRoute, UnreadablePlanIsNamedInTheMission) {
  json m = missionWithoutRoute();
  m["qgc_plan"] = "nowhere.plan";
  const std::string path = writeScratch("qgc_missing/mission.json", m);
  const std::string msg = test::messageOf<maps::ParseError>([&] { (void)loadMission(path); });
  EXPECT_EQ(msg.rfind(path + ": field '$.qgc_plan': got 'nowhere.plan'", 0), 0u) << msg;
  EXPECT_NE(msg.find("cannot be read"), std::string::npos) << msg;
  // A syntax error inside the plan names the plan and its line.
  const std::string plan_path = test::scratchPath("qgc_missing/bad.plan");
  std::ofstream(plan_path) << "{\n  \"fileType\": \"Plan\",\n  \"mission\": {,\n}";
  m["qgc_plan"] = "bad.plan";
  const std::string path2 = writeScratch("qgc_missing/mission.json", m);
  const std::string msg2 = test::messageOf<maps::ParseError>([&] { (void)loadMission(path2); });
  EXPECT_EQ(msg2.rfind(plan_path + ":3:", 0), 0u) << msg2;
}

// --- the mission file ------------------------------------------------------------------------------

TEST(MissionFile, QgcPlanAndStartTogetherAreRefusedNamingBoth) {
  json m = missionWithoutRoute();
  m["qgc_plan"] = "route.plan";
  m["start"] = {{"lat", 47.0}, {"lon", 8.0}};
  m["goal"] = {{"lat", 47.01}, {"lon", 8.0}};
  const std::string msg = test::messageOf<maps::ParseError>([&] { (void)parseMission(m, "m.json", "."); });
  EXPECT_EQ(msg.rfind("m.json: field '$.qgc_plan'", 0), 0u) << msg;
  EXPECT_NE(msg.find("either qgc_plan or start/waypoints/goal, not both"), std::string::npos) << msg;
  EXPECT_NE(msg.find("$.start, $.goal also given"), std::string::npos) << msg;
}

TEST(MissionFile, NoRouteIsRefusedNamingBothWays) {
  const std::string msg =
      test::messageOf<maps::ParseError>([&] { (void)parseMission(missionWithoutRoute(), "m.json", "."); });
  EXPECT_EQ(msg.rfind("m.json: field '$.start' is missing", 0), 0u) << msg;
  EXPECT_NE(msg.find("or qgc_plan"), std::string::npos) << msg;
}

TEST(MissionFile, PlanIsReadWithTheCallersReader) {
  json m = missionWithoutRoute();
  m["qgc_plan"] = "sub/route.plan";
  std::string asked;
  const Mission mission = parseMission(m, "m.json", "/base", [&](const std::string& path) {
    asked = path;
    return plan({waypoint(47.38, 8.55, 55)});
  });
  EXPECT_EQ(asked, "/base/sub/route.plan");
  EXPECT_EQ(mission.qgc_plan_file, "/base/sub/route.plan");
  EXPECT_EQ(mission.points.size(), 2u);
  EXPECT_DOUBLE_EQ(mission.cruise_agl_m, 55.0);
}

TEST(MissionFile, OmittedFieldsTakeTheirDefaults) {
  json m = missionWithoutRoute();
  m["start"] = {{"lat", 47.0}, {"lon", 8.0}};
  m["goal"] = {{"lat", 47.01}, {"lon", 8.0}};
  const Mission d = parseMission(m, "m.json", ".");
  const Mission defaults;
  const geofence::BoxLevels default_levels;
  EXPECT_EQ(d.levels.k1, default_levels.k1);
  EXPECT_EQ(d.levels.k2, default_levels.k2);
  EXPECT_EQ(d.levels.k1, 1.2);
  EXPECT_EQ(d.levels.k2, 300.0);
  EXPECT_EQ(d.vehicle.height_m, 0.0);
  EXPECT_EQ(d.climb_speed_mps, 3.0);
  EXPECT_EQ(d.cruise_agl_m, 60.0);
  EXPECT_EQ(d.min_agl_m, 30.0);
  EXPECT_EQ(d.max_agl_m, 120.0);
  EXPECT_FALSE(d.max_amsl_m.has_value());
  EXPECT_EQ(d.departure_latest - d.departure_earliest, 0.0);
  EXPECT_EQ(d.departure_step_s, 600.0);
  EXPECT_TRUE(d.terrain_file.empty());
  EXPECT_EQ(d.ground_amsl_m, 0.0);
  EXPECT_EQ(d.zone_format, "auto");
  EXPECT_EQ(d.method, integrity::IntegrityMethod::kRaim);
  EXPECT_FALSE(d.with_exclusion);
  EXPECT_EQ(d.mask_deg, defaults.mask_deg);
  EXPECT_EQ(d.sample_s, 1.0);
  EXPECT_EQ(d.cost_weight, 1.0);
  EXPECT_EQ(d.cost_cell_m, 50.0);
  EXPECT_EQ(d.planner, PlannerKind::kRrtStar);
  EXPECT_EQ(d.time_limit_s, 30.0);  // a safety net far above the iteration budget
  EXPECT_EQ(d.seed, 1u);
  EXPECT_EQ(d.resolution_m, 2.0);
  EXPECT_TRUE(d.simplify);
  EXPECT_TRUE(d.lattice_fallback);  // a leg the OMPL search cannot plan searches the lattice seed
  EXPECT_EQ(d.margin_m, 300.0);
  EXPECT_EQ(d.max_replans, 2);
  EXPECT_TRUE(d.qgc_plan_file.empty());
  ASSERT_EQ(d.points.size(), 2u);
}

TEST(MissionFile, IntegrityFdeIsTrueOrFalse) {
  json m = missionWithoutRoute();
  m["start"] = {{"lat", 47.0}, {"lon", 8.0}};
  m["goal"] = {{"lat", 47.01}, {"lon", 8.0}};
  m["integrity"] = {{"method", "araim"}, {"fde", true}};
  EXPECT_TRUE(parseMission(m, "m.json", ".").with_exclusion);
  m["integrity"]["fde"] = "yes";
  const std::string what = test::messageOf<maps::ParseError>([&] { (void)parseMission(m, "m.json", "."); });
  EXPECT_NE(what.find("m.json"), std::string::npos) << what;
  EXPECT_NE(what.find("integrity.fde"), std::string::npos) << what;
  EXPECT_NE(what.find("true or false"), std::string::npos) << what;
}

TEST(MissionFile, DepartureWindowGivesLatestAndStep) {
  json m = missionWithoutRoute();
  m["start"] = {{"lat", 47.0}, {"lon", 8.0}};
  m["goal"] = {{"lat", 47.01}, {"lon", 8.0}};
  m["departure_window"] = {{"latest", "2020-01-01T15:30:00Z"}};
  const Mission a = parseMission(m, "m.json", ".");
  EXPECT_DOUBLE_EQ(a.departure_latest - a.departure_earliest, 5400.0);
  EXPECT_EQ(a.departure_step_s, 600.0);  // the default step
  m["departure_window"]["step_s"] = 900;
  EXPECT_EQ(parseMission(m, "m.json", ".").departure_step_s, 900.0);
  m["departure_window"]["step_s"] = 0;
  const std::string msg = test::messageOf<maps::ParseError>([&] { (void)parseMission(m, "m.json", "."); });
  EXPECT_NE(msg.find("'$.departure_window.step_s': got '0', expected a number > 0"), std::string::npos) << msg;
  m["departure_window"] = {{"latest", "2020-01-01T13:00:00Z"}};
  const std::string msg2 = test::messageOf<maps::ParseError>([&] { (void)parseMission(m, "m.json", "."); });
  EXPECT_NE(msg2.find("'$.departure_window.latest'"), std::string::npos) << msg2;
  EXPECT_NE(msg2.find("a time not before departure"), std::string::npos) << msg2;
}

TEST(MissionFile, RelativeFileNamesResolveAgainstTheMissionsFolder) {
  json m = missionWithoutRoute();
  m["qgc_plan"] = "routes/route.plan";
  m["zones"] = {"zones.json", "/abs/zones.json"};
  m["terrain"] = "../dem/terrain.tif";
  m["buildings"] = "buildings.geojson";
  m["orbits"] = {"../gnss/alm.txt"};
  writeScratch("resolve/missions/routes/route.plan", plan({waypoint(47.38, 8.55, 60)}));
  const std::string path = writeScratch("resolve/missions/mission.json", m);
  const Mission loaded = loadMission(path);
  const std::filesystem::path dir = std::filesystem::path(test::scratchPath("resolve"));
  EXPECT_EQ(loaded.qgc_plan_file, (dir / "missions/routes/route.plan").string());
  ASSERT_EQ(loaded.zone_files.size(), 2u);
  EXPECT_EQ(loaded.zone_files[0], (dir / "missions/zones.json").string());
  EXPECT_EQ(loaded.zone_files[1], "/abs/zones.json");
  EXPECT_EQ(loaded.terrain_file, (dir / "dem/terrain.tif").string());
  EXPECT_EQ(loaded.buildings_file, (dir / "missions/buildings.geojson").string());
  ASSERT_EQ(loaded.orbit_files.size(), 1u);
  EXPECT_EQ(loaded.orbit_files[0], (dir / "gnss/alm.txt").string());
}

}  // namespace
}  // namespace skylane::planner
