#include "geofence/corridor.hpp"

#include "tests/test_util.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <functional>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstring>
#include <random>
#include <stdexcept>
#include <vector>

namespace skylane::geofence {
namespace {

constexpr double kPi = 3.141592653589793;

// --- alert limits ------------------------------------------------------------------------------

TEST(BoxLevels, AlertLimitsScaleTheMappedDimensions) {
  // GIVEN a 1.0 m span, 0.8 m long, 0.3 m high vehicle with the patent's mapping
  const Vehicle v{1.0, 0.8, 0.3};
  const LevelLimits l = alertLimits(v, BoxLevels{});
  // THEN HAL = k·lateral and VAL = k·longitudinal at k₁ = 1.2 and k₂ = 300
  EXPECT_DOUBLE_EQ(l.level1.hal_m, 1.2);
  EXPECT_DOUBLE_EQ(l.level1.val_m, 0.96);
  EXPECT_DOUBLE_EQ(l.level2.hal_m, 300.0);
  EXPECT_DOUBLE_EQ(l.level2.val_m, 240.0);
  EXPECT_TRUE(l.warnings.empty());
  // AND the mapping is configurable (VAL from the height)
  BoxLevels by_height;
  by_height.mapping.vertical = Dimension::kHeight;
  EXPECT_DOUBLE_EQ(alertLimits(v, by_height).level1.val_m, 1.2 * 0.3);
}

TEST(BoxLevels, FactorsOutsideTheirRangesNeedAnOverride) {
  const Vehicle v{1.0, 0.8, 0.3};
  BoxLevels wide;
  wide.k1 = 1.5;
  const std::string msg = test::messageOf<std::invalid_argument>([&] { (void)alertLimits(v, wide); });
  EXPECT_NE(msg.find("k1 = 1.5 is outside the box levels' range [1.1, 1.3]"), std::string::npos) << msg;
  wide.override_ranges = true;
  const LevelLimits l = alertLimits(v, wide);
  EXPECT_DOUBLE_EQ(l.level1.hal_m, 1.5);
  ASSERT_EQ(l.warnings.size(), 1u);
  EXPECT_NE(l.warnings[0].find("accepted by override"), std::string::npos);
  BoxLevels tiny;
  tiny.k2 = 50;
  EXPECT_THROW((void)alertLimits(v, tiny), std::invalid_argument);
  EXPECT_THROW((void)alertLimits(Vehicle{0.0, 0.8, 0.3}, BoxLevels{}), std::invalid_argument);
}

// --- containment ---------------------------------------------------------------------------------

TEST(Corridor, StraightLevelSegmentMarginsAreTheOffsetsFromTheWalls) {
  // GIVEN a level corridor 100 m east at 100 m, HAL 6 m, VAL 4 m
  const Corridor c({{0, 0, 100}, {100, 0, 100}}, {6.0, 4.0});
  // WHEN the volume is 2 m off the centre line and 1 m high, HPL 3, VPL 2
  const Containment in = c.contains({{50, 2, 101}, 3.0, 2.0});
  // THEN the margins are 6 − 2 − 3 = 1 and 4 − 1 − 2 = 1
  EXPECT_EQ(in.verdict, Verdict::kInside);
  EXPECT_NEAR(in.margin_h_m, 1.0, 1e-12);
  EXPECT_NEAR(in.margin_v_m, 1.0, 1e-12);
  EXPECT_FALSE(in.across_joint);
  // A larger HPL sticks out by 0.5 m; exactly at the wall is indeterminate.
  EXPECT_EQ(c.contains({{50, 2, 101}, 4.5, 2.0}).verdict, Verdict::kOutside);
  EXPECT_NEAR(c.contains({{50, 2, 101}, 4.5, 2.0}).margin_h_m, -0.5, 1e-12);
  EXPECT_EQ(c.contains({{50, 2, 101}, 4.0, 2.0}).verdict, Verdict::kIndeterminate);
  // The centre inside but the volume's top through the ceiling: outside (the volume counts).
  EXPECT_EQ(c.contains({{50, 0, 103}, 1.0, 2.0}).verdict, Verdict::kOutside);
  // Beyond the end, within the end cylinder: inside.
  EXPECT_EQ(c.contains({{103, 0, 100}, 2.0, 1.0}).verdict, Verdict::kInside);
  EXPECT_THROW((void)c.contains({{NAN, 0, 100}, 1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW((void)c.contains({{0, 0, 100}, -1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW((void)c.contains({{50, 2, 101}, 3.0, 2.0}, -1e-6), std::invalid_argument);
  EXPECT_THROW((void)c.contains({{50, 2, 101}, 3.0, 2.0}, NAN), std::invalid_argument);
}

TEST(Corridor, ClimbingSegmentTakesTheSlopeAcrossTheDisk) {
  // GIVEN a segment climbing 50 m over 100 m (slope 0.5), VAL 4
  const Corridor c({{0, 0, 0}, {100, 0, 50}}, {6.0, 4.0});
  // WHEN a volume of HPL 2, VPL 1 is on the centre line at x = 50 (z = 25)
  const Containment r = c.contains({{50, 0, 25}, 2.0, 1.0});
  // THEN the ceiling over the disk is lowest at x = 48: 24 + 4 = 28, the top 26 → margin 2
  EXPECT_EQ(r.verdict, Verdict::kInside);
  EXPECT_NEAR(r.margin_v_m, 2.0, 1e-12);
}

TEST(Corridor, OperatingLimitsClipTheBoxes) {
  // GIVEN a level-2 box (HAL 300, VAL 240 round 100 m) under a 150 m operating ceiling
  const Corridor c({{0, 0, 100}, {100, 0, 100}}, {300.0, 240.0}, {0.0, 150.0});
  // THEN a volume reaching 148 m is inside by 2 m, one reaching 153 m is out by 3 m
  EXPECT_NEAR(c.contains({{50, 0, 140}, 5.0, 8.0}).margin_v_m, 2.0, 1e-12);
  const Containment r = c.contains({{50, 0, 145}, 5.0, 8.0});
  EXPECT_EQ(r.verdict, Verdict::kOutside);
  EXPECT_NEAR(r.margin_v_m, -3.0, 1e-12);
  EXPECT_THROW(Corridor({{0, 0, 0}, {1, 0, 0}}, {1, 1}, {10.0, 5.0}), std::invalid_argument);
  EXPECT_THROW(Corridor({{0, 0, 0}}, {1, 1}), std::invalid_argument);
}

TEST(Corridor, JointAtARightAngleTurnIsCovered) {
  // GIVEN a path east then north with a 90° turn at (100, 0), HAL 6
  const Corridor c({{0, 0, 50}, {100, 0, 50}, {100, 100, 50}}, {6.0, 4.0});
  // WHEN the volume is off the outer corner, at (103, −3), HPL 1: outside both boxes' rectangles
  const Containment r = c.contains({{103, -3, 50}, 1.0, 1.0});
  // THEN the joint cylinder holds it: margin 6 − √18 − 1
  EXPECT_EQ(r.verdict, Verdict::kInside);
  EXPECT_NEAR(r.margin_h_m, 6.0 - std::sqrt(18.0) - 1.0, 1e-12);
  // AND inside the turn, a volume at (98, 2) with HPL 4.5 is held by no single piece
  // (6 − 2 − 4.5 < 0) but by their union: its farthest point from the path lies along the
  // bisector, 2 + 4.5/√2 from both legs, so the union margin is 6 − 2 − 4.5/√2 = 0.818 m.
  const Containment inner = c.contains({{98, 2, 50}, 4.5, 1.0});
  EXPECT_EQ(inner.verdict, Verdict::kInside);
  EXPECT_TRUE(inner.across_joint);
  EXPECT_LE(inner.margin_h_m, 6.0 - 2.0 - 4.5 / std::sqrt(2.0) + 1e-12);
  EXPECT_GE(inner.margin_h_m, 6.0 - 2.0 - 4.5 / std::sqrt(2.0) - 6e-3);  // certified to HAL/1000
  // AND at (97, 3) with HPL 5 the bisector point is 3 + 5/√2 = 6.54 m from both legs: outside
  EXPECT_EQ(c.contains({{97, 3, 50}, 5.0, 1.0}).verdict, Verdict::kOutside);
}

/// The whole scene moved: rotated about the vertical by `yaw` and translated by `t`.
Eigen::Vector3d moved(const Eigen::Vector3d& p, double yaw, const Eigen::Vector3d& t) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * p + t;
}

/// The containment of the volume in the corridor along the path, both turned by a random yaw and
/// shifted by up to 100 km (drawn from rng).
Containment containsInRandomFrame(const std::vector<Eigen::Vector3d>& path, const ProtectionVolume& volume,
                                  const AlertLimits& limits, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double yaw = 2 * kPi * u(rng);
  const Eigen::Vector3d shift(-1e5 + 2e5 * u(rng), -1e5 + 2e5 * u(rng), 0.0);
  std::vector<Eigen::Vector3d> p2;
  for (const Eigen::Vector3d& p : path) p2.push_back(moved(p, yaw, shift));
  return Corridor(p2, limits).contains({moved(volume.p_map, yaw, shift), volume.hpl_m, volume.vpl_m});
}

TEST(Corridor, MarginsDoNotJumpWhereTheUnionStopsHelpingAtAJoint) {
  // GIVEN a volume at a turn, horizontally well inside both pieces (h 16 m and 18 m) but 27 m
  // below both (v -27 m for both): the union's margin equals the best piece's min(h, v) = v, so
  // whether the union is "better", and which piece is best, rested on the last bit of sums whose
  // rounding depends on the frame.
  const std::vector<Eigen::Vector3d> path{{0, 0, 100}, {100, 0, 100}, {100, 100, 100}};
  const ProtectionVolume volume{{99, 3, 60}, 5.0, 5.0};
  const AlertLimits limits{24.0, 18.0};
  const Containment base = Corridor(path, limits).contains(volume);
  ASSERT_EQ(base.verdict, Verdict::kOutside);
  // WHEN the scene is moved to 2,000 frames (rotated, translated up to 100 km)
  std::mt19937 rng(3);
  for (int k = 0; k < 2000; ++k) {
    const Containment c = containsInRandomFrame(path, volume, limits, rng);
    // THEN the union gains nothing in any frame: the best piece's exact margins, the same in every
    // frame (before the fix, a clang build took the union's (v, v) in some frames on a last-bit
    // difference of two equal sums)
    EXPECT_FALSE(c.across_joint) << "frame " << k;
    ASSERT_NEAR(c.margin_h_m, base.margin_h_m, 1e-6) << "frame " << k;
    ASSERT_NEAR(c.margin_v_m, base.margin_v_m, 1e-6) << "frame " << k;
    ASSERT_EQ(c.verdict, Verdict::kOutside);
  }
  // The tie on v goes to the piece with more horizontal room: the second leg, 1 m away (not the
  // first, 3 m away, which came first).
  EXPECT_NEAR(base.margin_h_m, 24.0 - 1.0 - 5.0, 1e-9);  // HAL - offset from the second leg - HPL
  EXPECT_EQ(base.segment, 1u);
  EXPECT_NEAR(base.margin_v_m, (60.0 - 5.0) - (100.0 - 18.0), 1e-9);  // volume bottom - band floor
}

TEST(Corridor, MarginHDoesNotJumpWhereTheUnionGainsLessThanTheSearchAccuracy) {
  // GIVEN trial 199 of Fence.WholeSceneTranslatedAndRotated: a volume below the turn, 26.36 m
  // below the second leg's band (v) and 11.30 m horizontally beyond it (h), level-1 limits HAL
  // 24 m, VAL 18 m. The union of the legs gains 7.6 mm over that leg, less than the branch and
  // bound's accuracy (HAL/1000 = 24 mm): its certified bound beat the piece in one frame and not
  // in the rotated one (clang ASan build), and the report flipped between the union's (L, L) =
  // (-26.35, -26.35) and the piece's (h, v) = (-11.30, -26.36).
  const std::vector<Eigen::Vector3d> path{{0, 0, 100}, {400, 14.596468731341119, 110}, {547.53945159247439, 400, 100}};
  const ProtectionVolume volume{{382.0924875725035, 21.380898356221877, 152.3447748932457}, 16.154114946330786, 1.6276334237202144};
  const AlertLimits limits{24.0, 18.0};
  // The second leg's horizontal margin by hand: HAL − distance to the segment − HPL.
  const Eigen::Vector2d a = path[1].head<2>(), d = (path[2] - path[1]).head<2>(), x = volume.p_map.head<2>();
  const double t = std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  const double h_leg2 = 24.0 - (x - (a + t * d)).norm() - volume.hpl_m;
  // WHEN the scene is moved to 2,000 frames
  std::mt19937 rng(199);
  for (int k = 0; k < 2000; ++k) {
    const Containment c = containsInRandomFrame(path, volume, limits, rng);
    // THEN, whether or not the union is reported, margin_h is the leg's h (the union's horizontal
    // room is at least the leg's) and margin_v is within the accuracy of the leg's v
    ASSERT_EQ(c.verdict, Verdict::kOutside) << "frame " << k;
    EXPECT_EQ(c.segment, 1u) << "frame " << k;
    ASSERT_NEAR(c.margin_h_m, h_leg2, 1e-6) << "frame " << k << (c.across_joint ? " (union)" : " (piece)");
    ASSERT_NEAR(c.margin_v_m, -26.36, 0.024 + 0.01) << "frame " << k;
  }
  EXPECT_NEAR(h_leg2, -11.30, 0.01);
}

TEST(Corridor, AVolumeCentredOnAWaypointIsDecidedWithoutCoveringTheArcOfEqualMargins) {
  // GIVEN fuzz_fence's seed corridor as a path (level, then a 5 m climb; level-1 limits HAL
  // 1.8 m, VAL 0.6 m) and volumes centred on its first waypoint and on its turn, HPL 900 m,
  // VPL 300 m: far outside. Every point of the disk's boundary behind the end cap (or outside
  // the turn) is 900 m from the path, so the union's margin hal − HPL is attained along an arc,
  // and the branch and bound, narrowing it to HAL/1000, ran into its 200,000-cell cap (a
  // fuzz_fence timeout). The union gains nothing there, which the first boundary point shows.
  const std::vector<Eigen::Vector3d> path{{0, 0, 515}, {170, 120, 515}, {320, 255, 520}};
  const AlertLimits limits{1.8, 0.6};
  const Corridor c(path, limits);
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < 50; ++k) {
    for (const Eigen::Vector3d& at : {path[0], path[1]}) {
      const Containment r = c.contains({at, 900.0, 300.0});
      // THEN the best single piece's exact margins: h = HAL − 0 − HPL, v = VAL − VPL
      ASSERT_EQ(r.verdict, Verdict::kOutside);
      EXPECT_FALSE(r.across_joint);
      EXPECT_NEAR(r.margin_h_m, 1.8 - 900.0, 1e-9);
      EXPECT_NEAR(r.margin_v_m, 0.6 - 300.0, 1e-9);
    }
  }
  // AND quickly: 100 checks in well under 2 s (each took the cap's 200,000 cells before)
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

TEST(Corridor, VerdictsAndMarginsAreFrameInvariant) {
  const std::vector<Eigen::Vector3d> path{{0, 0, 50}, {100, 0, 60}, {100, 100, 60}, {30, 150, 40}};
  const std::vector<ProtectionVolume> volumes{{{50, 2, 56}, 3.0, 2.0}, {{103, -3, 60}, 1.0, 1.0},
                                              {{98, 2, 59}, 4.5, 1.0}, {{97, 3, 60}, 5.0, 1.0},
                                              {{70, 120, 52}, 2.0, 1.5}, {{0, 0, 50}, 10.0, 1.0}};
  const Corridor base(path, {6.0, 4.0});
  for (const double yaw : {0.3, -2.0, kPi / 2}) {
    const Eigen::Vector3d t(-250000.0, 4.2e6, 300.0);
    std::vector<Eigen::Vector3d> p2;
    for (const Eigen::Vector3d& p : path) p2.push_back(moved(p, yaw, t));
    const Corridor turned(p2, {6.0, 4.0});
    for (std::size_t k = 0; k < volumes.size(); ++k) {
      const Containment a = base.contains(volumes[k]);
      const Containment b = turned.contains({moved(volumes[k].p_map, yaw, t), volumes[k].hpl_m, volumes[k].vpl_m});
      EXPECT_EQ(a.verdict, b.verdict) << "volume " << k << " yaw " << yaw;
      // Exact for one piece; across a joint both are certified to within HAL/1000.
      const double tol = a.across_joint ? 6e-3 : 1e-6;
      EXPECT_EQ(a.across_joint, b.across_joint) << "volume " << k << " yaw " << yaw;
      EXPECT_NEAR(a.margin_h_m, b.margin_h_m, tol) << "volume " << k << " yaw " << yaw;
      EXPECT_NEAR(a.margin_v_m, b.margin_v_m, tol) << "volume " << k << " yaw " << yaw;
    }
  }
}

/// Whether the point lies in some piece, computed independently: horizontal distance to the
/// segment ≤ HAL and height within VAL of the centre line at the nearest point.
bool inSomePiece(const std::vector<Eigen::Vector3d>& path, const Eigen::Vector3d& x, double hal, double val) {
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::Vector2d a = path[i].head<2>(), b = path[i + 1].head<2>();
    const double t = std::clamp((x.head<2>() - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    const double z = path[i].z() + t * (path[i + 1].z() - path[i].z());
    if ((x.head<2>() - (a + t * (b - a))).norm() <= hal && std::abs(x.z() - z) <= val) return true;
  }
  return false;
}

TEST(Corridor, RandomScenesInsideMeansEverySampledPointIsInAPieceAndLargerPlsNeverTurnInside) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int inside = 0, outside = 0, joints = 0;
  for (int scene = 0; scene < 300; ++scene) {
    std::vector<Eigen::Vector3d> path{{0, 0, 100}};
    for (int k = 0; k < 4; ++k) {
      const double heading = 2 * kPi * u(rng), length = 20 + 80 * u(rng);
      path.push_back(path.back() + Eigen::Vector3d(length * std::cos(heading), length * std::sin(heading), -10 + 20 * u(rng)));
    }
    const double hal = 3 + 10 * u(rng), val = 2 + 6 * u(rng);
    const Corridor c(path, {hal, val});
    for (int k = 0; k < 20; ++k) {
      // A position near a random point of the path.
      const std::size_t seg = rng() % 4;
      const Eigen::Vector3d on = path[seg] + u(rng) * (path[seg + 1] - path[seg]);
      const Eigen::Vector3d p = on + Eigen::Vector3d(hal * (2 * u(rng) - 1), hal * (2 * u(rng) - 1), val * (2 * u(rng) - 1));
      const double hpl = hal * u(rng), vpl = val * u(rng);
      const Containment r = c.contains({p, hpl, vpl});
      if (r.verdict == Verdict::kInside) {
        ++inside;
        joints += r.across_joint ? 1 : 0;
        // THEN every sampled point of the cylinder lies in some piece
        for (int s = 0; s < 200; ++s) {
          const double a = 2 * kPi * u(rng), rr = hpl * std::sqrt(u(rng));
          const Eigen::Vector3d x = p + Eigen::Vector3d(rr * std::cos(a), rr * std::sin(a), vpl * (2 * u(rng) - 1));
          ASSERT_TRUE(inSomePiece(path, x, hal, val)) << "scene " << scene << " volume " << k << " sample " << s;
        }
      } else {
        ++outside;
      }
      // AND a larger HPL or VPL never turns "not inside" into "inside"
      if (r.verdict != Verdict::kInside) {
        EXPECT_NE(c.contains({p, hpl * 1.1 + 0.01, vpl}).verdict, Verdict::kInside) << "scene " << scene;
        EXPECT_NE(c.contains({p, hpl, vpl * 1.1 + 0.01}).verdict, Verdict::kInside) << "scene " << scene;
      }
    }
  }
  // The scenes exercise both outcomes and the joints.
  EXPECT_GT(inside, 500);
  EXPECT_GT(outside, 500);
  EXPECT_GT(joints, 10);
}

// --- end caps: the climb counts only where the disk projects inside the segment --------------

TEST(Corridor, VolumeInsideTheEndCapOfAClimbingLastLegIsInside) {
  // GIVEN a last leg climbing 50 m over 100 m (g = 0.5) to (100, 0, 50), HAL 6, VAL 4
  const Corridor c({{-50, 0, 0}, {0, 0, 0}, {100, 0, 50}}, {6.0, 4.0});
  // WHEN a volume (HPL 2, VPL 1) lies wholly beyond the last waypoint, its disk x ∈ [100.5, 104.5]
  // in the end cap, where the centre line is flat at 50 m, and its top at 53.5 m
  const Containment in = c.contains({{102.5, 0, 52.5}, 2.0, 1.0});
  // THEN it is inside by 54 − 53.5 = 0.5 m < g·HPL = 1 m (the climb does not count in the cap)
  EXPECT_EQ(in.verdict, Verdict::kInside);
  EXPECT_EQ(in.segment, 1u);
  EXPECT_FALSE(in.across_joint);
  EXPECT_NEAR(in.margin_v_m, 0.5, 1e-12);
  EXPECT_NEAR(in.margin_h_m, 6.0 - 2.5 - 2.0, 1e-12);
  // AND 1 m higher its top pokes 0.5 m through the cap's ceiling: outside
  const Containment out = c.contains({{102.5, 0, 53.5}, 2.0, 1.0});
  EXPECT_EQ(out.verdict, Verdict::kOutside);
  EXPECT_NEAR(out.margin_v_m, -0.5, 1e-12);
  // AND below the cap the floor is flat too: bottom at 46.5 m is inside by 0.5 m
  EXPECT_NEAR(c.contains({{102.5, 0, 47.5}, 2.0, 1.0}).margin_v_m, 0.5, 1e-12);
}

TEST(Corridor, VolumeStraddlingTheEndSeesTheClimbOnlyAlongTheSegment) {
  // GIVEN the same climbing leg, and a volume centred on its end waypoint (disk x ∈ [98, 102])
  const Corridor c({{0, 0, 0}, {100, 0, 50}}, {6.0, 4.0});
  // WHEN it is 1.5 m below the waypoint, VPL 1
  const Containment r = c.contains({{100, 0, 48.5}, 2.0, 1.0});
  // THEN the centre line over the disk spans 49 m (x = 98) to 50 m (the cap): the floor is
  // 50 − 4 = 46 m under the cap, the bottom 47.5 m → margin 1.5 (a g·HPL bound on both sides
  // would say 0.5); the ceiling is 49 + 4 = 53 m, the top 49.5 m
  EXPECT_EQ(r.verdict, Verdict::kInside);
  EXPECT_NEAR(r.margin_v_m, 1.5, 1e-12);
  // AND the path's first waypoint has a cap too: before (0, 0, 0) the floor is flat at −4 m
  EXPECT_NEAR(c.contains({{-2.5, 0, -2.5}, 2.0, 1.0}).margin_v_m, 0.5, 1e-12);
  EXPECT_EQ(c.contains({{-2.5, 0, -3.5}, 2.0, 1.0}).verdict, Verdict::kOutside);
}

TEST(Corridor, AColumnCoveredByTwoLegsTogetherIsInside) {
  // GIVEN a hairpin: a leg climbing from (0, 0, 0) to (100, 0, 50), then a level leg back to
  // (0, 4, 50), HAL 6, VAL 15 — at x = 50 the first leg holds heights [10, 40], the second
  // [35, 65]
  const Corridor c({{0, 0, 0}, {100, 0, 50}, {0, 4, 50}}, {6.0, 15.0});
  // WHEN a volume between the legs spans 27.5 … 47.5 m (HPL 1, VPL 10)
  const Containment r = c.contains({{50, 2, 37.5}, 1.0, 10.0});
  // THEN neither leg holds its columns alone but both together do, with room 17 m up and down;
  // the margin is the horizontal one, 6 − (2 + 1) = 3 m, certified to HAL/1000
  EXPECT_EQ(r.verdict, Verdict::kInside);
  EXPECT_TRUE(r.across_joint);
  EXPECT_LE(r.margin_v_m, 3.0 + 1e-12);
  EXPECT_GE(r.margin_v_m, 3.0 - 6e-3);
  // AND when the legs' bands leave a gap (VAL 10: [15, 35] and [40, 60]) the volume is outside
  const Corridor gap({{0, 0, 0}, {100, 0, 50}, {0, 4, 50}}, {6.0, 10.0});
  EXPECT_EQ(gap.contains({{50, 2, 37.5}, 1.0, 5.0}).verdict, Verdict::kOutside);
}

/// The oracle's margin of one point: max over the pieces of min(HAL − distance, VAL − |height −
/// centre line at the nearest point|), straight from the piece definition (positive inside).
double pointMarginInSomePiece(const std::vector<Eigen::Vector3d>& path, const Eigen::Vector3d& x, double hal,
                              double val) {
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::Vector2d a = path[i].head<2>(), b = path[i + 1].head<2>();
    const double t = std::clamp((x.head<2>() - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    const double z = path[i].z() + t * (path[i + 1].z() - path[i].z());
    best = std::max(best, std::min(hal - (x.head<2>() - (a + t * (b - a))).norm(), val - std::abs(x.z() - z)));
  }
  return best;
}

/// The oracle's margin of a volume: min of the point margin over a grid of its points — a
/// polar grid of its disk, each column sampled from bottom to top (the pieces' union need not
/// hold a column's heights as one interval). Sampling can only miss the minimum, so the true
/// minimum lies in [oracle − slack, oracle], slack = the point margin's Lipschitz constants
/// times the grid's spacing. The point margin's minimum is ≤ the corridor's column margin and
/// has its sign (a column grown by the smallest depth of its points still lies in the union).
struct OracleMargin {
  double margin_m;
  double slack_m;
};

OracleMargin sampledMargin(const std::vector<Eigen::Vector3d>& path, const ProtectionVolume& v, double hal, double val,
                           double max_slope) {
  constexpr int kRings = 20, kAngles = 96, kLevels = 12;
  double m = std::numeric_limits<double>::infinity();
  for (int j = 0; j <= kRings; ++j) {
    const double r = v.hpl_m * j / kRings;
    for (int k = 0; k < (j == 0 ? 1 : kAngles); ++k) {
      const double a = 2 * kPi * k / kAngles;
      const Eigen::Vector3d x = v.p_map + Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0);
      for (int l = 0; l <= kLevels; ++l) {
        const double dz = v.vpl_m * (2.0 * l / kLevels - 1.0);
        m = std::min(m, pointMarginInSomePiece(path, x + Eigen::Vector3d(0, 0, dz), hal, val));
      }
    }
  }
  // Every point of the volume is within half a ring step plus half an arc step of a sampled
  // column, and within half a level step of a sample on it; the point margin is
  // max(1, g)-Lipschitz horizontally and 1-Lipschitz vertically.
  const double spacing_m = v.hpl_m / (2.0 * kRings) + kPi * v.hpl_m / kAngles;
  return {m, std::max(1.0, max_slope) * spacing_m + v.vpl_m / kLevels};
}

TEST(Corridor, RandomClimbingEndLegsAgreeWithADenseSamplingOracle) {
  // GIVEN random two-leg paths whose legs climb or descend at up to g = 1.5, and volumes near
  // either end of the path (the caps) or straddling it
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  constexpr double kTolerance_m = 1e-6;
  int inside = 0, outside = 0, cap_cases_a_slope_bound_misses = 0, compared = 0;
  for (int scene = 0; scene < 400; ++scene) {
    std::vector<Eigen::Vector3d> path{{0, 0, 100}};
    double max_slope = 0.0;
    for (int k = 0; k < 2; ++k) {
      const double heading = 2 * kPi * u(rng), length = 20 + 80 * u(rng), g = -1.5 + 3.0 * u(rng);
      path.push_back(path.back() + Eigen::Vector3d(length * std::cos(heading), length * std::sin(heading), g * length));
      max_slope = std::max(max_slope, std::abs(g));
    }
    const double hal = 3 + 10 * u(rng), val = 2 + 6 * u(rng);
    const Corridor c(path, {hal, val});
    for (int k = 0; k < 5; ++k) {
      const Eigen::Vector3d& end = (k % 2 == 0) ? path.back() : path.front();
      const double a = 2 * kPi * u(rng), r = hal * u(rng);
      const Eigen::Vector3d p = end + Eigen::Vector3d(r * std::cos(a), r * std::sin(a), val * (2 * u(rng) - 1));
      const ProtectionVolume v{p, hal * u(rng), val * u(rng)};
      // WHEN the corridor and the oracle judge the volume
      const Containment got = c.contains(v, kTolerance_m);
      const OracleMargin oracle = sampledMargin(path, v, hal, val, max_slope);
      // THEN the verdicts agree wherever the oracle's margin is clear of the tolerance and of its
      // sampling slack, and a single-piece margin lies within the oracle's bracket
      // Across a joint the corridor certifies its margin to within max(tolerance, HAL/1000).
      const double accuracy_m = std::max(kTolerance_m, 1e-3 * hal);
      if (oracle.margin_m > kTolerance_m + accuracy_m + oracle.slack_m) {
        ++inside;
        EXPECT_EQ(got.verdict, Verdict::kInside) << "scene " << scene << " volume " << k << " oracle " << oracle.margin_m
                                                 << " got " << got.margin_h_m << " " << got.margin_v_m << " joint " << got.across_joint
                                                 << " seg " << got.segment << " p " << p.transpose() << " hpl " << v.hpl_m << " vpl "
                                                 << v.vpl_m << " hal " << hal << " val " << val << " path " << path[0].transpose() << " | "
                                                 << path[1].transpose() << " | " << path[2].transpose();
      } else if (oracle.margin_m < -kTolerance_m) {
        ++outside;
        EXPECT_NE(got.verdict, Verdict::kInside) << "scene " << scene << " volume " << k << " oracle " << oracle.margin_m;
        if (!got.across_joint) {
          EXPECT_EQ(got.verdict, Verdict::kOutside) << "scene " << scene << " volume " << k;
        }
      }
      if (got.verdict == Verdict::kInside) {
        // AND the corridor's margin is at least the oracle's (less its slack and, across a joint,
        // the accuracy), and for one piece at most the oracle's (where its columns are one piece's)
        ++compared;
        const double m = std::min(got.margin_h_m, got.margin_v_m);
        EXPECT_GE(m, oracle.margin_m - oracle.slack_m - (got.across_joint ? accuracy_m : 0.0) - 1e-9)
            << "scene " << scene << " volume " << k;
        if (!got.across_joint) {
          EXPECT_LE(m, oracle.margin_m + 1e-9) << "scene " << scene << " volume " << k;
        }
      }
      // A bound subtracting g·HPL over the whole disk (the centre's nearest point) would call
      // this volume outside: count the cases that exercise the end-cap rule.
      const Eigen::Vector2d c2 = p.head<2>();
      const std::size_t seg = (k % 2 == 0) ? 1 : 0;
      const Eigen::Vector2d s0 = path[seg].head<2>(), s1 = path[seg + 1].head<2>();
      const double t = std::clamp((c2 - s0).dot(s1 - s0) / (s1 - s0).squaredNorm(), 0.0, 1.0);
      const double g = std::abs(path[seg + 1].z() - path[seg].z()) / (s1 - s0).norm();
      const double old_v = val - v.vpl_m - std::abs(p.z() - (path[seg].z() + t * (path[seg + 1].z() - path[seg].z()))) - g * v.hpl_m;
      if (oracle.margin_m > kTolerance_m + oracle.slack_m && old_v < 0) ++cap_cases_a_slope_bound_misses;
    }
  }
  EXPECT_GT(inside, 300);
  EXPECT_GT(outside, 300);
  EXPECT_GT(compared, 300);
  EXPECT_GT(cap_cases_a_slope_bound_misses, 20);
}

/// The horizontal distance from x to the segment a–b, by projection (the test's own).
double segmentDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector2d& x) {
  const Eigen::Vector2d d = (b - a).head<2>();
  const double t = std::clamp((x - a.head<2>()).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (x - (a.head<2>() + t * d)).norm();
}

TEST(Corridor, TheNearestLegDecidesALevelCorridorFromAnyDistance) {
  // GIVEN level zig-zag corridors of 20 legs over up to 300 km (the fence benchmark's kind)
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int far = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const double span_m = trial % 2 == 0 ? 300000.0 : 3000.0;
    std::vector<Eigen::Vector3d> path;
    for (int i = 0; i < 21; ++i) path.emplace_back(span_m * i / 20.0, span_m * (0.5 + 0.3 * std::sin(i + trial)), 120.0);
    const AlertLimits limits{5.0 + 50.0 * u(rng), 5.0 + 20.0 * u(rng)};
    const Corridor c(path, limits);
    for (int k = 0; k < 200; ++k) {
      // WHEN a volume at the corridor's height lies anywhere, near the path or far from it
      Eigen::Vector2d x(span_m * (1.4 * u(rng) - 0.2), span_m * (1.4 * u(rng) - 0.2));
      if (k % 2 == 0) {
        const std::size_t i = rng() % 20;
        x = (path[i] + u(rng) * (path[i + 1] - path[i])).head<2>() + limits.hal_m * Eigen::Vector2d(u(rng) - 0.5, u(rng) - 0.5);
      }
      const ProtectionVolume v{{x.x(), x.y(), 120.0}, 0.5 + 0.4 * limits.hal_m * u(rng), 0.2 * limits.val_m * u(rng)};
      double nearest_m = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i + 1 < path.size(); ++i) nearest_m = std::min(nearest_m, segmentDistance(path[i], path[i + 1], x));
      const Containment in = c.contains(v);
      // THEN the horizontal margin is the nearest leg's, HAL − d − HPL (or more across a joint)
      const double expected_h = limits.hal_m - nearest_m - v.hpl_m;
      if (in.across_joint) {
        EXPECT_GE(in.margin_h_m, expected_h - 1e-6) << trial << "/" << k;
      } else {
        EXPECT_NEAR(in.margin_h_m, expected_h, 1e-6 * (1.0 + nearest_m)) << trial << "/" << k;
        EXPECT_NEAR(segmentDistance(path[in.segment], path[in.segment + 1], x), nearest_m, 1e-6 * (1.0 + nearest_m));
      }
      far += nearest_m > 1000.0;
    }
  }
  EXPECT_GT(far, 10000);
}

/// The best single piece as the specification scans it: every leg in order, each leg's margins
/// from a corridor of that leg alone (the same piece), a leg taking over when its min(h, v)
/// beats the best by more than the tolerance or ties it within the tolerance with a larger
/// other margin.
struct ScannedBest {
  std::size_t segment = 0;
  double h = 0, v = 0;
};
ScannedBest scanEveryLeg(const std::vector<Eigen::Vector3d>& path, const AlertLimits& limits, const OperatingLimits& operating,
                         const ProtectionVolume& volume, double tolerance_m) {
  ScannedBest best;
  double best_m = -std::numeric_limits<double>::infinity(), best_other = best_m;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Containment one = Corridor({path[i], path[i + 1]}, limits, operating).contains(volume, tolerance_m);
    const double m = std::min(one.margin_h_m, one.margin_v_m), other = std::max(one.margin_h_m, one.margin_v_m);
    if (m > best_m + tolerance_m || (m >= best_m - tolerance_m && other > best_other)) {
      best_m = m;
      best_other = other;
      best = {i, one.margin_h_m, one.margin_v_m};
    }
  }
  return best;
}

TEST(Corridor, SkippingFarLegsPicksTheSamePieceAsScanningEveryLeg) {
  // GIVEN corridors made for ties: a path that runs back and forth over the same line, each pass
  // a fraction of the tolerance higher (legs tied in h, and in v within the tolerance); passes
  // whose offsets and heights differ by steps of 0.3 tolerances (ties that chain); and random
  // zig-zags; tolerances from 0 to 1 m
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::vector<double> tolerances{0.0, 1e-6, 1e-3, 0.05, 1.0};
  int compared = 0, chosen_not_first = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const double tolerance_m = tolerances[static_cast<std::size_t>(trial) % tolerances.size()];
    const AlertLimits limits{20.0 + 200.0 * u(rng), 10.0 + 40.0 * u(rng)};
    const OperatingLimits operating{trial % 4 == 0 ? 90.0 : -std::numeric_limits<double>::infinity(),
                                    trial % 4 == 0 ? 160.0 : std::numeric_limits<double>::infinity()};
    std::vector<Eigen::Vector3d> path;
    const int legs = 2 + static_cast<int>(rng() % 30);
    for (int i = 0; i <= legs; ++i) {
      if (trial % 3 == 0) {
        path.emplace_back(i % 2 == 0 ? 0.0 : 1000.0, 0.0, 120.0 + 0.4 * tolerance_m * i);
      } else if (trial % 3 == 1) {  // parallel passes, each nearer and higher: ties in a chain
        path.emplace_back(i % 2 == 0 ? 0.0 : 1000.0, 100.0 + 0.3 * tolerance_m * static_cast<double>(rng() % 8),
                          120.0 + 0.3 * tolerance_m * static_cast<double>(rng() % 8));
      } else {
        path.emplace_back(3000.0 * u(rng), 3000.0 * u(rng), 100.0 + 40.0 * u(rng));
      }
    }
    const Corridor corridor(path, limits, operating);
    for (int k = 0; k < 100; ++k) {
      // WHEN a volume lies near the path or kilometres away
      const double spread_m = k % 2 == 0 ? 2.0 * limits.hal_m : 20000.0;
      const Eigen::Vector3d& a = path[rng() % path.size()];
      const ProtectionVolume volume{{a.x() + spread_m * (u(rng) - 0.5), a.y() + spread_m * (u(rng) - 0.5), 100.0 + 60.0 * u(rng)},
                                    0.5 + 0.5 * limits.hal_m * u(rng), 0.5 + 0.5 * limits.val_m * u(rng)};
      const Containment in = corridor.contains(volume, tolerance_m);
      if (in.across_joint) continue;
      // THEN the piece and its margins are those of the scan over every leg, to the bit
      const ScannedBest expected = scanEveryLeg(path, limits, operating, volume, tolerance_m);
      ASSERT_EQ(in.segment, expected.segment) << "trial " << trial << ", volume " << k;
      ASSERT_EQ(in.margin_h_m, expected.h) << "trial " << trial << ", volume " << k;
      ASSERT_EQ(in.margin_v_m, expected.v) << "trial " << trial << ", volume " << k;
      ++compared;
      chosen_not_first += expected.segment != 0;
    }
  }
  EXPECT_GT(compared, 20000);
  EXPECT_GT(chosen_not_first, 10000);
}

/// Every field of two containments, to the bit.
::testing::AssertionResult sameContainment(const Containment& a, const Containment& b) {
  if (a.verdict == b.verdict && a.segment == b.segment && a.across_joint == b.across_joint &&
      std::memcmp(&a.margin_h_m, &b.margin_h_m, sizeof(double)) == 0 &&
      std::memcmp(&a.margin_v_m, &b.margin_v_m, sizeof(double)) == 0) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "segment " << a.segment << " vs " << b.segment << ", margins (" << a.margin_h_m
                                       << ", " << a.margin_v_m << ") vs (" << b.margin_h_m << ", " << b.margin_v_m << ")";
}

TEST(Corridor, TwoLevelsOnOnePathAnswerAsEachAlone) {
  // GIVEN a fence's two levels on one random path (first level 1.2 × a vehicle, second 300 ×),
  // and a corridor on a path as long, 300 m east
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int compared = 0, across_joint = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<Eigen::Vector3d> path;
    const int legs = 1 + static_cast<int>(rng() % 20);
    for (int i = 0; i <= legs; ++i) path.emplace_back(3000.0 * u(rng), 3000.0 * u(rng), 100.0 + 40.0 * u(rng));
    std::vector<Eigen::Vector3d> moved = path;
    for (Eigen::Vector3d& p : moved) p.x() += 300.0;  // the same size, every waypoint elsewhere
    const Corridor level1(path, {1.8, 0.6}), level2(path, {450.0, 150.0}), elsewhere(moved, {450.0, 150.0});
    for (int k = 0; k < 500; ++k) {
      // WHEN a volume lies near the path, near a waypoint, or far away
      const Eigen::Vector3d& a = path[rng() % path.size()];
      const double spread_m = k % 3 == 0 ? 4.0 : (k % 3 == 1 ? 900.0 : 20000.0);
      const ProtectionVolume volume{{a.x() + spread_m * (u(rng) - 0.5), a.y() + spread_m * (u(rng) - 0.5), 90.0 + 60.0 * u(rng)},
                                    0.1 + 3.0 * u(rng), 0.1 + 3.0 * u(rng)};
      // THEN the pair's answers are each corridor's own, to the bit, on one path or two
      const auto [in1, in2] = level1.containsWith(level2, volume);
      ASSERT_TRUE(sameContainment(in1, level1.contains(volume))) << "trial " << trial << ", volume " << k;
      ASSERT_TRUE(sameContainment(in2, level2.contains(volume))) << "trial " << trial << ", volume " << k;
      const auto [again1, other] = level1.containsWith(elsewhere, volume);
      ASSERT_TRUE(sameContainment(again1, in1));
      ASSERT_TRUE(sameContainment(other, elsewhere.contains(volume))) << "trial " << trial << ", volume " << k;
      ++compared;
      across_joint += in1.across_joint || in2.across_joint;
    }
  }
  EXPECT_EQ(compared, 20000);
  EXPECT_GT(across_joint, 100) << "the joints' union search runs on shared bounds too";
}

TEST(Corridor, SegmentBoxCornersFollowTheClimb) {
  const Corridor c({{0, 0, 0}, {100, 0, 50}}, {6.0, 4.0});
  const auto k = c.segmentBoxCorners(0);
  EXPECT_TRUE(test::nearVec(k[0], Eigen::Vector3d(0, -6, -4), 1e-12));
  EXPECT_TRUE(test::nearVec(k[2], Eigen::Vector3d(100, 6, 46), 1e-12));
  EXPECT_TRUE(test::nearVec(k[6], Eigen::Vector3d(100, 6, 54), 1e-12));
  EXPECT_THROW((void)c.segmentBoxCorners(1), std::out_of_range);
}

}  // namespace
}  // namespace skylane::geofence
