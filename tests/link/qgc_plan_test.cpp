// The QGroundControl plan of an approved route (link/qgc_plan.hpp): every field as the plan
// format's published description gives it (QGroundControl developer guide, "Plan File Format"),
// and a round trip through skylane's own readers — the mission route reader (what `approve`
// takes as `qgc_plan`) and the zone loader of `.plan` geofences.
#include "link/qgc_plan.hpp"

#include "airspace/loaders.hpp"
#include "maps/text_file.hpp"
#include "planner/mission.hpp"

#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <memory>
#include <set>
#include <string>

namespace skylane::link {
namespace {

using nlohmann::json;

const std::string kExampleDir = std::string(SKYLANE_TEST_DATA) + "/../../examples/approve";

struct Example {
  std::unique_ptr<planner::Approver> approver;
  planner::ApprovalReport report;
  json plan;
};

const Example& example() {
  static const Example e = [] {
    Example x;
    x.approver = std::make_unique<planner::Approver>(planner::loadMission(kExampleDir + "/mission.json"));
    x.report = x.approver->approve();
    x.plan = qgcPlan(x.report, *x.approver);
    return x;
  }();
  return e;
}

/// Twice the signed area of a [[lat, lon], …] ring in the (lon, lat) plane: < 0 clockwise.
double signedArea2(const json& ring) {
  double a = 0.0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const json& p = ring[i];
    const json& q = ring[(i + 1) % ring.size()];
    a += p[1].get<double>() * q[0].get<double>() - q[1].get<double>() * p[0].get<double>();
  }
  return a;
}

/// Point in a plane polygon: the test utilities' independent crossing test.
bool inside(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& p) { return test::insideByCrossings(p, ring); }

TEST(QgcPlan, EveryFieldIsAsThePlanFormatDescribesIt) {
  const Example& e = example();
  ASSERT_TRUE(e.report.approved);
  const json& p = e.plan;
  EXPECT_EQ(p.at("fileType"), "Plan");
  EXPECT_EQ(p.at("version"), 1);
  EXPECT_TRUE(p.at("groundStation").is_string());
  const json& m = p.at("mission");
  EXPECT_EQ(m.at("version"), 2);
  EXPECT_EQ(m.at("firmwareType"), 0);  // MAV_AUTOPILOT_GENERIC
  EXPECT_EQ(m.at("vehicleType"), 2);   // MAV_TYPE_QUADROTOR
  EXPECT_EQ(m.at("globalPlanAltitudeMode"), 2);
  EXPECT_DOUBLE_EQ(m.at("cruiseSpeed").get<double>(), e.approver->mission().cruise_speed_mps);
  EXPECT_DOUBLE_EQ(m.at("hoverSpeed").get<double>(), e.approver->mission().cruise_speed_mps);
  ASSERT_EQ(m.at("plannedHomePosition").size(), 3u);
  const json& all_items = m.at("items");
  // takeoff, the cruise speed (the example's legs are flown at it), a waypoint per later point, land
  ASSERT_EQ(all_items.size(), e.report.route.size() + 2);
  const json& speed = all_items[1];
  EXPECT_EQ(speed.at("command"), 178);  // MAV_CMD_DO_CHANGE_SPEED
  EXPECT_EQ(speed.at("frame"), 2);      // MAV_FRAME_MISSION: no position
  EXPECT_EQ(speed.at("doJumpId"), 2);
  EXPECT_EQ(speed.at("params"), json({1, e.approver->mission().cruise_speed_mps, -1, 0, 0, 0, 0}));  // ground speed
  json items = json::array();
  for (std::size_t i = 0; i < all_items.size(); ++i) {
    if (i != 1) items.push_back(all_items[i]);
  }
  const std::set<std::string> keys{"AMSLAltAboveTerrain", "Altitude", "AltitudeMode", "autoContinue", "command",
                                   "doJumpId", "frame", "params", "type"};
  for (std::size_t i = 0; i < items.size(); ++i) {
    const json& it = items[i];
    std::set<std::string> have;
    for (const auto& [k, v] : it.items()) have.insert(k);
    EXPECT_EQ(have, keys) << it.dump();
    EXPECT_EQ(it.at("type"), "SimpleItem");
    EXPECT_EQ(it.at("doJumpId"), static_cast<int>(i == 0 ? 1 : i + 2));  // auto-numbered from 1
    EXPECT_EQ(it.at("frame"), 0);                                        // MAV_FRAME_GLOBAL (AMSL)
    EXPECT_EQ(it.at("AltitudeMode"), 2);
    ASSERT_EQ(it.at("params").size(), 7u);
    EXPECT_EQ(it.at("params")[6], it.at("Altitude"));
  }
  EXPECT_EQ(items.front().at("command"), 22);  // MAV_CMD_NAV_TAKEOFF
  EXPECT_EQ(items.back().at("command"), 21);   // MAV_CMD_NAV_LAND
  for (std::size_t i = 1; i + 1 < items.size(); ++i) {
    EXPECT_EQ(items[i].at("command"), 16);  // MAV_CMD_NAV_WAYPOINT
    EXPECT_NEAR(items[i].at("params")[1].get<double>(), e.report.limits.level1.hal_m, 1e-3);  // acceptance radius
    EXPECT_NEAR(items[i].at("Altitude").get<double>(), e.report.route[i].alt_amsl_m, 0.51e-3);
  }
  // The landing altitude is the ground under the goal: the route's last point less the cruise height.
  EXPECT_NEAR(items.back().at("Altitude").get<double>(),
              e.report.route.back().alt_amsl_m - e.approver->mission().cruise_agl_m, 1e-3);
  const json& fence = p.at("geoFence");
  EXPECT_EQ(fence.at("version"), 2);
  ASSERT_GE(fence.at("polygons").size(), 1u);
  EXPECT_EQ(fence.at("polygons")[0].at("inclusion"), true);
  for (const json& poly : fence.at("polygons")) {
    EXPECT_EQ(poly.at("version"), 1);
    ASSERT_GE(poly.at("polygon").size(), 3u);
    EXPECT_LT(signedArea2(poly.at("polygon")), 0.0) << "clockwise, as the format asks";
  }
  for (const json& c : fence.at("circles")) {
    EXPECT_EQ(c.at("inclusion"), false);
    EXPECT_GT(c.at("circle").at("radius").get<double>(), 0.0);
  }
  EXPECT_EQ(p.at("rallyPoints").at("version"), 2);
}

TEST(QgcPlan, TheRouteReadsBackThroughSkylanesPlanReader) {
  const Example& e = example();
  const planner::QgcPlanRoute back = planner::parseQgcPlanRoute(e.plan, "mission.plan");
  ASSERT_EQ(back.points.size(), e.report.route.size());
  for (std::size_t i = 0; i < back.points.size(); ++i) {
    EXPECT_NEAR(maps::rad2deg(back.points[i].lat_rad), maps::rad2deg(e.report.route[i].lat_rad), 0.51e-8);
    EXPECT_NEAR(maps::rad2deg(back.points[i].lon_rad), maps::rad2deg(e.report.route[i].lon_rad), 0.51e-8);
  }
}

TEST(QgcPlan, TheFenceReadsBackAsOneKeepInAroundEveryBoxAndTheCountedZonesOutside) {
  const Example& e = example();
  const std::vector<airspace::Zone> zones = airspace::parseZones(e.plan, "mission.plan", airspace::ZoneFormat::kQgcPlan);
  int keep_in = 0;
  for (const airspace::Zone& z : zones) keep_in += z.keep_in;
  EXPECT_EQ(keep_in, 1);
  EXPECT_EQ(zones.size(), e.plan.at("geoFence").at("polygons").size() + e.plan.at("geoFence").at("circles").size());
  // The keep-in polygon holds every corner of every segment's level-2 box (moved 1 cm inwards):
  // the union is whole. Checked in the map frame with an independent point-in-polygon test.
  std::vector<Eigen::Vector2d> ring;
  for (const json& ll : e.plan.at("geoFence").at("polygons")[0].at("polygon")) {
    ring.push_back(e.approver->frame().toPlane(maps::deg2rad(ll[0].get<double>()), maps::deg2rad(ll[1].get<double>())));
  }
  const auto& route = e.report.route;
  int corners = 0;
  for (std::size_t i = 1; i < route.size(); ++i) {
    const auto box = planner::segmentOutline(route[i - 1].xyz, route[i].xyz, e.report.limits.level2.hal_m - 0.01);
    for (const Eigen::Vector2d& c : box) {
      EXPECT_TRUE(inside(ring, c)) << "segment " << i;
      ++corners;
    }
    // and nothing more than the boxes: a point 1 m beyond a box's side is outside (at mid-segment)
    const Eigen::Vector2d mid = 0.5 * (route[i - 1].xyz + route[i].xyz).head<2>();
    const Eigen::Vector2d d = (route[i].xyz - route[i - 1].xyz).head<2>().normalized();
    const Eigen::Vector2d beyond = mid + Eigen::Vector2d(-d.y(), d.x()) * (e.report.limits.level2.hal_m + 1.0);
    bool in_other_box = false;
    for (std::size_t k = 1; k < route.size(); ++k) {
      in_other_box = in_other_box || inside(planner::segmentOutline(route[k - 1].xyz, route[k].xyz, e.report.limits.level2.hal_m), beyond);
    }
    if (!in_other_box) {
      EXPECT_FALSE(inside(ring, beyond)) << "segment " << i;
    }
  }
  EXPECT_EQ(corners, 4 * static_cast<int>(route.size() - 1));
}

// The vehicle flies the approved timing: a DO_CHANGE_SPEED before each leg whose speed differs,
// so that skylane's own plan reader, timing the legs as the approval does (the horizontal length
// at the leg's speed or the height change at the climb speed, whichever takes longer, after the
// last point's hover), gives back every ETA (to the cm/s the speeds are written with).
TEST(QgcPlan, TheVehicleIsGivenTheApprovedSpeedOfEveryLeg) {
  const Example& e = example();
  const planner::Approver& a = *e.approver;
  const double climb_mps = a.mission().climb_speed_mps;
  struct Leg {
    Eigen::Vector3d d;
    double speed_mps, hover_s;  // the leg's speed; the hover at its end
  };
  // 600 m and 400 m at 12 m/s, a 20 s hover, 300 m at 6 m/s, 50 m while climbing 60 m (the climb
  // takes longer: flown at 50 m over the climb's time), 500 m at 8 m/s.
  const std::vector<Leg> legs{{{600, 0, 0}, 12, 0}, {{0, 400, 0}, 12, 20}, {{300, 0, 0}, 6, 0}, {{50, 0, 60}, 12, 0},
                              {{0, -500, 0}, 8, 0}};
  const planner::RoutePoint& origin = e.report.route.front();
  planner::ApprovedFlight f;
  f.approved = true;
  f.departure = e.report.departure;
  f.level1 = e.report.limits.level1;
  f.level2 = e.report.limits.level2;
  Eigen::Vector3d p(0, 0, origin.h_ell_m);
  double t = 0;
  const auto addPoint = [&](double hover_s) {
    planner::RoutePoint rp;
    const Eigen::Vector2d ll = a.frame().toLatLon(p.head<2>());
    rp.lat_rad = ll.x();
    rp.lon_rad = ll.y();
    rp.h_ell_m = p.z();
    rp.alt_amsl_m = p.z() - (origin.h_ell_m - origin.alt_amsl_m);
    rp.eta_s = t;
    rp.hover_s = hover_s;
    f.route.push_back(rp);
  };
  addPoint(0);
  for (const Leg& l : legs) {
    t += f.route.back().hover_s + std::max(l.d.head<2>().norm() / l.speed_mps, std::abs(l.d.z()) / climb_mps);
    p += l.d;
    addPoint(l.hover_s);
  }
  const json plan = qgcPlan(f, a);
  std::vector<double> changes;
  for (const json& it : plan.at("mission").at("items")) {
    if (it.at("command") == 178) changes.push_back(it.at("params")[1].get<double>());
  }
  EXPECT_EQ(changes, (std::vector<double>{12, 6, std::round(50.0 / (60.0 / climb_mps) * 1e2) / 1e2, 8}));

  const planner::QgcPlanRoute back = planner::parseQgcPlanRoute(plan, "timing.plan");
  ASSERT_EQ(back.points.size(), f.route.size());
  // Speeds are written to the cm/s: a leg of length L at v may arrive up to L/v · 0.005/v late or
  // early; the ETAs must agree to that (and 1 ms a leg).
  double eta = 0, tolerance_s = 0;
  for (std::size_t i = 1; i < back.points.size(); ++i) {
    const Eigen::Vector2d from = a.frame().toPlane(back.points[i - 1].lat_rad, back.points[i - 1].lon_rad);
    const Eigen::Vector2d to = a.frame().toPlane(back.points[i].lat_rad, back.points[i].lon_rad);
    const double dz = f.route[i].h_ell_m - f.route[i - 1].h_ell_m;
    ASSERT_TRUE(back.flights[i].speed_mps) << "leg " << i;
    const double v = *back.flights[i].speed_mps;
    eta += back.flights[i - 1].hover_s + std::max((to - from).norm() / v, std::abs(dz) / climb_mps);
    tolerance_s += (to - from).norm() / v * 0.005 / v + 1e-3;
    EXPECT_NEAR(eta, f.route[i].eta_s, tolerance_s) << "point " << i;
  }
}

TEST(QgcPlan, AReportWithoutARouteIsRefused) {
  const Example& e = example();
  planner::ApprovalReport empty = e.report;
  empty.route.resize(1);
  EXPECT_THROW((void)qgcPlan(empty, *e.approver), std::invalid_argument);
}

}  // namespace
}  // namespace skylane::link
