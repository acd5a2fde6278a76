// The map-frame ground grid (maps/map_ground_grid.hpp) against the exact per-point path:
// PlaneFrame::toLatLon, then Terrain::heightEllipsoid_m (terrain + EGM96 geoid).
#include "maps/map_ground_grid.hpp"

#include "maps/geodesy.hpp"
#include "maps/plane_frame.hpp"
#include "maps/terrain.hpp"
#include "tests/maps/raster_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace skylane {
namespace {

using maps::deg2rad;
using maps::MapGroundGrid;
using maps::PlaneFrame;
using maps::Terrain;

/// Metres on the ground between two (lat, lon) [rad] a hair apart (local flat approximation,
/// WGS-84 a²/b: never smaller than the true distance).
double groundDistance_m(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  constexpr double kR_m = 6399593.6258;
  return kR_m * std::hypot(a.x() - b.x(), std::cos(a.x()) * std::remainder(a.y() - b.y(), 2.0 * M_PI));
}

/// The ground's steepest slope the exact path shows around `p` (central differences over ±h).
double localSlope(const PlaneFrame& f, const Terrain& t, const Eigen::Vector2d& p) {
  constexpr double kH_m = 2.0;
  const auto h = [&](double dx, double dy) {
    const Eigen::Vector2d ll = f.toLatLon(p + Eigen::Vector2d(dx, dy));
    return *t.heightEllipsoid_m(ll.x(), ll.y());
  };
  return std::hypot(h(kH_m, 0) - h(-kH_m, 0), h(0, kH_m) - h(0, -kH_m)) / (2.0 * kH_m);
}

/// GIVEN a grid over the box, WHEN random points inside are queried, THEN (lat, lon) lie within
/// the stated bound of the exact projection and heights within bound × (local slope + 2 %).
void expectWithinBound(const PlaneFrame& f, const Terrain& t, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  const MapGroundGrid grid(f, t, lo, hi);
  ASSERT_GT(grid.spacing_m().x(), 0.0);
  EXPECT_LE(grid.spacing_m().maxCoeff(), MapGroundGrid::kSpacing_m);
  EXPECT_LT(grid.positionErrorBound_m(), 2e-4) << "≤ 0.2 mm at 50 m spacing over ≤ 20 km";
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y());
  double worst_pos = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const Eigen::Vector2d p(ux(rng), uy(rng));
    ASSERT_TRUE(grid.covers(p));
    const Eigen::Vector2d exact = f.toLatLon(p), fast = grid.toLatLon(p);
    const double d_m = groundDistance_m(exact, fast);
    worst_pos = std::max(worst_pos, d_m);
    ASSERT_LE(d_m, grid.positionErrorBound_m()) << "at (" << p.x() << ", " << p.y() << ")";
    ASSERT_GE(fast.y(), -M_PI);
    ASSERT_LE(fast.y(), M_PI);
    const double h_exact = *t.heightEllipsoid_m(exact.x(), exact.y());
    const double h_fast = *grid.heightEllipsoid_m(p);
    // At a DEM cell edge (a kink) the steeper side is at most twice the central difference.
    ASSERT_LE(std::abs(h_fast - h_exact), grid.positionErrorBound_m() * (2.0 * localSlope(f, t, p) + 0.02) + 1e-9);
  }
  EXPECT_GT(worst_pos, 0.0) << "the interpolation is not the exact path";
}

TEST(MapGroundGrid, FlatGroundWithGeoidMatchesTheExactPathWithinTheBound) {
  const PlaneFrame f(deg2rad(47.318), deg2rad(8.459));  // the bench city's start
  expectWithinBound(f, Terrain::flat(408.0), {-1600.0, -2600.0}, {10600.0, 2600.0});
}

TEST(MapGroundGrid, RasterTerrainMatchesTheExactPathWithinTheBound) {
  // Hills of ±300 m every 2 km on a 1/1200° (≈ 90 m) WGS-84 raster around 47.3°N 8.5°E.
  const double gt[6] = {8.35, 1.0 / 1200, 0.0, 47.40, 0.0, -1.0 / 1200};
  const std::string path = test::writeGeoTiff("skylane_ground_grid_hills.tif", 360, 240, gt, "EPSG:4326", [](int r, int c) {
    return 500.0 + 300.0 * std::sin(r * 0.25) * std::cos(c * 0.2);
  });
  const Terrain t = Terrain::fromRaster(path);
  const PlaneFrame f(deg2rad(47.30), deg2rad(8.45));
  expectWithinBound(f, t, {-3000.0, -5000.0}, {9000.0, 5000.0});
}

TEST(MapGroundGrid, BoxAcrossTheAntimeridianKeepsLongitudesInRange) {
  const PlaneFrame f(deg2rad(-16.5), deg2rad(179.99));  // Fiji
  expectWithinBound(f, Terrain::flat(0.0), {-5000.0, -5000.0}, {5000.0, 5000.0});
}

TEST(MapGroundGrid, BoxAtAPoleAndPointsOutsideTheBoxAreExact) {
  const PlaneFrame polar(deg2rad(89.99), 0.0);
  const MapGroundGrid at_pole(polar, Terrain::flat(0.0), {-5000.0, -5000.0}, {5000.0, 5000.0});
  EXPECT_FALSE(at_pole.covers({0.0, 0.0}));
  EXPECT_EQ(at_pole.toLatLon({1234.5, -321.0}), polar.toLatLon({1234.5, -321.0}));
  const PlaneFrame f(deg2rad(47.3), deg2rad(8.45));
  const MapGroundGrid grid(f, Terrain::flat(408.0), {-1000.0, -1000.0}, {1000.0, 1000.0});
  const Eigen::Vector2d outside(1000.5, 0.0);
  EXPECT_FALSE(grid.covers(outside));
  EXPECT_EQ(grid.toLatLon(outside), f.toLatLon(outside));
  EXPECT_EQ(*grid.heightEllipsoid_m(outside), *Terrain::flat(408.0).heightEllipsoid_m(f.toLatLon(outside).x(), f.toLatLon(outside).y()));
}

}  // namespace
}  // namespace skylane
