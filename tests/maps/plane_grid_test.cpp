// The interpolated projection of live fixes agrees with the exact azimuthal equidistant
// projection (GeographicLib) to within 1e-8 m everywhere it interpolates, at mid latitude, across
// the antimeridian, in the south and near its polar limit; beyond its area it is the exact one.
#include "maps/geodesy.hpp"
#include "maps/plane_frame.hpp"
#include "maps/plane_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

namespace skylane::maps {
namespace {

double worstDeviation_m(double lat0_deg, double lon0_deg, double half_deg, int n, unsigned seed) {
  const PlaneFrame frame(deg2rad(lat0_deg), deg2rad(lon0_deg));
  const PlaneGrid grid(frame);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-half_deg, half_deg);
  double worst = 0.0;
  int interpolated = 0;  // not the exact bits: the grid answered, not the exact fallback
  for (int k = 0; k < n; ++k) {
    const double lat = deg2rad(std::clamp(lat0_deg + u(rng), -90.0, 90.0)), lon = deg2rad(lon0_deg + u(rng));
    const Eigen::Vector2d exact = frame.toPlane(lat, lon), near = grid.toPlane(lat, lon);
    worst = std::max(worst, (near - exact).norm());
    interpolated += near != exact;
  }
  EXPECT_GT(interpolated, n / 2);
  return worst;
}

TEST(PlaneGrid, AgreesWithTheExactProjectionToTenNanometres) {
  EXPECT_LT(worstDeviation_m(47.0, 8.0, 0.02, 20000, 1), 1e-8);    // the cells at the origin
  EXPECT_LT(worstDeviation_m(47.0, 8.0, 1.0, 50000, 2), 1e-8);     // a city's area
  EXPECT_LT(worstDeviation_m(47.0, 8.0, 1.99, 20000, 3), 1e-8);    // to the edge of the grid
  EXPECT_LT(worstDeviation_m(0.01, 179.98, 0.5, 20000, 4), 1e-8);  // the equator and the antimeridian
  EXPECT_LT(worstDeviation_m(-60.0, -70.0, 1.0, 20000, 5), 1e-8);
  EXPECT_LT(worstDeviation_m(84.5, 20.0, 0.4, 20000, 6), 1e-8);    // up to its polar limit
}

TEST(PlaneGrid, BeyondItsAreaIsTheExactProjection) {
  const PlaneFrame frame(deg2rad(47.0), deg2rad(8.0));
  const PlaneGrid grid(frame);
  for (const auto& [lat, lon] : {std::pair{47.0, 10.5}, std::pair{44.9, 8.0}, std::pair{49.1, 6.0}, std::pair{10.0, 100.0}}) {
    EXPECT_EQ(grid.toPlane(deg2rad(lat), deg2rad(lon)), frame.toPlane(deg2rad(lat), deg2rad(lon))) << lat << ", " << lon;
  }
  const PlaneFrame polar(deg2rad(84.0), 0.0);
  const PlaneGrid polar_grid(polar);
  EXPECT_EQ(polar_grid.toPlane(deg2rad(85.5), deg2rad(1.0)), polar.toPlane(deg2rad(85.5), deg2rad(1.0)));
  EXPECT_TRUE(grid.toPlane(std::nan(""), 0.1).hasNaN());
}

TEST(PlaneGrid, ThreadsBuildingCellsAtOnceGetTheSamePositions) {
  const PlaneFrame frame(deg2rad(47.0), deg2rad(8.0));
  std::vector<Eigen::Vector2d> points;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int k = 0; k < 4000; ++k) points.emplace_back(deg2rad(47.0 + u(rng)), deg2rad(8.0 + u(rng)));
  const PlaneGrid alone(frame);
  std::vector<Eigen::Vector2d> expected;
  for (const Eigen::Vector2d& p : points) expected.push_back(alone.toPlane(p.x(), p.y()));
  const PlaneGrid shared(frame);
  std::vector<std::vector<Eigen::Vector2d>> got(4);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (const Eigen::Vector2d& p : points) got[t].push_back(shared.toPlane(p.x(), p.y()));
    });
  }
  for (std::thread& th : threads) th.join();
  for (const auto& g : got) EXPECT_EQ(g, expected);
}

}  // namespace
}  // namespace skylane::maps
