// A stream of fence checks makes no allocation once its verdict has grown: the check writes
// into the caller's verdict (Fence::check(v, out)), its checks' strings are reused (the k-th
// check of a verdict gets the k-th of the one before), and the scene's and the keep-in check's
// scratch is per thread. Its own executable: it counts every operator new of the process.
#include "geofence/fence.hpp"
#include "tests/allocation_counter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace skylane::geofence {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

/// 40 zones along the path y = 0 (x 0 … 4 km; the fixes go on to 6 km, past the zones): squares
/// and disks 20–60 m across, 30–90 m off the path on either side, floors 0–40 m and ceilings
/// 150–200 m; zone 0 is a keep-in zone around the whole path. Identifiers and names are longer
/// than std::string keeps inline, as real ones are, and every other zone's restriction word
/// (REQ_AUTHORISATION) too.
struct Scenario {
  std::vector<airspace::Zone> zones;
  std::vector<ScenePiece> pieces;
  std::vector<KeepInVolume> keep_in;
};

Scenario scenario() {
  Scenario s;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  airspace::Zone keep;
  keep.identifier = "OPERATOR-SITE-KEEP-IN-FENCE";
  keep.name = "the operator's site fence (keep in)";
  keep.keep_in = true;
  s.zones.push_back(keep);
  s.keep_in.push_back(
      {{Vector2d(-500, -500), Vector2d(6500, -500), Vector2d(6500, 500), Vector2d(-500, 500)}, 0.0, 400.0, 0});
  for (std::size_t z = 1; z <= 40; ++z) {
    airspace::Zone zone;
    zone.identifier = "LS-GENERATED-ZONE-" + std::to_string(z);
    zone.name = std::string(z % 4 == 0 ? "a zone with a name longer than its neighbours' " : "zone number ") +
                std::to_string(z);
    zone.restriction = z % 2 == 0 ? airspace::Restriction::kReqAuthorisation : airspace::Restriction::kProhibited;
    s.zones.push_back(zone);
    const double side = 20 + 40 * u(rng), x = 100.0 * static_cast<double>(z);
    const double y = (z % 2 == 0 ? 1 : -1) * (30 + 60 * u(rng));
    airspace::PlanarPrism p;
    p.floor_h_ell_m = 40 * u(rng);
    p.ceiling_h_ell_m = 150 + 50 * u(rng);
    if (z % 3 == 0) {
      p.centre = Vector2d(x, y);
      p.radius_m = side / 2;
    } else {
      p.ring = {Vector2d(x, y), Vector2d(x + side, y), Vector2d(x + side, y + side), Vector2d(x, y + side)};
    }
    s.pieces.push_back({p, PieceOwner::kZone, z});
  }
  return s;
}

/// Fixes along the path, some in zones, PLs 1–60 m (so the count of checks varies fix to fix).
std::vector<TimedVolume> fixes() {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const maps::GpsTime t{2400, 0.0};
  std::vector<TimedVolume> out;
  for (int i = 0; i < 400; ++i) {
    const Vector3d p(6000 * u(rng), 120 * (u(rng) - 0.5), 60 + 80 * u(rng));
    const double hpl = 1 + 59 * u(rng), vpl = 1 + 59 * u(rng);
    out.push_back({t, t, {p, hpl, vpl}});
  }
  return out;
}

void expectSameCheck(const Check& a, const Check& b) {
  EXPECT_EQ(a.level, b.level);
  EXPECT_EQ(a.verdict, b.verdict);
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.subject, b.subject);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.restriction, b.restriction);
  EXPECT_EQ(a.margin_h_m, b.margin_h_m);
  EXPECT_EQ(a.margin_v_m, b.margin_v_m);
  EXPECT_EQ(a.clearance_m, b.clearance_m);
  EXPECT_EQ(a.across_joint, b.across_joint);
  EXPECT_EQ(a.exact, b.exact);
}

TEST(FenceAllocation, AStreamOfChecksIntoOneVerdictAllocatesNothingOnceGrown) {
  Scenario s = scenario();
  const std::vector<Vector3d> path{Vector3d(0, 0, 100), Vector3d(4000, 0, 100)};
  const LevelLimits limits = alertLimits({1.5, 1.2, 0.5}, {});
  const Fence fence(Corridor(path, limits.level1), Corridor(path, limits.level2),
                    Obstructions(s.zones, {}, Scene(s.pieces), {}, {}, s.keep_in));
  const std::vector<TimedVolume> volumes = fixes();

  FenceVerdict reused;
  std::size_t most = 0, least = 1000, outside = 0;
  for (const TimedVolume& v : volumes) {  // grows the verdict and each thread-local scratch
    fence.check(v, reused);
    most = std::max(most, reused.checks.size());
    least = std::min(least, reused.checks.size());
    outside += reused.verdict == Verdict::kOutside;
  }
  EXPECT_LT(least, 4u);  // the scenario reaches from no zone …
  EXPECT_GE(most, 5u);   // … to several, so that the verdict shrinks and grows
  EXPECT_GT(outside, 10u);

  EXPECT_EQ(test::allocationsOf([&] {
              for (const TimedVolume& v : volumes) fence.check(v, reused);
            }),
            0);

  // The reused verdict says what a fresh one says, fix after fix.
  for (const TimedVolume& v : volumes) {
    fence.check(v, reused);
    const FenceVerdict fresh = fence.check(v);
    EXPECT_EQ(reused.verdict, fresh.verdict);
    EXPECT_EQ(reused.violated, fresh.violated);
    EXPECT_EQ(reused.deciding, fresh.deciding);
    ASSERT_EQ(reused.checks.size(), fresh.checks.size());
    for (std::size_t k = 0; k < fresh.checks.size(); ++k) expectSameCheck(reused.checks[k], fresh.checks[k]);
  }
}

TEST(FenceAllocation, TheCounterSeesAnAllocation) {
  std::vector<SceneHit> grown;
  EXPECT_EQ(test::allocationsOf([&] { grown.resize(3); }), 1);  // the library's way of allocating
  EXPECT_EQ(grown.size(), 3u);
}

}  // namespace
}  // namespace skylane::geofence
