// Approval with keep-in fences and reasons that name their cause (issue 17). The property test
// checks every approved route's predicted samples with the exact predicates of airspace/ (CGAL
// bounded side, exact segment-meets-disk), independently of the fence's own margins.
#include "planner/approval.hpp"
#include "link/qgc_plan.hpp"
#include "planner/report_formats.hpp"
#include "planner/tracking/tracker.hpp"

#include "airspace/zone_geometry.hpp"
#include "maps/geodesy.hpp"
#include "maps/plane_frame.hpp"
#include "tests/planner/map_frame_json.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <random>

namespace skylane::planner {
namespace {

using nlohmann::json;

constexpr double kLat0 = 47.3712, kLon0 = 8.5320;
const test::MapFrameJson kMap(kLat0, kLon0);
const maps::PlaneFrame& frame() { return kMap.frame(); }
json lonLat(const Eigen::Vector2d& xy) { return kMap.lonLat(xy); }

/// A GeoJSON feature: a polygon given in the map frame, with a restriction.
json polygonFeature(const std::string& id, const std::string& restriction, const std::vector<Eigen::Vector2d>& ring) {
  json coords = json::array();
  for (const Eigen::Vector2d& p : ring) coords.push_back(lonLat(p));
  coords.push_back(lonLat(ring.front()));
  return {{"type", "Feature"},
          {"properties", {{"identifier", id}, {"name", id + " name"}, {"restriction", restriction}}},
          {"geometry", {{"type", "Polygon"}, {"coordinates", json::array({coords})}}}};
}

/// A GeoJSON circle (Point + radius_m) in the map frame.
json circleFeature(const std::string& id, const std::string& restriction, const Eigen::Vector2d& c, double r) {
  return {{"type", "Feature"},
          {"properties", {{"identifier", id}, {"name", id + " name"}, {"restriction", restriction}, {"radius_m", r}}},
          {"geometry", {{"type", "Point"}, {"coordinates", lonLat(c)}}}};
}

/// A mission from the frame's origin to 1.5 km east (or the points given), over these features.
Mission missionOver(const std::vector<json>& features, const std::string& name, Eigen::Vector2d start = {0, 0},
                    Eigen::Vector2d goal = {1500, 0}) {
  const std::string zones = test::scratchPath(name + "_zones.geojson");
  std::ofstream(zones) << json{{"type", "FeatureCollection"}, {"features", features}}.dump();
  const json s = lonLat(start), g = lonLat(goal);
  json m{{"name", name},
         {"vehicle", {{"lateral_m", 1.2}, {"longitudinal_m", 1.0}, {"cruise_speed_mps", 12}}},
         {"k1", 1.2},
         {"k2", 150},
         {"start", {{"lat", s[1]}, {"lon", s[0]}}},
         {"goal", {{"lat", g[1]}, {"lon", g[0]}}},
         {"departure", "2020-01-01T14:00:00Z"},
         {"zones", {zones}},
         {"ground_amsl_m", 408},
         {"orbits", {test::dataPath("gnss/alm01jan2020.txt")}},
         {"integrity", {{"cost_weight", 0.0}}},
         {"planner", {{"iterations", 800}, {"seed", 5}}}};
  return parseMission(m, name + ".json", ".");
}

/// An irregular octagon round the middle of the route, holding start and goal.
std::vector<Eigen::Vector2d> fenceRing(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector2d> ring;
  const double a = 950 + 200 * u(rng), b = 250 + 200 * u(rng);
  for (int k = 0; k < 8; ++k) {
    const double t = 2.0 * M_PI * (k + 0.25 * (u(rng) - 0.5)) / 8.0;
    ring.emplace_back(750 + a * std::cos(t), b * std::sin(t));
  }
  return ring;
}

/// Exactly: the disk of radius r round c lies inside the ring (its centre inside, no edge meeting it).
bool diskInsideRing(const Eigen::Vector2d& c, double r, const airspace::PlanarRing& ring) {
  const airspace::PlanarPrism prism{ring, {}, 0.0, -1.0, 1.0};
  if (!airspace::cylinderMeetsPrism({c.x(), c.y(), 0.0}, 0.0, 0.0, prism)) return false;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    if (airspace::segmentMeetsDisk(ring[i], ring[(i + 1) % ring.size()], c, r)) return false;
  }
  return true;
}

TEST(KeepInApproval, ApprovedRoutesStayInsideTheFenceAndClearOfTheZones) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int approved = 0, samples = 0;
  for (int scene = 0; scene < 6; ++scene) {
    const std::vector<Eigen::Vector2d> ring = fenceRing(rng);
    std::vector<json> features{polygonFeature("FENCE-" + std::to_string(scene), "KEEP_IN", ring)};
    std::vector<std::pair<Eigen::Vector2d, double>> circles;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d c(300 + 900 * u(rng), (u(rng) - 0.5) * 160);
      const double r = 30 + 50 * u(rng);
      circles.emplace_back(c, r);
      features.push_back(circleFeature("NFZ-" + std::to_string(scene) + "-" + std::to_string(k), "PROHIBITED", c, r));
    }
    const std::string name = "keep_in_random_" + std::to_string(scene);
    Approver a(missionOver(features, name));
    const ApprovalReport r = a.approve();
    if (!r.approved) continue;
    ++approved;
    // The fence ring as the planner's frame has it (straight edges between projected vertices).
    airspace::PlanarRing planar;
    for (const Eigen::Vector2d& p : ring) {
      const Eigen::Vector2d ll = frame().toLatLon(p);
      planar.push_back(frame().toPlane(ll.x(), ll.y()));
    }
    for (const PredictedSample& s : r.predicted) {
      ++samples;
      EXPECT_TRUE(diskInsideRing(s.xyz.head<2>(), s.hpl_m, planar)) << name << " t=" << s.t_s << " HPL " << s.hpl_m;
      for (const auto& [c, radius] : circles) {
        EXPECT_GT((s.xyz.head<2>() - c).norm(), radius + s.hpl_m) << name << " t=" << s.t_s;
      }
    }
  }
  EXPECT_GE(approved, 4);
  EXPECT_GT(samples, 400);
}

// A prohibited circle south of the direct line leaves the short way round to the north, but
// the fence's north edge is 60 m from the line: the route must take the long way, south.
TEST(KeepInApproval, TheFenceSendsTheRouteTheLongWayRound) {
  const std::vector<Eigen::Vector2d> ring{{-300, -700}, {1800, -700}, {1800, 60}, {-300, 60}};
  const std::vector<json> features{polygonFeature("SITE", "KEEP_IN", ring),
                                   circleFeature("BLOCK", "PROHIBITED", {750, -60}, 120)};
  const ApprovalReport r = Approver(missionOver(features, "keep_in_long_way")).approve();
  ASSERT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
  double min_y = 0.0;
  for (const PredictedSample& s : r.predicted) {
    EXPECT_LT(s.xyz.y() + s.hpl_m, 60.0) << "t=" << s.t_s;
    min_y = std::min(min_y, s.xyz.y());
  }
  EXPECT_LT(min_y, -180.0);  // south of the circle
  // Without the fence the same mission goes north, the short way.
  const ApprovalReport free = Approver(missionOver({features[1]}, "no_fence_short_way")).approve();
  ASSERT_TRUE(free.approved);
  double max_y = 0.0;
  for (const PredictedSample& s : free.predicted) max_y = std::max(max_y, s.xyz.y());
  EXPECT_GT(max_y, 60.0);
}

using Rings = std::vector<std::vector<Eigen::Vector2d>>;

/// The plan's fence polygons in the map frame: the inclusion ones and the exclusion ones.
std::pair<Rings, Rings> fencePolygons(const json& plan) {
  std::pair<Rings, Rings> out;
  for (const json& poly : plan.at("geoFence").at("polygons")) {
    std::vector<Eigen::Vector2d> ring;
    for (const json& ll : poly.at("polygon")) {
      ring.push_back(frame().toPlane(maps::deg2rad(ll[0].get<double>()), maps::deg2rad(ll[1].get<double>())));
    }
    (poly.at("inclusion").get<bool>() ? out.first : out.second).push_back(ring);
  }
  return out;
}

// The plan handed to the vehicle (QGroundControl .plan, and the FENCE upload made from it) keeps
// it inside the keep-in zones: the level-2 airspace is cut to them, and a hole they leave in it
// is an exclusion polygon. Checked by sampling points: inside the plan's fence exactly where
// inside both the level-2 boxes and the keep-in zones' union.
TEST(KeepInPlan, TheVehiclesFenceIsTheAirspaceCutToTheKeepInZonesWithTheirHole) {
  // A (y −90 … 60) and a Π-shaped B (y 50 … 170, notched to 120 over x 600 … 900): their union
  // leaves the hole [600, 900] × [60, 120], beside the route along y = 0.
  const std::vector<Eigen::Vector2d> a{{-150, -90}, {1650, -90}, {1650, 60}, {-150, 60}};
  const std::vector<Eigen::Vector2d> b{{-150, 50},  {600, 50},   {600, 120},  {900, 120},
                                       {900, 50},   {1650, 50},  {1650, 170}, {-150, 170}};
  Approver approver(missionOver({polygonFeature("A", "KEEP_IN", a), polygonFeature("B", "KEEP_IN", b)}, "keep_in_plan"));
  const ApprovalReport r = approver.approve();
  ASSERT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
  const auto [inclusions, exclusions] = fencePolygons(link::qgcPlan(r, approver));
  ASSERT_EQ(inclusions.size(), 1u);
  ASSERT_EQ(exclusions.size(), 1u);  // the hole (the mission's zones are all keep-in)
  const std::vector<Eigen::Vector2d> hole{{600, 60}, {900, 60}, {900, 120}, {600, 120}};
  for (const Eigen::Vector2d& corner : hole) {
    double nearest = 1e9;
    for (const Eigen::Vector2d& v : exclusions[0]) nearest = std::min(nearest, (v - corner).norm());
    EXPECT_LT(nearest, 0.05) << corner.transpose();
  }
  std::vector<RoutePoint> route = r.route;
  for (RoutePoint& p : route) {
    const Eigen::Vector2d xy = frame().toPlane(p.lat_rad, p.lon_rad);
    p.xyz = Eigen::Vector3d(xy.x(), xy.y(), p.h_ell_m);
  }
  for (const RoutePoint& p : route) EXPECT_TRUE(test::insideByCrossings(p.xyz.head<2>(), inclusions[0]));
  const std::vector<Eigen::Vector2d> outline = link::airspaceOutline(route, r.limits.level2.hal_m);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> ux(-400, 1900), uy(-400, 400);
  int fenced = 0, wrong = 0;
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector2d p(ux(rng), uy(rng));
    const bool in_keep_in = test::insideByCrossings(p, a) || test::insideByCrossings(p, b);
    const bool expected = test::insideByCrossings(p, outline) && in_keep_in;
    const bool given = test::insideByCrossings(p, inclusions[0]) && !test::insideByCrossings(p, exclusions[0]);
    fenced += given;
    wrong += expected != given;
  }
  EXPECT_LE(wrong, 2) << "of 20,000 points (only those within millimetres of an edge may differ)";
  // The level-2 boxes (HAL₂ ≥ 170 m round the route) hold the union: 1,800 m × 260 m less the
  // hole's 300 m × 60 m, of the 2,300 m × 800 m sampled — 4,891 of 20,000 expected (σ ≈ 61).
  EXPECT_GE(r.limits.level2.hal_m, 170.0);
  EXPECT_NEAR(fenced, 20000.0 * (1800.0 * 260.0 - 300.0 * 60.0) / (2300.0 * 800.0), 250.0);
}

// A prohibited circle cuts the fence in two: no route, and the reason names what blocks the leg.
TEST(KeepInApproval, ALegWithNoRouteNamesWhatBlocksItsDirectLine) {
  const std::vector<Eigen::Vector2d> ring{{-300, -60}, {1800, -60}, {1800, 60}, {-300, 60}};
  Mission m = missionOver({polygonFeature("SITE", "KEEP_IN", ring), circleFeature("CUT", "PROHIBITED", {750, 0}, 100)},
                          "keep_in_cut");
  m.iterations = 300;
  const ApprovalReport r = Approver(m).approve();
  EXPECT_FALSE(r.approved);
  ASSERT_FALSE(r.reasons.empty());
  const Reason& why = r.reasons.front();
  EXPECT_EQ(why.kind, "planning");
  EXPECT_NE(why.message.find("no route found for leg 1 within"), std::string::npos) << why.message;
  EXPECT_NE(why.message.find("the direct line meets zone CUT (PROHIBITED, \"CUT name\")"), std::string::npos)
      << why.message;
  EXPECT_NE(why.message.find("planner.margin_m"), std::string::npos) << why.message;
}

TEST(KeepInApproval, AStartOutsideTheFenceIsRejectedNamingIt) {
  const std::vector<Eigen::Vector2d> ring{{200, -200}, {1700, -200}, {1700, 200}, {200, 200}};
  Approver a(missionOver({polygonFeature("SITE", "KEEP_IN", ring)}, "keep_in_start_outside"));
  const ApprovalReport r = a.approve();
  EXPECT_FALSE(r.approved);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_EQ(r.reasons.front().kind, "keep_in");
  EXPECT_EQ(r.reasons.front().subject, "SITE");
  EXPECT_NE(r.reasons.front().message.find("the start lies outside keep-in zone SITE"), std::string::npos)
      << r.reasons.front().message;
}

TEST(KeepInApproval, AGoalInAnAuthorisationZoneSaysWhatWouldLiftIt) {
  Approver a(missionOver({circleFeature("CTR-1", "REQ_AUTHORISATION", {1500, 0}, 100)}, "goal_in_ctr"));
  const ApprovalReport r = a.approve();
  EXPECT_FALSE(r.approved);
  ASSERT_FALSE(r.reasons.empty());
  const Reason& why = r.reasons.front();
  EXPECT_EQ(why.kind, "zone");
  EXPECT_NE(why.message.find("the goal lies in zone CTR-1 (REQ_AUTHORISATION, \"CTR-1 name\")"), std::string::npos)
      << why.message;
  EXPECT_NE(why.message.find("an authorisation for it would lift it"), std::string::npos) << why.message;
  // With the authorisation listed, the same mission flies.
  Mission m = missionOver({circleFeature("CTR-1", "REQ_AUTHORISATION", {1500, 0}, 100)}, "goal_in_ctr_ok");
  m.authorisations.insert("CTR-1");
  EXPECT_TRUE(Approver(m).approve().approved);
}

// The start is 3 m from a prohibited zone: not in it, but its planning volume (the level-1 box
// grown to 1.2 × the predicted HPL, metres) reaches it. The reason says so, with the distance.
TEST(KeepInApproval, AStartReachedByItsPlanningVolumeSaysHowFarTheZoneIs) {
  Approver a(missionOver({circleFeature("NEAR", "PROHIBITED", {0, 53}, 50)}, "start_near_zone"));
  const ApprovalReport r = a.approve();
  EXPECT_FALSE(r.approved);
  ASSERT_FALSE(r.reasons.empty());
  const Reason& why = r.reasons.front();
  EXPECT_EQ(why.kind, "zone");
  EXPECT_EQ(why.subject, "NEAR");
  EXPECT_NE(why.message.find("its planning volume (the level-1 box"), std::string::npos) << why.message;
  EXPECT_NE(why.message.find("reaches zone NEAR (PROHIBITED"), std::string::npos) << why.message;
  EXPECT_NE(why.message.find("3.0"), std::string::npos) << why.message;  // the start's own distance to it
}

// Tracking: a fix that leaves the fence is a keep_in violation at once (like a zone), and the
// replan from where the vehicle is brings it back inside.
TEST(KeepInTracking, LeavingTheFenceIsAViolationAndReplansBackInside) {
  const std::vector<Eigen::Vector2d> ring{{-300, -60}, {1800, -60}, {1800, 60}, {-300, 60}};
  auto approver = std::make_shared<Approver>(missionOver({polygonFeature("SITE", "KEEP_IN", ring)}, "keep_in_track"));
  const ApprovalReport r = approver->approve();
  ASSERT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
  Tracker tracker{TrackerOptions{}};
  tracker.addFlight("F1", parseApprovalReport(json(r), "report.json"), approver);
  auto fix = [&](double t, const Eigen::Vector3d& p, std::size_t line) {
    TrackFix f;
    f.flight = "F1";
    f.time = r.departure.plus(t);
    const Eigen::Vector2d ll = approver->frame().toLatLon(p.head<2>());
    f.lat_rad = ll.x();
    f.lon_rad = ll.y();
    f.h_ell_m = p.z();
    f.hpl_m = 2.0;
    f.vpl_m = 2.0;
    f.line = line;
    std::vector<json> out;
    for (const TrackEvent& e : tracker.process(f)) {
      // The fast line writer, the one JSON form and its reader agree on the keep-in level too.
      EXPECT_EQ(json::parse(e.jsonLine()), e.toJson()) << e.jsonLine();
      EXPECT_EQ(e.toJson().get<TrackEvent>().toJson(), e.toJson()) << e.jsonLine();
      out.push_back(e.toJson());
    }
    return out;
  };
  const std::vector<json> inside = fix(10.0, positionAlong(r.route, 10.0), 1);
  ASSERT_FALSE(inside.empty());
  EXPECT_EQ(inside.back().at("levels").at("keep_in").at("verdict"), "inside");
  EXPECT_EQ(inside.back().at("levels").at("keep_in").at("restriction"), "KEEP_IN");
  // 8 m north of the fence's edge.
  const Eigen::Vector3d out = positionAlong(r.route, 11.0) + Eigen::Vector3d(0, 68.0 - positionAlong(r.route, 11.0).y(), 0);
  const std::vector<json> events = fix(11.0, out, 2);
  const auto violation = std::find_if(events.begin(), events.end(), [](const json& e) {
    return e.at("event") == "violation" && e.at("level") == "keep_in";
  });
  ASSERT_NE(violation, events.end());
  EXPECT_EQ(violation->at("verdict"), "outside");
  EXPECT_EQ(violation->at("subject"), "SITE");
  EXPECT_NEAR(violation->at("margin_h_m").get<double>(), -8.0 - 2.0, 0.05);
  const auto replan = std::find_if(events.begin(), events.end(), [](const json& e) { return e.at("event") == "replan"; });
  ASSERT_NE(replan, events.end());
  EXPECT_EQ(replan->at("trigger"), "keep_in");
  ASSERT_EQ(replan->at("decision"), "approved") << replan->dump();
  // The new route, beyond the vehicle's own first metres, lies inside the fence.
  for (const json& p : replan->at("report").at("route")) {
    const Eigen::Vector2d xy =
        approver->frame().toPlane(maps::deg2rad(p.at("lat").get<double>()), maps::deg2rad(p.at("lon").get<double>()));
    if ((xy - out.head<2>()).norm() > 30.0) {
      EXPECT_LT(xy.y(), 60.0);
    }
  }
}

}  // namespace
}  // namespace skylane::planner
