#include "airspace/zone_geometry.hpp"

#include "maps/geodesy.hpp"
#include "maps/plane_frame.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace skylane::airspace {
namespace {

constexpr double kPi = 3.141592653589793;

/// A random star-shaped (hence simple) counter-clockwise ring of n vertices round the origin.
PlanarRing randomStar(std::mt19937& rng, int n, double radius_m) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> angles;
  for (int i = 0; i < n; ++i) angles.push_back(2 * kPi * (i + 0.1 + 0.8 * u(rng)) / n);
  PlanarRing ring;
  for (double a : angles) {
    const double r = radius_m * (0.3 + 0.7 * u(rng));
    ring.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return ring;
}

/// Distance from p to the segment ab (independent of the library under test).
double distanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

double distanceToBoundary(const Eigen::Vector2d& p, const PlanarRing& ring) {
  double d = INFINITY;
  for (std::size_t i = 0; i < ring.size(); ++i) d = std::min(d, distanceToSegment(p, ring[i], ring[(i + 1) % ring.size()]));
  return d;
}

bool isConvexCcw(const PlanarRing& ring) {
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[(i + 1) % ring.size()];
    const Eigen::Vector2d& c = ring[(i + 2) % ring.size()];
    const double cross = (b - a).x() * (c - b).y() - (b - a).y() * (c - b).x();
    if (cross < -1e-9 * (b - a).norm() * (c - b).norm()) return false;
  }
  return true;
}

Outline circleAt(double lat_deg, double lon_deg, double radius_m) {
  Outline c;
  c.kind = Outline::Kind::kCircle;
  c.centre = {maps::deg2rad(lat_deg), maps::deg2rad(lon_deg)};
  c.radius_m = radius_m;
  return c;
}

// --- circles as polygons -------------------------------------------------------------------------

TEST(ZoneGeometry, CircleVertexCountIsTheSmallestMeetingTheError) {
  struct Case { double r, e; SafeSide side; };
  for (const Case& c : {Case{100, 1, SafeSide::kContain}, Case{5000, 0.5, SafeSide::kContain},
                        Case{100, 1, SafeSide::kContained}, Case{5000, 0.5, SafeSide::kContained},
                        Case{10, 50, SafeSide::kContain}}) {
    const int n = circleVertexCount(c.r, c.e, c.side);
    // Largest deviation of a regular N-gon: circumscribed r/cos(π/N) − r, inscribed r(1 − cos(π/N)).
    const auto deviation = [&](int k) {
      return c.side == SafeSide::kContain ? c.r / std::cos(kPi / k) - c.r : c.r * (1 - std::cos(kPi / k));
    };
    EXPECT_LE(deviation(n), c.e * (1 + 1e-12)) << "r " << c.r << " e " << c.e;
    if (n > 3) {
      EXPECT_GT(deviation(n - 1), c.e) << "r " << c.r << " e " << c.e;
    }
  }
  // r = 100 m, e = 1 m circumscribed: π / acos(100/101) = 22.3 → 23
  EXPECT_EQ(circleVertexCount(100, 1, SafeSide::kContain), 23);
  EXPECT_THROW((void)circleVertexCount(100, 100, SafeSide::kContained), std::invalid_argument);
  EXPECT_THROW((void)circleVertexCount(100, 0, SafeSide::kContain), std::invalid_argument);
  EXPECT_THROW((void)circleVertexCount(NAN, 1, SafeSide::kContain), std::invalid_argument);
}

TEST(ZoneGeometry, CirclePolygonStaysOnItsSideWithinTheError) {
  // A 500 m circle at Bern and one on the antimeridian, 2 m error, both sides.
  for (const Outline& circle : {circleAt(46.95, 7.44, 500.0), circleAt(-17.0, 180.0, 1500.0)}) {
    for (SafeSide side : {SafeSide::kContain, SafeSide::kContained}) {
      const double e = 2.0;
      const Outline poly = circleToPolygon(circle, e, side);
      ASSERT_EQ(poly.kind, Outline::Kind::kPolygon);
      // Sample every edge densely in the plane at the centre, where distances are geodesic.
      const maps::PlaneFrame frame(circle.centre.lat_rad, circle.centre.lon_rad);
      double d_min = INFINITY, d_max = 0.0;
      for (std::size_t i = 0; i < poly.ring.size(); ++i) {
        const LatLon& a = poly.ring[i];
        const LatLon& b = poly.ring[(i + 1) % poly.ring.size()];
        const Eigen::Vector2d pa = frame.toPlane(a.lat_rad, a.lon_rad), pb = frame.toPlane(b.lat_rad, b.lon_rad);
        for (int k = 0; k <= 20; ++k) {
          const Eigen::Vector2d p = pa + (pb - pa) * (k / 20.0);
          d_min = std::min(d_min, p.norm());
          d_max = std::max(d_max, p.norm());
        }
      }
      const double r = circle.radius_m;
      if (side == SafeSide::kContain) {
        EXPECT_GE(d_min, r + e / 4 - 1e-6);
        EXPECT_LE(d_max, r + e + 1e-6);
      } else {
        EXPECT_GE(d_min, r - e - 1e-6);
        EXPECT_LE(d_max, r - e / 4 + 1e-6);
      }
      // Points on the circle: inside the circumscribed polygon, outside the inscribed one.
      for (int k = 0; k < 36; ++k) {
        const Eigen::Vector2d ll = frame.toLatLon({r * std::sin(k * kPi / 18), r * std::cos(k * kPi / 18)});
        EXPECT_EQ(horizontalSide(poly, {ll.x(), ll.y()}), side == SafeSide::kContain ? Side::kInside : Side::kOutside);
      }
    }
  }
}

// --- buffering -----------------------------------------------------------------------------------

TEST(ZoneGeometry, BufferedSquareHasTheSteinerArea) {
  // GIVEN a 100 m square buffered by d = 10 m within e = 0.5 m
  const PlanarRing square{{0, 0}, {100, 0}, {100, 100}, {0, 100}};
  const double d = 10.0, e = 0.5;
  const PlanarRing buffered = bufferRing(square, d, e);
  // THEN its area lies between the Steiner areas A + P·r + π r² of the exact buffers at d and d + e
  const auto steiner = [](double r) { return 100.0 * 100.0 + 400.0 * r + kPi * r * r; };
  const double area = twiceSignedArea_m2(buffered) / 2;
  EXPECT_GT(area, steiner(d));
  EXPECT_LT(area, steiner(d + e));
  // AND the east side moved out by between d + e/4 (the stated margin) and d + e
  double x_max = -INFINITY;
  for (const Eigen::Vector2d& v : buffered) x_max = std::max(x_max, v.x());
  EXPECT_GE(x_max, 100.0 + d + e / 4);
  EXPECT_LE(x_max, 100.0 + d + e);
}

TEST(ZoneGeometry, BufferContainsEveryPointWithinTheDistanceAndNothingBeyondTheError) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    const PlanarRing ring = randomStar(rng, 4 + trial % 30, 1000.0);
    const double d = 5.0 + 200.0 * u(rng), e = 0.5 + 2.0 * u(rng);
    const PlanarRing buffered = bufferRing(ring, d, e);
    ASSERT_GT(twiceSignedArea_m2(buffered), 0.0);
    // Every vertex of the buffer lies between d and d + e from the ring (and outside it).
    for (const Eigen::Vector2d& v : buffered) {
      const double dist = distanceToBoundary(v, ring);
      EXPECT_GE(dist, d * (1 - 1e-12)) << "trial " << trial;
      EXPECT_LE(dist, (d + e) * (1 + 1e-12)) << "trial " << trial;
    }
    // Random points within 0.99·d of the ring's boundary or inside it are inside the buffer.
    for (int k = 0; k < 200; ++k) {
      const std::size_t i = rng() % ring.size();
      const Eigen::Vector2d on_edge = ring[i] + (ring[(i + 1) % ring.size()] - ring[i]) * u(rng);
      const double a = 2 * kPi * u(rng), r = 0.99 * d * u(rng);
      const Eigen::Vector2d p = on_edge + r * Eigen::Vector2d(std::cos(a), std::sin(a));
      EXPECT_TRUE(test::insideByCrossings(p, buffered)) << "trial " << trial << " point " << k;
    }
  }
}

TEST(ZoneGeometry, BufferedOutlineInLatLonGrowsByTheDistanceOnTheGround) {
  // GIVEN a 1 km square near Zürich, buffered 50 m within 1 m
  const maps::PlaneFrame frame(maps::deg2rad(47.4), maps::deg2rad(8.5));
  Outline square;
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0, 0), Eigen::Vector2d(1000, 0), Eigen::Vector2d(1000, 1000),
                                   Eigen::Vector2d(0, 1000)}) {
    const Eigen::Vector2d ll = frame.toLatLon(p);
    square.ring.push_back({ll.x(), ll.y()});
  }
  const Outline buffered = bufferOutline(square, 50.0, 1.0);
  // THEN points 49.5 m out from each edge middle are inside, 51.5 m out are outside
  const Eigen::Vector2d mids[4] = {{500, 0}, {1000, 500}, {500, 1000}, {0, 500}};
  const Eigen::Vector2d normals[4] = {{0, -1}, {1, 0}, {0, 1}, {-1, 0}};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d in = frame.toLatLon(mids[i] + 49.5 * normals[i]);
    const Eigen::Vector2d out = frame.toLatLon(mids[i] + 51.5 * normals[i]);
    EXPECT_EQ(horizontalSide(buffered, {in.x(), in.y()}), Side::kInside) << "edge " << i;
    EXPECT_EQ(horizontalSide(buffered, {out.x(), out.y()}), Side::kOutside) << "edge " << i;
  }
  // AND a circle grows its radius exactly
  const Outline c = bufferOutline(circleAt(47.0, 8.0, 300.0), 25.0, 1.0);
  EXPECT_EQ(c.kind, Outline::Kind::kCircle);
  EXPECT_DOUBLE_EQ(c.radius_m, 325.0);
  EXPECT_THROW((void)bufferOutline(square, -1.0, 1.0), std::invalid_argument);
}

// --- convex decomposition -------------------------------------------------------------------------

TEST(ZoneGeometry, ConvexPiecesLieInsideAndCoverTheRing) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 60; ++trial) {
    const PlanarRing ring = randomStar(rng, 4 + trial, 500.0);
    const std::vector<PlanarRing> pieces = convexPieces(ring);
    ASSERT_FALSE(pieces.empty());
    double area_sum = 0.0;
    for (const PlanarRing& piece : pieces) {
      EXPECT_TRUE(isConvexCcw(piece)) << "trial " << trial;
      area_sum += twiceSignedArea_m2(piece) / 2;
      // Random convex combinations of a piece's vertices lie in the ring.
      for (int k = 0; k < 20; ++k) {
        Eigen::Vector2d p = Eigen::Vector2d::Zero();
        double w_sum = 0.0;
        for (const Eigen::Vector2d& v : piece) {
          const double w = u(rng);
          p += w * v;
          w_sum += w;
        }
        p /= w_sum;
        EXPECT_TRUE(segmentMeetsRing(p, p, ring)) << "trial " << trial;
      }
    }
    // The pieces' areas add up to the ring's: with the containment, their interiors are disjoint.
    EXPECT_NEAR(area_sum, twiceSignedArea_m2(ring) / 2, 1e-9 * twiceSignedArea_m2(ring)) << "trial " << trial;
    // Random points of the ring lie in some piece.
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector2d p(-500 + 1000 * u(rng), -500 + 1000 * u(rng));
      if (!test::insideByCrossings(p, ring)) continue;
      bool covered = false;
      for (const PlanarRing& piece : pieces) covered = covered || segmentMeetsRing(p, p, piece);
      EXPECT_TRUE(covered) << "trial " << trial << " point (" << p.x() << ", " << p.y() << ")";
    }
  }
}

TEST(ZoneGeometry, ConvexPiecesOfAnLAreTwoAndABowTieIsRefused) {
  const PlanarRing l_shape{{0, 0}, {20, 0}, {20, 10}, {10, 10}, {10, 20}, {0, 20}};
  EXPECT_EQ(convexPieces(l_shape).size(), 2u);
  const PlanarRing square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_EQ(convexPieces(square).size(), 1u);
  const PlanarRing bow_tie{{0, 0}, {1, 1}, {1, 0}, {0, 1}};
  EXPECT_THROW((void)convexPieces(bow_tie), std::invalid_argument);
  const PlanarRing clockwise{{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  EXPECT_THROW((void)convexPieces(clockwise), std::invalid_argument);
}

// --- segment predicates ----------------------------------------------------------------------------

TEST(ZoneGeometry, SegmentMeetsRingTableUnderTranslations) {
  // The square [0, 10]², moved by offsets exact in binary; "up" nudges a y coordinate by one
  // ulp after the move, so the near misses stay one ulp away wherever the square is.
  const PlanarRing square{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  struct Case {
    const char* name;
    Eigen::Vector2d a, b;
    bool nudge_up;
    bool meets;
  };
  const Case cases[] = {
      {"crosses two edges", {-5, 5}, {15, 5}, false, true},
      {"inside entirely", {2, 2}, {8, 3}, false, true},
      {"outside entirely", {-5, -5}, {-1, 20}, false, false},
      {"ends on an edge", {-5, 5}, {0, 5}, false, true},
      {"through a corner only", {-5, 5}, {5, 15}, false, true},
      {"past the corner by one ulp", {-5, 5}, {5, 15}, true, false},
      {"along an edge", {-5, 0}, {15, 0}, false, true},
      {"parallel to the top edge", {-5, 10}, {15, 10}, false, true},
      {"parallel one ulp above the top edge", {-5, 10}, {15, 10}, true, false},
      {"a point inside", {3, 3}, {3, 3}, false, true},
      {"a point outside", {30, 3}, {30, 3}, false, false},
  };
  const auto up = [](Eigen::Vector2d p) {
    p.y() = std::nextafter(p.y(), INFINITY);
    return p;
  };
  for (const Eigen::Vector2d& offset : {Eigen::Vector2d(0, 0), Eigen::Vector2d(-1024, 4096), Eigen::Vector2d(0.5, -0.25)}) {
    PlanarRing moved;
    for (const Eigen::Vector2d& v : square) moved.push_back(v + offset);
    for (const Case& c : cases) {
      const Eigen::Vector2d a = c.nudge_up ? up(c.a + offset) : Eigen::Vector2d(c.a + offset);
      const Eigen::Vector2d b = c.nudge_up ? up(c.b + offset) : Eigen::Vector2d(c.b + offset);
      EXPECT_EQ(segmentMeetsRing(a, b, moved), c.meets) << c.name << " at offset (" << offset.x() << ", " << offset.y() << ")";
    }
  }
}

TEST(ZoneGeometry, SegmentMeetsDiskTangentIsTouching) {
  const Eigen::Vector2d c(0, 0);
  EXPECT_TRUE(segmentMeetsDisk({-10, 3}, {10, 3}, c, 3.0));                          // tangent
  EXPECT_FALSE(segmentMeetsDisk({-10, std::nextafter(3.0, 4.0)}, {10, 3.5}, c, 3.0));  // just above
  EXPECT_TRUE(segmentMeetsDisk({1, 1}, {1, 1}, c, 3.0));                             // a point inside
  EXPECT_FALSE(segmentMeetsDisk({5, 0}, {10, 0}, c, 3.0));                           // pointing away
  EXPECT_TRUE(segmentMeetsDisk({5, 0}, {-10, 0}, c, 3.0));
}

TEST(ZoneGeometry, SegmentMeetsPrismClipsByHeightFirst) {
  PlanarPrism box;
  box.ring = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  box.floor_h_ell_m = 100.0;
  box.ceiling_h_ell_m = 200.0;
  struct Case3 {
    const char* name;
    Eigen::Vector3d a, b;
    bool meets;
  };
  const Case3 cases[] = {
      {"over the top", {-5, 5, 201}, {15, 5, 250}, false},
      {"level through the middle", {-5, 5, 150}, {15, 5, 150}, true},
      {"descends through the ceiling over the box", {5, 5, 250}, {5, 5, 150}, true},
      // h(x) = 260 − 2(x + 10): 240 … 220 m over the box, below the ceiling only from x = 20 on.
      {"descends after passing", {-10, 5, 260}, {30, 5, 180}, false},
      {"climbs into the box from below the floor", {-5, 5, 50}, {5, 5, 120}, true},
      {"touches the ceiling at the edge", {10, 5, 200}, {20, 5, 300}, true},
      {"under the floor", {-5, 5, 99}, {15, 5, 0}, false},
      {"vertical beside the box", {11, 5, 0}, {11, 5, 300}, false},
  };
  for (const Case3& c : cases) EXPECT_EQ(segmentMeetsPrism(c.a, c.b, box), c.meets) << c.name;
  // Unlimited ceiling, no floor; a disk prism.
  box.ceiling_h_ell_m = INFINITY;
  box.floor_h_ell_m = -INFINITY;
  EXPECT_TRUE(segmentMeetsPrism({-5, 5, 1e5}, {15, 5, 1e5}, box));
  PlanarPrism disk;
  disk.centre = {0, 0};
  disk.radius_m = 5.0;
  disk.floor_h_ell_m = 0.0;
  disk.ceiling_h_ell_m = 100.0;
  EXPECT_TRUE(segmentMeetsPrism({-10, 0, 50}, {10, 0, 50}, disk));
  EXPECT_FALSE(segmentMeetsPrism({-10, 0, 150}, {10, 0, 101}, disk));
  EXPECT_TRUE(segmentMeetsPrism({-10, 5, 100}, {10, 5, 100}, disk));  // tangent at the ceiling
  EXPECT_THROW((void)segmentMeetsPrism({NAN, 0, 0}, {0, 0, 0}, disk), std::invalid_argument);
}


// --- cylinder meets prism ----------------------------------------------------------------------------

/// A named case of cylinderMeetsPrism: a vertical cylinder (centre, radius, half-height)
/// against a prism, with the expected answer. Coordinates are small integers, so a case moved
/// by a dyadic offset keeps its exact distances and touching stays touching; a one-ulp nudge
/// of the centre is applied after the move (an ulp of 4 is lost when 1024 is added).
struct CylinderCase {
  const char* name;
  PlanarPrism prism;
  Eigen::Vector3d centre;
  double radius_m;
  double half_height_m;
  bool meets;
  bool nudge_east = false;  ///< move the centre one ulp east after the translation
};

PlanarPrism squarePrism(double floor_m, double ceiling_m) {
  PlanarPrism p;
  p.ring = {{0, 0}, {4, 0}, {4, 4}, {0, 4}};
  p.floor_h_ell_m = floor_m;
  p.ceiling_h_ell_m = ceiling_m;
  return p;
}

PlanarPrism diskPrism(const Eigen::Vector2d& centre, double radius_m, double floor_m, double ceiling_m) {
  PlanarPrism p;
  p.centre = centre;
  p.radius_m = radius_m;
  p.floor_h_ell_m = floor_m;
  p.ceiling_h_ell_m = ceiling_m;
  return p;
}

/// The prism moved by `t` (heights too; ±∞ stays).
PlanarPrism translated(PlanarPrism p, const Eigen::Vector3d& t) {
  for (Eigen::Vector2d& v : p.ring) v += t.head<2>();
  p.centre += t.head<2>();
  p.floor_h_ell_m += t.z();
  p.ceiling_h_ell_m += t.z();
  return p;
}

TEST(CylinderMeetsPrism, TableOfTouchingAndNearMissesUnderDyadicTranslations) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // One ulp below a value: the smallest possible miss.
  const auto below = [](double v) { return std::nextafter(v, 0.0); };
  const PlanarPrism box = squarePrism(10, 20);  // [0, 4]² × [10, 20]
  const PlanarPrism disk = diskPrism({0, 0}, 3, 10, 20);
  const CylinderCase cases[] = {
      {"disjoint horizontally (6 m from the wall, radius 5)", box, {10, 2, 15}, 5, 1, false},
      {"disjoint vertically (bottom 25 over a 20 m ceiling)", box, {2, 2, 30}, 5, 5, false},
      {"disjoint vertically (top 9 under a 10 m floor)", box, {2, 2, 4}, 5, 5, false},
      {"touching the east wall", box, {9, 2, 15}, 5, 1, true},
      {"one ulp short of the east wall", box, {9, 2, 15}, below(5.0), 1, false},
      {"touching the west wall from outside", box, {-3, 1, 15}, 3, 1, true},
      {"touching the floor from below", box, {2, 2, 5}, 1, 5, true},
      {"one ulp short of the floor", box, {2, 2, 5}, 1, below(5.0), false},
      {"touching the ceiling from above", box, {2, 2, 25}, 1, 5, true},
      {"one ulp short of the ceiling", box, {2, 2, 25}, 1, below(5.0), false},
      {"touching the wall and the ceiling at once (edge contact)", box, {9, 2, 25}, 5, 5, true},
      {"touching the vertex (4, 4) diagonally: (3, 4) away, radius 5", box, {7, 8, 15}, 5, 1, true},
      {"one ulp short of the vertex", box, {7, 8, 15}, below(5.0), 1, false},
      {"centre inside, zero size", box, {1, 3, 15}, 0, 0, true},
      {"centre on the wall, zero size", box, {4, 2, 15}, 0, 0, true},
      {"centre on the vertex, zero size", box, {4, 4, 20}, 0, 0, true},
      {"zero-size point one ulp east of the wall", box, {4, 2, 15}, 0, 0, false, true},
      {"radius 1 one ulp east of touching the wall", box, {5, 2, 15}, 1, 0, false, true},
      {"volume swallowing the prism", box, {2, 2, 15}, 100, 100, true},
      {"disk volume touching the disk prism: 10 = 3 + 7", disk, {6, 8, 15}, 7, 1, true},
      {"disk volume one ulp short of the disk prism", disk, {6, 8, 15}, below(7.0), 1, false},
      {"disk volume centre inside the disk prism", disk, {1, 1, 15}, 0, 0, true},
      {"disk volume touching the disk prism's floor", disk, {0, 0, 8}, 1, 2, true},
      {"unlimited floor: far below still meets", squarePrism(-kInf, 20), {2, 2, -1e6}, 1, 0, true},
      {"unlimited floor: above the ceiling misses", squarePrism(-kInf, 20), {2, 2, 22}, 1, 1, false},
      {"unlimited ceiling: far above still meets", squarePrism(10, kInf), {2, 2, 1e6}, 1, 0, true},
      {"unlimited ceiling: below the floor misses", squarePrism(10, kInf), {2, 2, 8}, 1, 1, false},
      {"unlimited both ways, touching the wall", squarePrism(-kInf, kInf), {9, 2, 0}, 5, 0, true},
      {"unlimited both ways, one ulp short", squarePrism(-kInf, kInf), {9, 2, 0}, below(5.0), 0, false},
      {"no heights at all (ceiling −∞)", squarePrism(-kInf, -kInf), {2, 2, 0}, 5, 5, false},
  };
  // Offsets exact in binary: every moved coordinate is still a double with no rounding.
  const Eigen::Vector3d offsets[] = {{0, 0, 0}, {1024, -4096, 0}, {0.25, -0.75, 512}, {-3 * 1024.0, 2048.25, -1024},
                                     {1048576.5, -1048576.25, 8192}};
  for (const Eigen::Vector3d& t : offsets) {
    std::ostringstream where;
    where << "offset (" << t.x() << ", " << t.y() << ", " << t.z() << ")";
    SCOPED_TRACE(where.str());
    for (const CylinderCase& c : cases) {
      SCOPED_TRACE(c.name);
      Eigen::Vector3d centre = c.centre + t;
      if (c.nudge_east) centre.x() = std::nextafter(centre.x(), INFINITY);
      EXPECT_EQ(cylinderMeetsPrism(centre, c.radius_m, c.half_height_m, translated(c.prism, t)), c.meets);
    }
  }
}

TEST(CylinderMeetsPrism, InvalidSizesAndCentresThrowWithTheValues) {
  const PlanarPrism box = squarePrism(10, 20);
  const std::string negative_radius = test::messageOf<std::invalid_argument>(
      [&] { (void)cylinderMeetsPrism({2, 2, 15}, -1.5, 2.0, box); });
  EXPECT_NE(negative_radius.find("radius and half-height must be finite and ≥ 0, got -1.5 m, 2 m"), std::string::npos)
      << negative_radius;
  const std::string negative_height = test::messageOf<std::invalid_argument>(
      [&] { (void)cylinderMeetsPrism({2, 2, 15}, 1.0, -3.0, box); });
  EXPECT_NE(negative_height.find("got 1 m, -3 m"), std::string::npos) << negative_height;
  const std::string infinite_radius = test::messageOf<std::invalid_argument>(
      [&] { (void)cylinderMeetsPrism({2, 2, 15}, INFINITY, 1.0, box); });
  EXPECT_NE(infinite_radius.find("got inf m"), std::string::npos) << infinite_radius;
  const std::string nan_centre = test::messageOf<std::invalid_argument>(
      [&] { (void)cylinderMeetsPrism({NAN, 2, 15}, 1.0, 1.0, box); });
  EXPECT_NE(nan_centre.find("non-finite centre"), std::string::npos) << nan_centre;
}

}  // namespace
}  // namespace skylane::airspace
