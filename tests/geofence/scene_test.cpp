#include "geofence/scene.hpp"

#include "geofence/fcl_module.hpp"

#include "airspace/zone_geometry.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace skylane::geofence {
namespace {

using airspace::PlanarPrism;
using airspace::PlanarRing;

constexpr double kPi = 3.141592653589793;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// A deciding margin within this of 0 is "at contact": the floating-point margins and the
/// exact predicate may then disagree, and either answer stands; 1 µm is far above rounding at
/// kilometre coordinates (~1e-10 m).
constexpr double kContactBand_m = 1e-6;

/// How far FCL's GJK distance may lie from the closed form and still count as agreeing here:
/// the 1 mm minimum size of the volume's FCL cylinder plus GJK's 1e-6 m tolerance, with room.
/// Measured with FCL 0.7.0: libccd's GJK alone was off on ~9 % of clear pairs (worst 6.8 m,
/// beside tall pieces), FCL's own GJK alone on thin tall volumes (14.04 m for 2.45 m);
/// FclAgreesWithExactPredicates prints how often both stray.
constexpr double kFclClearance_m = 2e-3;

/// Rounding of margins at coordinates up to ~300 km: a few ulps of 3e5 m (6e-11 m) through a
/// handful of operations, with a wide berth.
constexpr double kFrameRounding_m = 1e-6;

/// Rounding of a distance of up to a few kilometres through a few operations (ulps ~1e-13 m).
constexpr double kRounding_m = 1e-9;

/// a ≈ b within tol, or the same infinity (a margin is −∞ for a piece unlimited both ways).
::testing::AssertionResult nearOrSameInfinity(double a, double b, double tol) {
  if (a == b || std::abs(a - b) <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " vs " << b << " (tolerance " << tol << ")";
}

// --- independent geometry (none of scene.cpp's code) ---------------------------------------------

/// Distance from p to the closed segment ab: the foot of the perpendicular when it falls on
/// the segment, else the nearer end.
double segmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double along = (p - a).dot(ab);
  if (along <= 0 || ab.squaredNorm() == 0) return (p - a).norm();
  if (along >= ab.squaredNorm()) return (p - b).norm();
  // |cross| / |ab| is the distance to the line.
  return std::abs(ab.x() * (p - a).y() - ab.y() * (p - a).x()) / ab.norm();
}

/// Signed horizontal distance from p to the piece's shape (negative inside), edge by edge.
double signedDistanceByEdges(const PlanarPrism& q, const Eigen::Vector2d& p) {
  if (q.ring.empty()) return (p - q.centre).norm() - q.radius_m;
  double d = kInf;
  for (std::size_t i = 0; i < q.ring.size(); ++i) d = std::min(d, segmentDistance(p, q.ring[i], q.ring[(i + 1) % q.ring.size()]));
  return test::insideByCrossings(p, q.ring) ? -d : d;
}

/// Distance from p to the ring's boundary sampled every `step_m` along the edges: an upper
/// bound on the true distance, at most step/2 above it.
double boundaryDistanceBySampling(const PlanarRing& ring, const Eigen::Vector2d& p, double step_m) {
  double d = kInf;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[(i + 1) % ring.size()];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step_m)));
    for (int k = 0; k <= n; ++k) d = std::min(d, (a + (b - a) * (static_cast<double>(k) / n) - p).norm());
  }
  return d;
}

/// 3-D distance from the point x to the prism (a product set: horizontal and vertical gaps
/// combine by Pythagoras).
double pointPrismDistance(const PlanarPrism& q, const Eigen::Vector3d& x) {
  const double h = std::max(signedDistanceByEdges(q, x.head<2>()), 0.0);
  const double v = std::max({q.floor_h_ell_m - x.z(), x.z() - q.ceiling_h_ell_m, 0.0});
  return std::hypot(h, v);
}

/// Least distance from sample points on the volume's surface to the prism, and the covering
/// radius of the samples: the true clearance C satisfies D − δ ≤ C ≤ D (samples lie in the
/// volume; every surface point is within δ of one, and the distance is 1-Lipschitz). The
/// surface suffices: disjoint closed convex sets are nearest at boundary points, and if they
/// meet, either a surface point lies in the prism or the whole volume does.
struct SampledClearance {
  double distance_m;
  double covering_m;
};

SampledClearance sampledClearance(const ProtectionVolume& v, const PlanarPrism& q) {
  constexpr int kAngles = 360, kHeights = 40, kRings = 20;
  const Eigen::Vector3d& c = v.p_map;
  double d = kInf;
  for (int a = 0; a < kAngles; ++a) {
    const double th = 2 * kPi * a / kAngles;
    const Eigen::Vector2d u(std::cos(th), std::sin(th));
    for (int k = 0; k <= kHeights; ++k) {  // side wall
      const double z = c.z() - v.vpl_m + 2 * v.vpl_m * k / kHeights;
      d = std::min(d, pointPrismDistance(q, {c.x() + v.hpl_m * u.x(), c.y() + v.hpl_m * u.y(), z}));
    }
    for (int k = 0; k < kRings; ++k) {  // caps
      const double r = v.hpl_m * k / kRings;
      for (const double z : {c.z() - v.vpl_m, c.z() + v.vpl_m}) {
        d = std::min(d, pointPrismDistance(q, {c.x() + r * u.x(), c.y() + r * u.y(), z}));
      }
    }
  }
  // Radially half a ring spacing, along the arc half an angle step (chord ≤ arc), vertically
  // half a height step (side wall); the caps' radial and angular steps likewise.
  const double arc = v.hpl_m * kPi / kAngles;
  const double covering = std::max(std::hypot(arc, v.vpl_m / kHeights), v.hpl_m / (2.0 * kRings) + arc);
  return {d, covering};
}

// --- random scenes ------------------------------------------------------------------------------

/// A random star-shaped (hence simple) counter-clockwise ring of n vertices round `c`.
PlanarRing randomStar(std::mt19937& rng, int n, double radius_m, const Eigen::Vector2d& c) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  PlanarRing ring;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * (i + 0.1 + 0.8 * u(rng)) / n;
    const double r = radius_m * (0.3 + 0.7 * u(rng));
    ring.emplace_back(c.x() + r * std::cos(a), c.y() + r * std::sin(a));
  }
  return ring;
}

/// A zone before decomposition: a ring (star polygon) or a disk, between floor and ceiling.
struct ZoneShape {
  PlanarRing ring;  ///< empty for a disk
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
  double floor_m = 0.0;
  double ceiling_m = 0.0;
};

ZoneShape randomZone(std::mt19937& rng, bool disk) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ZoneShape z;
  const Eigen::Vector2d c(-500 + 1000 * u(rng), -500 + 1000 * u(rng));
  if (disk) {
    z.centre = c;
    z.radius_m = 5 + 195 * u(rng);
  } else {
    z.ring = randomStar(rng, 4 + static_cast<int>(rng() % 9), 30 + 370 * u(rng), c);
  }
  // Heights: sometimes unlimited below or above.
  const double base = -50 + 350 * u(rng);
  z.floor_m = u(rng) < 0.15 ? -kInf : base;
  z.ceiling_m = u(rng) < 0.15 ? kInf : base + 5 + 295 * u(rng);
  return z;
}

/// The zones' convex pieces (rings through airspace::convexPieces), owner_index = zone; or, with
/// `owner_per_piece`, each piece its own owner, so that the scene reports every piece it reaches.
std::vector<ScenePiece> piecesOf(const std::vector<ZoneShape>& zones, bool owner_per_piece = false) {
  std::vector<ScenePiece> pieces;
  const auto owner = [&](std::size_t zone) { return owner_per_piece ? pieces.size() : zone; };
  for (std::size_t i = 0; i < zones.size(); ++i) {
    const ZoneShape& z = zones[i];
    PlanarPrism q;
    q.floor_h_ell_m = z.floor_m;
    q.ceiling_h_ell_m = z.ceiling_m;
    if (z.ring.empty()) {
      q.centre = z.centre;
      q.radius_m = z.radius_m;
      pieces.push_back({q, PieceOwner::kZone, owner(i)});
      continue;
    }
    for (PlanarRing& r : airspace::convexPieces(z.ring)) {
      q.ring = std::move(r);
      pieces.push_back({q, PieceOwner::kZone, owner(i)});
    }
  }
  return pieces;
}

/// An offset from a contact: mostly exactly at it or within rounding, a micrometre, a
/// millimetre, or metres to hundreds of metres, either side.
double randomOffset(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double sign = u(rng) < 0.5 ? -1.0 : 1.0;
  switch (rng() % 7) {
    case 0: return 0.0;
    case 1: return sign * 1e-9 * u(rng);
    case 2: return sign * 1e-6 * (0.5 + u(rng));
    case 3: return sign * 1e-3;
    case 4: return sign * 5 * u(rng);
    case 5: return 1e-2 * u(rng);  // just above FCL's exact band
    default: return -50 + 300 * u(rng);
  }
}

/// A protection volume placed near the piece: the centre at HPL + offset from a random point
/// of the boundary along an outward direction there (a vertex's whole normal cone), and
/// either level with the piece or VPL + offset from its floor or ceiling.
ProtectionVolume volumeNear(std::mt19937& rng, const PlanarPrism& q) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ProtectionVolume v;
  v.hpl_m = u(rng) < 0.1 ? 0.0 : 50 * u(rng);
  v.vpl_m = u(rng) < 0.1 ? 0.0 : 50 * u(rng);
  Eigen::Vector2d b, n;
  if (q.ring.empty()) {
    const double th = 2 * kPi * u(rng);
    n = {std::cos(th), std::sin(th)};
    b = q.centre + q.radius_m * n;
  } else {
    const std::size_t m = q.ring.size(), i = rng() % m;
    const Eigen::Vector2d& a = q.ring[i];
    const Eigen::Vector2d& c = q.ring[(i + 1) % m];
    const Eigen::Vector2d e = (c - a).normalized();
    const Eigen::Vector2d n_edge(e.y(), -e.x());  // outward: right of a counter-clockwise edge
    if (u(rng) < 0.3) {  // at vertex i + 1, between the normals of its two edges
      const Eigen::Vector2d f = (q.ring[(i + 2) % m] - c).normalized();
      const double w = u(rng);
      b = c;
      n = ((1 - w) * n_edge + w * Eigen::Vector2d(f.y(), -f.x())).normalized();
    } else {
      b = a + u(rng) * (c - a);
      n = n_edge;
    }
  }
  const Eigen::Vector2d xy = b + (v.hpl_m + randomOffset(rng)) * n;
  // A finite band to pick a level height from: the piece's, or 300 m of it where unlimited.
  const double lo = std::isfinite(q.floor_h_ell_m)     ? q.floor_h_ell_m
                    : std::isfinite(q.ceiling_h_ell_m) ? q.ceiling_h_ell_m - 300
                                                       : 0.0;
  const double hi = std::isfinite(q.ceiling_h_ell_m) ? q.ceiling_h_ell_m : lo + 300;
  double z = lo + (hi - lo) * u(rng);
  const double r = u(rng);
  if (r < 0.25 && std::isfinite(q.ceiling_h_ell_m)) z = q.ceiling_h_ell_m + v.vpl_m + randomOffset(rng);
  if (r > 0.75 && std::isfinite(q.floor_h_ell_m)) z = q.floor_h_ell_m - v.vpl_m - randomOffset(rng);
  v.p_map = {xy.x(), xy.y(), z};
  return v;
}

/// The scene's answer for one piece: its hit, if the query reached it.
std::optional<Separation> hitFor(const std::vector<SceneHit>& hits, std::size_t piece) {
  for (const SceneHit& h : hits) {
    if (h.piece == piece) return h.separation;
  }
  return std::nullopt;
}

bool meetsIn(const std::vector<SceneHit>& hits, std::size_t piece) {
  const std::optional<Separation> s = hitFor(hits, piece);
  return s && s->meets;
}

const auto kAcceptAll = [](PieceOwner, std::size_t) { return true; };

/// Counts the pairs whose error exceeds the tolerance and keeps the worst, so that a failure
/// over thousands of random pairs reads as one line with its worst case.
struct ErrorTally {
  long exceeded = 0;
  double worst = 0.0;
  std::string worst_case;
  void add(double error, double tolerance, const std::function<std::string()>& where) {
    if (error > tolerance) ++exceeded;
    if (error > worst) {
      worst = error;
      worst_case = where();
    }
  }
};

std::string describe(const ProtectionVolume& v) {
  std::ostringstream s;
  s.precision(17);
  s << "volume at (" << v.p_map.x() << ", " << v.p_map.y() << ", " << v.p_map.z() << "), HPL " << v.hpl_m << ", VPL "
    << v.vpl_m;
  return s.str();
}

std::string describe(const PlanarPrism& q) {
  std::ostringstream s;
  s.precision(17);
  if (q.ring.empty()) {
    s << "disk (" << q.centre.x() << ", " << q.centre.y() << ") r " << q.radius_m;
  } else {
    s << "ring";
    for (const Eigen::Vector2d& p : q.ring) s << " (" << p.x() << ", " << p.y() << ")";
  }
  s << " from " << q.floor_h_ell_m << " to " << q.ceiling_h_ell_m;
  return s.str();
}

// --- margins ---------------------------------------------------------------------------------------

TEST(Scene, SeparationMarginsMatchBruteForce) {
  std::mt19937 rng(2024);
  int meeting = 0, clear = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const ZoneShape zone = randomZone(rng, trial % 4 == 0);
    for (const ScenePiece& piece : piecesOf({zone})) {
      const PlanarPrism& q = piece.prism;
      const ProtectionVolume v = volumeNear(rng, q);
      SCOPED_TRACE(describe(v) + " vs " + describe(q));
      const Separation s = separationMargins(v, q);
      // Horizontal: edge by edge, and bracketed by boundary samples every 1 cm.
      const double sd = signedDistanceByEdges(q, v.p_map.head<2>());
      constexpr double kStep_m = 0.01;
      EXPECT_NEAR(s.margin_h_m, sd - v.hpl_m, kRounding_m);
      if (!q.ring.empty()) {
        const double sampled = boundaryDistanceBySampling(q.ring, v.p_map.head<2>(), kStep_m);
        EXPECT_LE(std::abs(s.margin_h_m + v.hpl_m), sampled + kRounding_m);
        EXPECT_GE(std::abs(s.margin_h_m + v.hpl_m), sampled - kStep_m / 2 - kRounding_m);
      }
      // Vertical: below the floor, above the ceiling, or minus the depth inside the band.
      const double z = v.p_map.z();
      const double sv = z < q.floor_h_ell_m     ? q.floor_h_ell_m - z
                        : z > q.ceiling_h_ell_m ? z - q.ceiling_h_ell_m
                                                : -std::min(z - q.floor_h_ell_m, q.ceiling_h_ell_m - z);
      EXPECT_TRUE(nearOrSameInfinity(s.margin_v_m, sv - v.vpl_m, kRounding_m));
      // Clearance and meets against the sampled volume.
      const SampledClearance b = sampledClearance(v, q);
      EXPECT_LE(s.clearance_m, b.distance_m + kRounding_m);
      EXPECT_GE(s.clearance_m, b.distance_m - b.covering_m - kRounding_m);
      EXPECT_EQ(s.meets, s.clearance_m == 0.0);
      if (s.meets) {
        EXPECT_LE(b.distance_m, b.covering_m + kRounding_m);
        ++meeting;
      } else {
        ++clear;
      }
    }
  }
  EXPECT_GT(meeting, 50);
  EXPECT_GT(clear, 50);
}

// --- FCL against the exact predicates ---------------------------------------------------------------

TEST(Scene, FclAgreesWithExactPredicates) {
  std::mt19937 rng(7);
  constexpr double kHorizon_m = 200.0;
  long pairs = 0, exact_path = 0, fcl_failed = 0, at_contact = 0, fcl_clear = 0, meets_count = 0, clear_at_zero = 0;
  long off_cm = 0, off_m = 0;  // reported clearances off by more than 1 cm, 1 m
  long fcl_compared = 0;
  ErrorTally clearance, fcl_distance;
  for (int scene_index = 0; scene_index < 3000; ++scene_index) {
    // GIVEN one or two star-shaped zones (decomposed) and up to two disks
    std::vector<ZoneShape> zones;
    const int rings = 1 + static_cast<int>(rng() % 2), disks = static_cast<int>(rng() % 3);
    for (int k = 0; k < rings; ++k) zones.push_back(randomZone(rng, false));
    for (int k = 0; k < disks; ++k) zones.push_back(randomZone(rng, true));
    const Scene scene(piecesOf(zones, true));
    const std::vector<ScenePiece>& pieces = scene.pieces();
    for (int vi = 0; vi < 4; ++vi) {
      // WHEN a volume near one of the pieces is queried
      const ProtectionVolume v = volumeNear(rng, pieces[rng() % pieces.size()].prism);
      const std::vector<SceneHit> hits = scene.query(v, kHorizon_m, kAcceptAll);
      // THEN every piece's answer agrees with the exact predicate and the analytic margins
      for (std::size_t i = 0; i < pieces.size(); ++i) {
        const PlanarPrism& q = pieces[i].prism;
        const auto where = [&] {
          return "scene " + std::to_string(scene_index) + " piece " + std::to_string(i) + ": " + describe(v) + " vs " +
                 describe(q);
        };
        SCOPED_TRACE(where());
        ++pairs;
        const Separation m = separationMargins(v, q);
        const bool exact = airspace::cylinderMeetsPrism(v.p_map, v.hpl_m, v.vpl_m, q);
        const std::optional<Separation> hit = hitFor(hits, i);
        const double deciding = std::max(m.margin_h_m, m.margin_v_m);
        meets_count += exact ? 1 : 0;
        const bool near_contact = std::abs(deciding) <= kContactBand_m;
        if (near_contact) {
          ++at_contact;
        } else {
          EXPECT_EQ(hit && hit->meets, exact) << "deciding margin " << deciding;
          EXPECT_EQ(exact, deciding <= 0);  // the margins and the predicate agree away from contact
        }
        if (exact) {
          EXPECT_TRUE(hit.has_value()) << "a met piece is always reported";
        }
        // Reach: within the horizon reported, beyond it (and FCL's slack) not.
        if (m.clearance_m <= kHorizon_m - kFclClearance_m) {
          EXPECT_TRUE(hit.has_value()) << "clearance " << m.clearance_m;
        }
        if (m.clearance_m > kHorizon_m + kFclClearance_m) {
          EXPECT_FALSE(hit.has_value()) << "clearance " << m.clearance_m;
        }
        if (!hit) continue;
        EXPECT_EQ(hit->margin_h_m, m.margin_h_m);
        EXPECT_EQ(hit->margin_v_m, m.margin_v_m);
        exact_path += hit->exact ? 1 : 0;
        fcl_failed += hit->fcl_failed ? 1 : 0;
        if (hit->meets) {
          EXPECT_EQ(hit->clearance_m, 0.0);
          continue;
        }
        if (!near_contact) {
          EXPECT_GT(hit->clearance_m, 0.0);
        }
        clear_at_zero += hit->clearance_m == 0.0 ? 1 : 0;  // clear by the predicate, margins ≤ 0 by rounding
        // FCL's own distance, where it ran and the pair is clear by more than its band, against
        // the closed form (independent of the library's choice of which to report).
        if (std::isfinite(hit->fcl_distance_m) && m.clearance_m > kExactBand_m) {
          ++fcl_compared;
          fcl_distance.add(std::abs(hit->fcl_distance_m - m.clearance_m), kExactBand_m, [&] {
            std::ostringstream s;
            s.precision(10);
            s << "FCL " << hit->fcl_distance_m << " m, closed form " << m.clearance_m << " m; " << where();
            return s.str();
          });
        }
        fcl_clear += hit->exact ? 0 : 1;
        off_cm += std::abs(hit->clearance_m - m.clearance_m) > 0.01 ? 1 : 0;
        off_m += std::abs(hit->clearance_m - m.clearance_m) > 1.0 ? 1 : 0;
        clearance.add(std::abs(hit->clearance_m - m.clearance_m), kFclClearance_m, [&] {
          std::ostringstream s;
          s.precision(10);
          s << "reported " << hit->clearance_m << " m, analytic " << m.clearance_m << " m; " << where();
          return s.str();
        });
      }
    }
  }
  std::printf("[ stats    ] %ld pairs: %ld met, %ld within %g m of contact, %ld decided by the exact predicate, %ld "
              "clear by FCL, %ld with FCL failing, %ld clear at clearance 0; %ld clearances off by more than %g m (%ld "
              "by more than 1 cm, %ld by more than 1 m), worst %.3g m\n",
              pairs, meets_count, at_contact, kContactBand_m, exact_path, fcl_clear, fcl_failed, clear_at_zero,
              clearance.exceeded, kFclClearance_m, off_cm, off_m, clearance.worst);
  std::printf("[ stats    ] FCL GJK distance (the last solver run) vs closed form over %ld clear pairs: %ld off by "
              "more than %g m (settled exactly), worst %.3g m\n",
              fcl_compared, fcl_distance.exceeded, kExactBand_m, fcl_distance.worst);
  EXPECT_EQ(clearance.exceeded, 0) << "worst: " << clearance.worst_case;
  // FCL settles nearly every clear pair by itself: where one solver strays, the other agrees
  // (a pair both miss goes to the exact predicate, and is counted here).
  EXPECT_GT(fcl_compared, 10000);
  EXPECT_LT(fcl_distance.exceeded, fcl_compared / 200) << "worst: " << fcl_distance.worst_case;
  // The scenes exercise both paths and the contact band.
  EXPECT_GT(exact_path, 1000);
  EXPECT_GT(fcl_clear, 3000);
  EXPECT_GT(at_contact, 1000);
}

/// Per zone, the scene reports one hit: met when any of its pieces is met (the exact predicate),
/// else the nearest piece with its clearance; zones wholly beyond the horizon are not reported.
TEST(Scene, OneHitPerZoneFromItsDecidingPiece) {
  std::mt19937 rng(31);
  constexpr double kHorizon_m = 100.0;
  long zones_checked = 0, met = 0, multi_piece = 0;
  for (int scene_index = 0; scene_index < 1500; ++scene_index) {
    std::vector<ZoneShape> zones{randomZone(rng, false), randomZone(rng, false), randomZone(rng, true)};
    const Scene scene(piecesOf(zones));
    const std::vector<ScenePiece>& pieces = scene.pieces();
    const ProtectionVolume v = volumeNear(rng, pieces[rng() % pieces.size()].prism);
    const std::vector<SceneHit> hits = scene.query(v, kHorizon_m, kAcceptAll);
    for (std::size_t z = 0; z < zones.size(); ++z) {
      SCOPED_TRACE("scene " + std::to_string(scene_index) + " zone " + std::to_string(z) + ": " + describe(v));
      bool exact_meets = false, near_contact = false;
      double nearest = kInf;
      int count = 0;
      for (const ScenePiece& p : pieces) {
        if (p.owner_index != z) continue;
        ++count;
        const Separation m = separationMargins(v, p.prism);
        exact_meets = exact_meets || airspace::cylinderMeetsPrism(v.p_map, v.hpl_m, v.vpl_m, p.prism);
        near_contact = near_contact || std::abs(std::max(m.margin_h_m, m.margin_v_m)) <= kContactBand_m;
        nearest = std::min(nearest, m.clearance_m);
      }
      multi_piece += count > 1;
      const auto hit = std::find_if(hits.begin(), hits.end(), [&](const SceneHit& h) { return h.owner_index == z; });
      EXPECT_EQ(std::count_if(hits.begin(), hits.end(), [&](const SceneHit& h) { return h.owner_index == z; }),
                hit == hits.end() ? 0 : 1);
      ++zones_checked;
      if (exact_meets) {
        ++met;
        ASSERT_NE(hit, hits.end());
        if (!near_contact) {
          EXPECT_TRUE(hit->separation.meets);
        }
        continue;
      }
      if (nearest > kHorizon_m + kRounding_m) {
        EXPECT_EQ(hit, hits.end());
        continue;
      }
      ASSERT_NE(hit, hits.end());
      if (!near_contact) {
        EXPECT_FALSE(hit->separation.meets);
        EXPECT_NEAR(hit->separation.clearance_m, nearest, kRounding_m);
      }
      EXPECT_EQ(pieces[hit->piece].owner_index, z);
    }
  }
  EXPECT_GT(met, 300);
  EXPECT_GT(multi_piece, 2000);
  EXPECT_GT(zones_checked, 4000);
}

/// A triangle from 280.3 m up without limit and a volume beside it whose top is level with the
/// floor (margin_v ≈ −1e-6 m, so the clearance is the horizontal margin, 20.968 m): found by
/// the random scenes of FclAgreesWithExactPredicates; FCL 0.7.0's libccd GJK stops at 25.662 m.
TEST(Scene, ClearanceBesideATallPieceIsTheTrueDistance) {
  PlanarPrism q;
  q.ring = {{198.97393333010314, -176.21280202224577},
            {177.44745222872177, -155.7511521102183},
            {155.23968880383455, -177.54472111920046}};
  q.floor_h_ell_m = 280.30060458505091;
  q.ceiling_h_ell_m = kInf;
  const ProtectionVolume v{{257.00598805233244, -214.40765277549616, 262.38319663637037}, 48.505426068481285,
                           17.917409288235849};
  // GIVEN the clearance bracketed by sampling the volume (independent of the library)
  const SampledClearance b = sampledClearance(v, q);
  const Separation m = separationMargins(v, q);
  EXPECT_LE(m.clearance_m, b.distance_m + kRounding_m);
  EXPECT_GE(m.clearance_m, b.distance_m - b.covering_m);
  // WHEN the scene is asked THEN it reports that clearance
  const Scene scene({{q, PieceOwner::kZone, 0}});
  const std::vector<SceneHit> hits = scene.query(v, 200.0, kAcceptAll);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_FALSE(hits[0].separation.meets);
  EXPECT_NEAR(hits[0].separation.clearance_m, m.clearance_m, kFclClearance_m);
  EXPECT_LE(hits[0].separation.clearance_m, b.distance_m + kFclClearance_m) << "more room reported than there is";
  // AND the piece is within a 22 m horizon but not within 20.9 m
  EXPECT_EQ(scene.query(v, 22.0, kAcceptAll).size(), 1u);
  EXPECT_TRUE(scene.query(v, 20.9, kAcceptAll).empty());
}

TEST(Scene, PieceOutsideTheModelledHeightsKeepsItsTrueClearance) {
  // GIVEN a 100 m square from −5000 m to −3000 m, wholly below the heights FCL models, and a
  // volume whose bottom is at −1995 m: 1005 m above it
  PlanarPrism low;
  low.ring = {{0, 0}, {100, 0}, {100, 100}, {0, 100}};
  low.floor_h_ell_m = -5000;
  low.ceiling_h_ell_m = -3000;
  const ProtectionVolume over_low{{50, 50, -1990}, 5, 5};
  const Scene below({{low, PieceOwner::kZone, 0}});
  // THEN it is not within a 100 m horizon, and within 2 km it is 1005 m away
  EXPECT_TRUE(below.query(over_low, 100.0, kAcceptAll).empty());
  std::vector<SceneHit> hits = below.query(over_low, 2000.0, kAcceptAll);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_NEAR(hits[0].separation.clearance_m, 1005.0, kFclClearance_m);
  // AND likewise a square from 25 km to 30 km over a volume whose top is at 19005 m
  PlanarPrism high = low;
  high.floor_h_ell_m = 25000;
  high.ceiling_h_ell_m = 30000;
  const ProtectionVolume under_high{{50, 50, 19000}, 5, 5};
  const Scene above({{high, PieceOwner::kZone, 0}});
  EXPECT_TRUE(above.query(under_high, 1500.0, kAcceptAll).empty());
  hits = above.query(under_high, 6000.0, kAcceptAll);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_NEAR(hits[0].separation.clearance_m, 5995.0, kFclClearance_m);
}

// --- touching under poses -------------------------------------------------------------------------

/// A pose of the whole scene: yaw about the vertical through the origin, then a translation.
/// `exact` poses keep every coordinate exact (a quarter turn swaps coordinates; the offsets
/// are integers far below 2^53).
struct Pose {
  const char* name;
  int quarter_turns;  ///< exact rotation by multiples of 90°
  double yaw_rad;     ///< any further rotation (inexact)
  Eigen::Vector3d t;
  bool exact() const { return yaw_rad == 0.0; }
};

Eigen::Vector2d applyXY(const Pose& pose, Eigen::Vector2d p) {
  for (int k = 0; k < pose.quarter_turns; ++k) p = Eigen::Vector2d(-p.y(), p.x());
  if (pose.yaw_rad != 0.0) p = Eigen::Rotation2Dd(pose.yaw_rad) * p;
  return p + pose.t.head<2>();
}

PlanarPrism applyPose(const Pose& pose, PlanarPrism q) {
  for (Eigen::Vector2d& v : q.ring) v = applyXY(pose, v);
  q.centre = applyXY(pose, q.centre);
  q.floor_h_ell_m += pose.t.z();
  q.ceiling_h_ell_m += pose.t.z();
  return q;
}

ProtectionVolume applyPose(const Pose& pose, ProtectionVolume v) {
  const Eigen::Vector2d xy = applyXY(pose, v.p_map.head<2>());
  v.p_map = {xy.x(), xy.y(), v.p_map.z() + pose.t.z()};
  return v;
}

TEST(Scene, TouchingCasesAreDecidedExactlyUnderPoses) {
  // GIVEN a 400 m square zone and a 100 m disk obstacle, both from 100 m to 200 m
  PlanarPrism square;
  square.ring = {{0, 0}, {400, 0}, {400, 400}, {0, 400}};
  square.floor_h_ell_m = 100;
  square.ceiling_h_ell_m = 200;
  PlanarPrism disk;
  disk.centre = {1000, 0};
  disk.radius_m = 100;
  disk.floor_h_ell_m = 100;
  disk.ceiling_h_ell_m = 200;
  enum class Kind { kTouching, kGap, kOverlap, kDeep };
  struct Case {
    const char* name;
    std::size_t piece;
    ProtectionVolume volume;
    Kind kind;
    double clearance_m;  ///< expected (0 unless a gap)
  };
  const double mm = 1e-3;
  const Case cases[] = {
      {"wall tangent", 0, {{405, 200, 150}, 5, 2}, Kind::kTouching, 0},
      {"vertex tangent (3, 4) from (400, 400), HPL 5", 0, {{403, 404, 150}, 5, 2}, Kind::kTouching, 0},
      {"top on the floor", 0, {{200, 200, 90}, 5, 10}, Kind::kTouching, 0},
      {"bottom on the ceiling", 0, {{200, 200, 210}, 5, 10}, Kind::kTouching, 0},
      {"wall and ceiling at once (edge)", 0, {{405, 200, 210}, 5, 10}, Kind::kTouching, 0},
      {"vertex and floor at once (corner)", 0, {{403, 404, 90}, 5, 10}, Kind::kTouching, 0},
      {"a point on the wall (HPL = VPL = 0)", 0, {{400, 200, 150}, 0, 0}, Kind::kTouching, 0},
      {"a flat disk on the ceiling (VPL = 0)", 0, {{200, 200, 200}, 3, 0}, Kind::kTouching, 0},
      {"a vertical segment on the wall (HPL = 0)", 0, {{400, 200, 150}, 0, 7}, Kind::kTouching, 0},
      {"disk rim tangent, (63, 84) = 105 = 100 + 5", 1, {{1063, 84, 150}, 5, 2}, Kind::kTouching, 0},
      {"disk floor contact", 1, {{1050, 0, 90}, 5, 10}, Kind::kTouching, 0},
      {"disk rim and ceiling at once", 1, {{1105, 0, 210}, 5, 10}, Kind::kTouching, 0},
      {"wall, 1 mm gap", 0, {{405 + mm, 200, 150}, 5, 2}, Kind::kGap, mm},
      {"wall, 1 mm overlap", 0, {{405 - mm, 200, 150}, 5, 2}, Kind::kOverlap, 0},
      {"vertex, 1 mm gap", 0, {{403 + 0.6 * mm, 404 + 0.8 * mm, 150}, 5, 2}, Kind::kGap, mm},
      {"vertex, 1 mm overlap", 0, {{403 - 0.6 * mm, 404 - 0.8 * mm, 150}, 5, 2}, Kind::kOverlap, 0},
      {"ceiling, 1 mm gap", 0, {{200, 200, 210 + mm}, 5, 10}, Kind::kGap, mm},
      {"floor, 1 mm overlap", 0, {{200, 200, 90 + mm}, 5, 10}, Kind::kOverlap, 0},
      {"edge, 1 mm gap both ways", 0, {{405 + mm, 200, 210 + mm}, 5, 10}, Kind::kGap, std::hypot(mm, mm)},
      {"disk rim, 1 mm gap", 1, {{1105 + mm, 0, 150}, 5, 2}, Kind::kGap, mm},
      {"disk rim, 1 mm overlap", 1, {{1105 - mm, 0, 150}, 5, 2}, Kind::kOverlap, 0},
      {"deep inside the square", 0, {{200, 200, 150}, 5, 5}, Kind::kDeep, 0},
      {"deep inside the disk", 1, {{1000, 10, 160}, 20, 5}, Kind::kDeep, 0},
  };
  const Pose poses[] = {
      {"identity", 0, 0.0, {0, 0, 0}},
      {"300 km east, 300 km south", 0, 0.0, {300000, -300000, 0}},
      {"quarter turn, 300 km west, 1 km up", 1, 0.0, {-300000, 299999, 1000}},
      {"three quarter turns, 250 km north", 3, 0.0, {0, 250000, -500}},
      {"yaw 0.3 rad, 300 km north-east", 0, 0.3, {300000, 300000, 0}},
      {"yaw 2 rad, 300 km west", 0, 2.0, {-300000, 0, 0}},
      {"yaw −1 rad after a quarter turn", 1, -1.0, {123456.5, -654321.25, 40}},
  };
  for (const Pose& pose : poses) {
    SCOPED_TRACE(pose.name);
    const Scene scene({{applyPose(pose, square), PieceOwner::kZone, 0}, {applyPose(pose, disk), PieceOwner::kObstacle, 0}});
    for (const Case& c : cases) {
      SCOPED_TRACE(c.name);
      const ProtectionVolume v = applyPose(pose, c.volume);
      const std::vector<SceneHit> hits = scene.query(v, 10.0, kAcceptAll);
      const std::optional<Separation> s = hitFor(hits, c.piece);
      ASSERT_TRUE(s.has_value());
      const double deciding = std::max(s->margin_h_m, s->margin_v_m);
      switch (c.kind) {
        case Kind::kTouching:
          if (pose.exact()) {
            // THEN touching at exact coordinates meets, by the exact predicate, at clearance 0
            EXPECT_TRUE(s->meets);
            EXPECT_TRUE(s->exact);
            EXPECT_EQ(s->clearance_m, 0.0);
            EXPECT_NEAR(deciding, 0.0, kFrameRounding_m);
          } else {
            // Rotated, the contact is lost to rounding either way; it must stay within it.
            EXPECT_TRUE(s->meets || std::abs(deciding) < kContactBand_m) << "deciding " << deciding;
          }
          break;
        case Kind::kGap:
          EXPECT_FALSE(s->meets);
          EXPECT_NEAR(s->clearance_m, c.clearance_m, kFrameRounding_m);
          EXPECT_TRUE(s->exact) << "a millimetre is inside the exact band";
          break;
        case Kind::kOverlap:
          EXPECT_TRUE(s->meets);
          EXPECT_EQ(s->clearance_m, 0.0);
          EXPECT_NEAR(deciding, -mm, kFrameRounding_m);
          break;
        case Kind::kDeep:
          EXPECT_TRUE(s->meets);
          EXPECT_EQ(s->clearance_m, 0.0);
          EXPECT_LT(deciding, -1.0);
          break;
      }
      // The other piece is far (≥ 400 m) in every case: not reported within 10 m.
      EXPECT_EQ(hits.size(), 1u);
    }
  }
}

// --- monotonicity -----------------------------------------------------------------------------------

/// Whether the volume meets the zone (any of its pieces), by the scene.
bool zoneMet(const Scene& scene, const ProtectionVolume& v, std::size_t zone) {
  for (const SceneHit& h : scene.query(v, 0.0, kAcceptAll)) {
    if (scene.pieces()[h.piece].owner_index == zone && h.separation.meets) return true;
  }
  return false;
}

TEST(Scene, MonotoneInProtectionLevelAndZoneGrowth) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int met = 0, grown_checks = 0;
  for (int trial = 0; trial < 600; ++trial) {
    // GIVEN a ring zone and a disk zone, and a volume near one of the ring's pieces
    std::vector<ZoneShape> zones{randomZone(rng, false), randomZone(rng, true)};
    const Scene scene(piecesOf(zones));
    const std::size_t target = rng() % scene.pieces().size();
    const ProtectionVolume v = volumeNear(rng, scene.pieces()[target].prism);
    const std::size_t zone = scene.pieces()[target].owner_index;
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + describe(v) + " near " + describe(scene.pieces()[target].prism));
    if (!zoneMet(scene, v, zone)) continue;
    ++met;
    // THEN a larger HPL or VPL still meets, by a hair or by metres
    for (const double grow : {1e-9, 1e-3, 1.0, 20 * u(rng)}) {
      ProtectionVolume wider = v, taller = v;
      wider.hpl_m += grow;
      taller.vpl_m += grow;
      EXPECT_TRUE(zoneMet(scene, wider, zone)) << "HPL + " << grow;
      EXPECT_TRUE(zoneMet(scene, taller, zone)) << "VPL + " << grow;
    }
    // AND a grown zone still meets: buffered outward (re-decomposed) or a larger disk, a lower
    // floor, a higher ceiling
    for (const double d : {1e-3, 0.5, 30 * u(rng)}) {
      std::vector<ZoneShape> grown = zones;
      ZoneShape& z = grown[zone];
      if (z.ring.empty()) {
        z.radius_m += d;
      } else {
        z.ring = airspace::bufferRing(z.ring, d, d / 10);
      }
      z.floor_m -= u(rng) < 0.5 ? d : 0.0;
      z.ceiling_m += u(rng) < 0.5 ? d : 0.0;
      const Scene bigger(piecesOf(grown));
      EXPECT_TRUE(zoneMet(bigger, v, zone)) << "zone grown by " << d;
      ++grown_checks;
    }
  }
  EXPECT_GT(met, 200);
  EXPECT_GT(grown_checks, 600);
}

// --- frame invariance -----------------------------------------------------------------------------

TEST(Scene, FrameInvarianceOfMargins) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int compared = 0;
  ErrorTally clearance;
  for (int trial = 0; trial < 1000; ++trial) {
    std::vector<ZoneShape> zones{randomZone(rng, false), randomZone(rng, true), randomZone(rng, false)};
    const std::vector<ScenePiece> pieces = piecesOf(zones, true);
    const Pose pose{"random", static_cast<int>(rng() % 4), -kPi + 2 * kPi * u(rng),
                    Eigen::Vector3d(-3e5 + 6e5 * u(rng), -3e5 + 6e5 * u(rng), -100 + 200 * u(rng))};
    std::vector<ScenePiece> moved = pieces;
    for (ScenePiece& p : moved) p.prism = applyPose(pose, p.prism);
    const Scene a(pieces), b(moved);
    const ProtectionVolume v = volumeNear(rng, pieces[rng() % pieces.size()].prism);
    const ProtectionVolume w = applyPose(pose, v);
    std::ostringstream where;
    where << "trial " << trial << ", yaw " << pose.yaw_rad << " + " << pose.quarter_turns << " quarter turns, "
          << describe(v);
    SCOPED_TRACE(where.str());
    const std::vector<SceneHit> ha = a.query(v, 150.0, kAcceptAll), hb = b.query(w, 150.0, kAcceptAll);
    for (std::size_t i = 0; i < pieces.size(); ++i) {
      SCOPED_TRACE("piece " + std::to_string(i));
      const Separation ma = separationMargins(v, pieces[i].prism), mb = separationMargins(w, moved[i].prism);
      EXPECT_TRUE(nearOrSameInfinity(ma.margin_h_m, mb.margin_h_m, kFrameRounding_m));
      EXPECT_TRUE(nearOrSameInfinity(ma.margin_v_m, mb.margin_v_m, kFrameRounding_m));
      EXPECT_NEAR(ma.clearance_m, mb.clearance_m, kFrameRounding_m);
      const std::optional<Separation> sa = hitFor(ha, i), sb = hitFor(hb, i);
      const bool away = std::abs(std::max(ma.margin_h_m, ma.margin_v_m)) > kContactBand_m;
      if (away) {
        EXPECT_EQ(meetsIn(ha, i), meetsIn(hb, i));
        // Reached in both frames unless the clearance sits at the horizon.
        if (std::abs(ma.clearance_m - 150.0) > kFclClearance_m) {
          EXPECT_EQ(sa.has_value(), sb.has_value());
        }
      }
      if (sa && sb) {
        clearance.add(std::abs(sa->clearance_m - sb->clearance_m), kFclClearance_m, [&] {
          std::ostringstream s;
          s.precision(10);
          s << sa->clearance_m << " m vs " << sb->clearance_m << " m moved; " << where.str() << ", piece " << i;
          return s.str();
        });
        ++compared;
      }
    }
  }
  EXPECT_EQ(clearance.exceeded, 0) << "worst " << clearance.worst << " m: " << clearance.worst_case;
  EXPECT_GT(compared, 2000);
}

// --- filter and errors ----------------------------------------------------------------------------

ScenePiece squarePiece(double x0, double floor_m, double ceiling_m, PieceOwner owner, std::size_t index) {
  PlanarPrism q;
  q.ring = {{x0, 0}, {x0 + 10, 0}, {x0 + 10, 10}, {x0, 10}};
  q.floor_h_ell_m = floor_m;
  q.ceiling_h_ell_m = ceiling_m;
  return {q, owner, index};
}

TEST(Scene, AcceptFilterAndErrors) {
  // GIVEN a zone and an obstacle side by side, both met by a wide volume between them
  const Scene scene({squarePiece(0, 0, 100, PieceOwner::kZone, 4), squarePiece(20, 0, 100, PieceOwner::kObstacle, 9)});
  const ProtectionVolume v{{15, 5, 50}, 6, 2};
  EXPECT_EQ(scene.query(v, 50.0, kAcceptAll).size(), 2u);
  // WHEN only obstacles are accepted THEN only the obstacle is reported
  const std::vector<SceneHit> obstacles =
      scene.query(v, 50.0, [](PieceOwner owner, std::size_t) { return owner == PieceOwner::kObstacle; });
  ASSERT_EQ(obstacles.size(), 1u);
  EXPECT_EQ(obstacles[0].piece, 1u);
  EXPECT_TRUE(obstacles[0].separation.meets);
  EXPECT_TRUE(scene.query(v, 50.0, [](PieceOwner, std::size_t) { return false; }).empty());
  // AND an exception thrown by accept comes out of query
  const std::string thrown = test::messageOf<std::runtime_error>(
      [&] { (void)scene.query(v, 50.0, [](PieceOwner, std::size_t) -> bool { throw std::runtime_error("accept refused"); }); });
  EXPECT_EQ(thrown, "accept refused");

  // Pieces the scene refuses, with the piece named.
  ScenePiece dented = squarePiece(0, 0, 100, PieceOwner::kZone, 7);
  dented.prism.ring = {{0, 0}, {4, 0}, {2, 1}, {4, 4}, {0, 4}};  // vertex 2 is reflex
  std::string msg = test::messageOf<std::invalid_argument>([&] { Scene s({dented}); });
  EXPECT_NE(msg.find("piece 0 (zone 7): the ring must be convex and counter-clockwise (vertex 2 turns right)"),
            std::string::npos)
      << msg;
  msg = test::messageOf<std::invalid_argument>(
      [&] { Scene s({squarePiece(0, 0, 100, PieceOwner::kZone, 0), squarePiece(0, 200, 100, PieceOwner::kObstacle, 3)}); });
  EXPECT_NE(msg.find("piece 1 (obstacle 3): floor 200 m must be below ceiling 100 m"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { Scene s({squarePiece(0, 50, 50, PieceOwner::kZone, 0)}); });
  EXPECT_NE(msg.find("floor 50 m must be below ceiling 50 m"), std::string::npos) << msg;
  ScenePiece flat_disk{PlanarPrism{}, PieceOwner::kObstacle, 2};
  flat_disk.prism.ceiling_h_ell_m = 10;
  msg = test::messageOf<std::invalid_argument>([&] { Scene s({flat_disk}); });
  EXPECT_NE(msg.find("piece 0 (obstacle 2): a disk needs a finite centre and a positive radius"), std::string::npos) << msg;

  // Volumes the query refuses.
  msg = test::messageOf<std::invalid_argument>([&] { (void)scene.query({{0, 0, 19990}, 1, 20}, 50.0, kAcceptAll); });
  EXPECT_NE(msg.find("protection volume 19970 … 20010 m (ellipsoidal) reaches outside the modelled heights -2000 … 20000 m"),
            std::string::npos)
      << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)scene.query({{0, 0, -1995}, 1, 10}, 50.0, kAcceptAll); });
  EXPECT_NE(msg.find("reaches outside the modelled heights"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)scene.query({{NAN, 0, 50}, 1, 1}, 50.0, kAcceptAll); });
  EXPECT_EQ(msg, "protection volume position is not finite");
  msg = test::messageOf<std::invalid_argument>([&] { (void)scene.query({{0, 0, 50}, -1, 2}, 50.0, kAcceptAll); });
  EXPECT_NE(msg.find("protection levels must be finite and ≥ 0, got HPL -1 m, VPL 2 m"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)scene.query({{0, 0, 50}, 1, INFINITY}, 50.0, kAcceptAll); });
  EXPECT_NE(msg.find("VPL inf m"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)scene.query({{0, 0, 50}, 1, 1}, -1.0, kAcceptAll); });
  EXPECT_NE(msg.find("clearance horizon must be a finite number of metres ≥ 0"), std::string::npos) << msg;
}

}  // namespace
}  // namespace skylane::geofence

namespace skylane::geofence {
namespace {

/// A convex regular n-gon, counter-clockwise, of circumradius r about c.
PlanarRing regularRing(const Eigen::Vector2d& c, double r, int n, double phase) {
  PlanarRing ring;
  for (int k = 0; k < n; ++k) {
    const double a = phase + 2 * kPi * k / n;
    ring.emplace_back(c.x() + r * std::cos(a), c.y() + r * std::sin(a));
  }
  return ring;
}

/// The broad phase over thousands of pieces (a grid in scene.cpp) finds every zone a brute
/// force over all pieces finds: GIVEN 600 zones of 1–3 pieces (rings and disks, 20–900 m, a few
/// of 8–15 km that span many grid cells) in 30 km × 30 km, WHEN volumes anywhere and next to
/// pieces are queried, THEN a zone is reported iff one of its pieces meets the volume or lies
/// within the horizon (closed-form margins, away from the boundary cases).
TEST(Scene, BroadPhaseOverManyPiecesFindsWhatBruteForceFinds) {
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  constexpr double kArea_m = 30000.0, kHorizon_m = 100.0;
  std::vector<ScenePiece> pieces;
  constexpr std::size_t kZones = 600;
  for (std::size_t z = 0; z < kZones; ++z) {
    const Eigen::Vector2d c(kArea_m * u(rng), kArea_m * u(rng));
    const double size = z % 100 == 7 ? 8000.0 + 7000.0 * u(rng) : 20.0 + 880.0 * u(rng);
    const int parts = 1 + static_cast<int>(rng() % 3);
    for (int k = 0; k < parts; ++k) {
      PlanarPrism q;
      q.floor_h_ell_m = u(rng) < 0.2 ? -kInf : 400.0 + 100.0 * u(rng);
      q.ceiling_h_ell_m = u(rng) < 0.2 ? kInf : 600.0 + 300.0 * u(rng);
      const Eigen::Vector2d ck = c + Eigen::Vector2d(size * (u(rng) - 0.5), size * (u(rng) - 0.5));
      if (u(rng) < 0.25) {
        q.centre = ck;
        q.radius_m = 0.5 * size * (0.2 + 0.8 * u(rng));
      } else {
        q.ring = regularRing(ck, 0.5 * size * (0.2 + 0.8 * u(rng)), 3 + static_cast<int>(rng() % 10), 2 * kPi * u(rng));
      }
      pieces.push_back({q, PieceOwner::kZone, z});
    }
  }
  const Scene scene(pieces);
  long reported = 0, checked = 0;
  for (int i = 0; i < 3000; ++i) {
    Eigen::Vector3d p(kArea_m * u(rng), kArea_m * u(rng), 350.0 + 700.0 * u(rng));
    if (i % 2 == 1) {  // next to a piece's centre or vertex
      const PlanarPrism& q = pieces[rng() % pieces.size()].prism;
      const Eigen::Vector2d at = q.ring.empty() ? q.centre : q.ring[rng() % q.ring.size()];
      p.head<2>() = at + Eigen::Vector2d(300.0 * (u(rng) - 0.5), 300.0 * (u(rng) - 0.5));
    }
    const ProtectionVolume v{p, 2.0 + 60.0 * u(rng), 2.0 + 60.0 * u(rng)};
    const std::vector<SceneHit> hits = scene.query(v, kHorizon_m, kAcceptAll);
    std::vector<double> nearest(kZones, kInf);
    std::vector<bool> meets(kZones, false), boundary(kZones, false);
    for (const ScenePiece& piece : pieces) {
      const Separation m = separationMargins(v, piece.prism);
      const double deciding = std::max(m.margin_h_m, m.margin_v_m);
      meets[piece.owner_index] = meets[piece.owner_index] || deciding <= 0;
      boundary[piece.owner_index] = boundary[piece.owner_index] || std::abs(deciding) <= kContactBand_m ||
                                    std::abs(m.clearance_m - kHorizon_m) <= kContactBand_m;
      nearest[piece.owner_index] = std::min(nearest[piece.owner_index], m.clearance_m);
    }
    for (std::size_t z = 0; z < kZones; ++z) {
      if (boundary[z]) continue;
      const bool expected = meets[z] || nearest[z] <= kHorizon_m;
      const bool found = std::any_of(hits.begin(), hits.end(), [&](const SceneHit& h) { return h.owner_index == z; });
      ASSERT_EQ(found, expected) << "query " << i << " zone " << z << ": " << describe(v) << ", nearest " << nearest[z];
      ++checked;
      reported += found;
    }
  }
  EXPECT_GT(reported, 1500);  // the queries reach zones, not only empty space
  EXPECT_GT(checked, 1000000);
}

// reachesAny answers "does query(v, 0) report anything?" without FCL; the answer must be the
// same for every volume, above all those in contact or within the exact band of it.
TEST(Scene, ReachesAnyIsWhetherTheQueryAtContactReportsAnything) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  constexpr double kArea_m = 3000.0;
  // GIVEN 200 owners of one to three pieces (rings and disks, some unlimited in height)
  std::vector<ScenePiece> pieces;
  for (std::size_t z = 0; z < 200; ++z) {
    const Eigen::Vector2d c(kArea_m * u(rng), kArea_m * u(rng));
    for (int k = 0, parts = 1 + static_cast<int>(rng() % 3); k < parts; ++k) {
      PlanarPrism q;
      q.floor_h_ell_m = u(rng) < 0.2 ? -kInf : 400.0 + 100.0 * u(rng);
      q.ceiling_h_ell_m = u(rng) < 0.2 ? kInf : 600.0 + 300.0 * u(rng);
      const Eigen::Vector2d ck = c + Eigen::Vector2d(200.0 * (u(rng) - 0.5), 200.0 * (u(rng) - 0.5));
      if (u(rng) < 0.3) {
        q.centre = ck;
        q.radius_m = 10.0 + 90.0 * u(rng);
      } else {
        q.ring = regularRing(ck, 10.0 + 90.0 * u(rng), 3 + static_cast<int>(rng() % 8), 2 * kPi * u(rng));
      }
      pieces.push_back({q, z % 5 == 0 ? PieceOwner::kObstacle : PieceOwner::kZone, z});
    }
  }
  const Scene scene(pieces);
  const auto accept_some = [](PieceOwner owner, std::size_t i) { return owner == PieceOwner::kObstacle || i % 3 != 1; };
  const double offsets_m[] = {0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-3, -1e-3, 0.0099, 0.0101, -0.02, 0.5, -0.5};
  int reached = 0, near_contact = 0;
  for (int i = 0; i < 20000; ++i) {
    // WHEN a volume is placed anywhere, or sized to touch a piece to within a small offset
    Eigen::Vector3d p(kArea_m * u(rng), kArea_m * u(rng), 350.0 + 700.0 * u(rng));
    ProtectionVolume v{p, 2.0 + 40.0 * u(rng), 2.0 + 40.0 * u(rng)};
    if (i % 4 != 0) {
      const PlanarPrism& q = pieces[rng() % pieces.size()].prism;
      const Eigen::Vector2d at = q.ring.empty() ? q.centre : q.ring[rng() % q.ring.size()];
      v.p_map.head<2>() = at + Eigen::Vector2d(120.0 * (u(rng) - 0.5), 120.0 * (u(rng) - 0.5));
      const Separation m = separationMargins(v, q);
      const double offset = offsets_m[rng() % std::size(offsets_m)];
      if (m.margin_h_m >= m.margin_v_m) {
        v.hpl_m = std::max(0.0, v.hpl_m + m.margin_h_m + offset);
      } else {
        v.vpl_m = std::max(0.0, v.vpl_m + m.margin_v_m + offset);
      }
      ++near_contact;
    }
    for (const bool all : {true, false}) {
      const std::function<bool(PieceOwner, std::size_t)> accept = all ? kAcceptAll : accept_some;
      const bool expected = !scene.query(v, 0.0, accept).empty();
      // THEN reachesAny gives the query's answer
      ASSERT_EQ(scene.reachesAny(v, accept), expected) << "volume " << i << ": " << describe(v);
      reached += expected;
    }
  }
  EXPECT_GT(reached, 8000);  // both answers are common
  EXPECT_LT(reached, 32000);
  EXPECT_GT(near_contact, 10000);
}

// The broad phase's query box is computed without FCL (detail::cylinderBox); it must be FCL's
// own AABB of the query cylinder to the bit, or the grid would not find what FCL's broad phase
// finds at touching boxes.
TEST(Scene, QueryBoxIsFclsCylinderBoxToTheBit) {
  const std::unique_ptr<detail::FclPieces> fcl = detail::fclModule().make();
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const double scale = std::pow(10.0, 7.0 * u(rng) - 1.0);  // 0.1 m … 1,000 km
    const Eigen::Vector3d p(scale * (u(rng) - 0.5), scale * (u(rng) - 0.5), 3000.0 * u(rng) - 500.0);
    const double radius = std::pow(10.0, 5.0 * u(rng) - 3.0), half = std::pow(10.0, 5.0 * u(rng) - 3.0);
    const detail::FclBox expected = fcl->placeCylinder(p, radius, half);
    const detail::FclBox got = detail::cylinderBox(p, radius, half);
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(got.min[k], expected.min[k]) << "case " << i << " axis " << k;
      ASSERT_EQ(got.max[k], expected.max[k]) << "case " << i << " axis " << k;
    }
  }
}

}  // namespace
}  // namespace skylane::geofence
