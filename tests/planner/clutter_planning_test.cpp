// Routes through clutter (issue 22): the lattice seed refined by OMPL finds the route that an
// independent grid search proves to exist, every motion of it clear of every obstacle (exact
// segment-to-centre distances, not the planner's samples); a field with no route is still
// rejected with its reason; the approval of a cluttered field is approved and every sample clear.
#include "planner/approval.hpp"
#include "planner/lattice_search.hpp"
#include "planner/route_planner.hpp"

#include "geofence/corridor.hpp"
#include "maps/geodesy.hpp"
#include "maps/plane_frame.hpp"
#include "tests/planner/disc_field_proof.hpp"
#include "tests/planner/map_frame_json.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

namespace skylane::planner {
namespace {

using nlohmann::json;

/// A disc obstacle: centre x, y and radius [m].
using Disc = Eigen::Vector3d;

/// `count` discs of radius [r_min, r_max] uniform over [x0, x1] × [y0, y1], none within `keep_m`
/// (plus its radius) of the points in `clear`.
std::vector<Disc> scatter(std::uint64_t seed, int count, const Eigen::Vector4d& area, double r_min, double r_max,
                          const std::vector<Eigen::Vector2d>& clear, double keep_m) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Disc> out;
  while (static_cast<int>(out.size()) < count) {
    const Eigen::Vector2d c(area[0] + u(rng) * (area[1] - area[0]), area[2] + u(rng) * (area[3] - area[2]));
    const double r = r_min + (r_max - r_min) * u(rng);
    if (std::any_of(clear.begin(), clear.end(), [&](const Eigen::Vector2d& p) { return (p - c).norm() < keep_m + r; })) {
      continue;
    }
    out.emplace_back(c.x(), c.y(), r);
  }
  return out;
}

/// Exact distance from the segment a–b (horizontal) to the point c.
double segmentDistance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d d = b - a;
  const double t = d.squaredNorm() > 0.0 ? std::clamp((c - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * d - c).norm();
}

/// Independently of the planner (disc_field_proof.hpp): whether start and goal are joined
/// through 1 m cells farther than radius + grow_m from every disc. A "yes" proves a route exists;
/// `area` is x0, x1, y0, y1.
bool gridProvesARoute(const std::vector<Disc>& discs, const Eigen::Vector4d& area, double grow_m,
                      const Eigen::Vector2d& start, const Eigen::Vector2d& goal) {
  return test::proveRouteThroughDiscs(discs, area, 1.0, grow_m, start, goal).route;
}

// --- planPath on its own -----------------------------------------------------------------------

const Eigen::Vector4d kField{0, 1200, 0, 800};
const Eigen::Vector2d kStart{100, 100}, kGoal{1100, 700};

/// 700 discs (radius 8–20 m) over 1.2 km × 0.8 km: about 38 % of it covered.
const std::vector<Disc>& fieldDiscs() {
  static const std::vector<Disc> discs = scatter(22, 700, kField, 8.0, 20.0, {kStart, kGoal}, 30.0);
  return discs;
}

/// Valid: inside the box and more than radius + 0.5 m from every disc centre.
PathProblem clutterProblem(PlannerKind kind) {
  PathProblem p;
  p.lower_enu_m = Eigen::Vector3d(kField[0], kField[2], 0);
  p.upper_enu_m = Eigen::Vector3d(kField[1], kField[3], 100);
  p.start_enu_m = Eigen::Vector3d(kStart.x(), kStart.y(), 50);
  p.goal_enu_m = Eigen::Vector3d(kGoal.x(), kGoal.y(), 50);
  p.is_valid = [](const Eigen::Vector3d& x) {
    return std::none_of(fieldDiscs().begin(), fieldDiscs().end(),
                        [&](const Disc& c) { return (x.head<2>() - c.head<2>()).norm() <= c.z() + 0.5; });
  };
  p.resolution_m = 2.0;
  p.time_limit_s = 60.0;  // a safety net: the budgets end the searches (reproducible)
  p.max_iterations = 200;
  p.seed = 3;
  p.planner = kind;
  return p;
}

/// Every motion of the path clear of every disc (exact distances), from start to goal.
void expectClearRoute(const PathResult& r) {
  ASSERT_EQ(r.status, PathStatus::kExact);
  ASSERT_GE(r.points.size(), 2u);
  EXPECT_EQ(r.points.front(), Eigen::Vector3d(kStart.x(), kStart.y(), 50));
  EXPECT_EQ(r.points.back(), Eigen::Vector3d(kGoal.x(), kGoal.y(), 50));
  double closest = 1e9;
  for (std::size_t i = 1; i < r.points.size(); ++i) {
    for (const Disc& c : fieldDiscs()) {
      closest = std::min(closest, segmentDistance(r.points[i - 1].head<2>(), r.points[i].head<2>(), c.head<2>()) - c.z());
    }
  }
  EXPECT_GT(closest, 0.0) << "a motion meets a disc";
}

TEST(ClutterPlanning, AGridSearchProvesTheRouteExistsAndTheLatticeSeedFindsItClear) {
  ASSERT_TRUE(gridProvesARoute(fieldDiscs(), kField, 0.5, kStart, kGoal));
  const PathResult r = planPath(clutterProblem(PlannerKind::kLattice));
  expectClearRoute(r);
  EXPECT_TRUE(r.lattice_searched);
  EXPECT_TRUE(r.lattice_seed);
  EXPECT_GT(r.lattice_state_checks, 0u);
  // The refined route is no longer than the straight line through the clutter allows, and not
  // absurdly long: within 1.5 × the direct distance (the seed is the lattice's shortest path,
  // plain A*, and the simplifier only shortens it).
  EXPECT_GE(r.length_m, (kGoal - kStart).norm());
  EXPECT_LT(r.length_m, 1.5 * (kGoal - kStart).norm());
}

TEST(ClutterPlanning, RrtStarThatRunsOutOfIterationsFallsBackToTheLatticeSeed) {
  PathProblem plain = clutterProblem(PlannerKind::kRrtStar);
  plain.lattice_fallback = false;
  const PathResult alone = planPath(plain);
  ASSERT_NE(alone.status, PathStatus::kExact) << "RRT* found it in 200 iterations: the fallback is not exercised";
  EXPECT_FALSE(alone.lattice_searched);

  const PathResult r = planPath(clutterProblem(PlannerKind::kRrtStar));
  expectClearRoute(r);
  EXPECT_TRUE(r.lattice_seed);
  EXPECT_EQ(r.iterations, alone.iterations);  // the same OMPL search ran first
}

TEST(ClutterPlanning, SameProblemSameRoute) {
  const PathResult a = planPath(clutterProblem(PlannerKind::kLattice));
  const PathResult b = planPath(clutterProblem(PlannerKind::kRrtStar));  // another query in between
  const PathResult c = planPath(clutterProblem(PlannerKind::kLattice));
  ASSERT_EQ(a.status, PathStatus::kExact);
  ASSERT_EQ(b.status, PathStatus::kExact);
  EXPECT_EQ(a.points, c.points);
  EXPECT_EQ(a.lattice_state_checks, c.lattice_state_checks);
}

TEST(ClutterPlanning, AWallAcrossTheFieldLeavesNoRouteAndTheLatticeSaysSo) {
  PathProblem p = clutterProblem(PlannerKind::kRrtStar);
  const auto cluttered = p.is_valid;
  p.is_valid = [cluttered](const Eigen::Vector3d& x) { return std::abs(x.x() - 600.0) > 20.0 && cluttered(x); };
  // The searches end by exhaustion, not by the clock: ≈ 1.7 s in a release build, but over a
  // minute under AddressSanitizer on a slow 2-vCPU VM, so the safety net is set well above that
  // (and below ctest's 600 s).
  p.time_limit_s = 300.0;
  const PathResult r = planPath(p);
  EXPECT_NE(r.status, PathStatus::kExact);
  EXPECT_TRUE(r.lattice_searched);
  EXPECT_FALSE(r.lattice_seed);
  EXPECT_DOUBLE_EQ(r.lattice_step_m, p.resolution_m);  // down to the finest step
  // Every lattice searched to its end (the reachable side exhausted), not cut short.
  EXPECT_FALSE(r.lattice_budget_spent);
  EXPECT_FALSE(r.stopped_by_time);
}

// --- the approval of a cluttered field --------------------------------------------------------

constexpr double kLat0 = 47.40, kLon0 = 8.50;
const test::MapFrameJson kMap(kLat0, kLon0);
json lonLat(const Eigen::Vector2d& xy) { return kMap.lonLat(xy); }

const Eigen::Vector4d kApprovalField{-200, 2200, -200, 1400};
const Eigen::Vector2d kApprovalGoal{2000, 1200};

/// 1,000 prohibited circles (radius 10–25 m) over 2.4 km × 1.6 km round a 2.3 km leg from the
/// frame's origin; the receiver declares HPL 4 m, VPL 6 m.
Mission clutterMission(const std::vector<Disc>& discs, const std::string& algorithm) {
  json features = json::array();
  for (std::size_t i = 0; i < discs.size(); ++i) {
    features.push_back({{"type", "Feature"},
                        {"properties", {{"identifier", "C-" + std::to_string(i)}, {"restriction", "PROHIBITED"},
                                        {"radius_m", discs[i].z()}}},
                        {"geometry", {{"type", "Point"}, {"coordinates", lonLat(discs[i].head<2>())}}}});
  }
  const std::string zones = test::scratchPath("clutter_" + algorithm + "_zones.geojson");
  std::ofstream(zones) << json{{"type", "FeatureCollection"}, {"features", features}}.dump();
  const json g = lonLat(kApprovalGoal);
  json m{{"name", "clutter"},
         {"vehicle", {{"lateral_m", 1.2}, {"longitudinal_m", 1.0}, {"cruise_speed_mps", 12}}},
         {"k1", 1.2},
         {"k2", 150},
         {"start", {{"lat", kLat0}, {"lon", kLon0}}},
         {"goal", {{"lat", g[1]}, {"lon", g[0]}}},
         {"departure", "2020-01-01T14:00:00Z"},
         {"zones", {zones}},
         {"ground_amsl_m", 408},
         {"orbits", {test::dataPath("gnss/alm01jan2020.txt")}},
         {"navigation", {{"kind", "receiver"}, {"hpl_m", 4.0}, {"vpl_m", 6.0}}},
         {"integrity", {{"cost_weight", 0.0}}},
         {"planner", {{"algorithm", algorithm}, {"iterations", 100}, {"seed", 5}, {"resolution_m", 3.0}, {"margin_m", 200}}}};
  return parseMission(m, "clutter.json", ".");
}

TEST(ClutterApproval, AClutteredFieldWithARouteIsApprovedAndEverySampleIsClear) {
  const std::vector<Disc> discs = scatter(7, 1000, kApprovalField, 10.0, 25.0, {{0, 0}, kApprovalGoal}, 60.0);
  const Mission m = clutterMission(discs, "rrtstar");
  const geofence::LevelLimits limits = geofence::alertLimits(m.vehicle, m.levels);
  const double grow_m = std::max(limits.level1.hal_m, 1.2 * 4.0);
  ASSERT_TRUE(gridProvesARoute(discs, kApprovalField, grow_m + 1.0, {0, 0}, kApprovalGoal));

  const ApprovalReport r = Approver(m).approve();
  ASSERT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
  EXPECT_EQ(r.planner.lattice_legs_searched, 1);  // RRT*'s 100 iterations did not do
  EXPECT_EQ(r.planner.lattice_legs_seeded, 1);
  ASSERT_GT(r.predicted.size(), 100u);
  // Every sample's protection volume (radius HPL = 4 m) clear of every circle, by exact distance.
  double closest = 1e9;
  for (const PredictedSample& s : r.predicted) {
    EXPECT_TRUE(s.pl_available);
    for (const Disc& c : discs) closest = std::min(closest, (s.xyz.head<2>() - c.head<2>()).norm() - c.z() - s.hpl_m);
  }
  EXPECT_GT(closest, 0.0);
  // And the route's legs, between the samples, clear of every circle too.
  for (std::size_t i = 1; i < r.route.size(); ++i) {
    for (const Disc& c : discs) {
      EXPECT_GT(segmentDistance(r.route[i - 1].xyz.head<2>(), r.route[i].xyz.head<2>(), c.head<2>()), c.z() + 4.0);
    }
  }
}

}  // namespace
}  // namespace skylane::planner
