#include "maps/geodesy.hpp"

#include "tests/test_util.hpp"

#include <cmath>
#include <random>

namespace skylane::maps {
namespace {

/// Round trips must agree to well below a millimetre; GeographicLib is exact to nanometres.
constexpr double kRoundTripTol_m = 1e-6;

TEST(Geodesy, HeaderPositionOfStation3040MatchesRtklibGeodetic) {
  // GIVEN the APPROX POSITION XYZ of station 3040 (tests/data/gnss/30400920.05o)
  const Eigen::Vector3d p(-3978242.4348, 3382841.1715, 3649902.7667);
  // WHEN converted to geodetic
  const Geodetic g = ecefToGeodetic(p);
  // THEN it matches RTKLIB's ecef2pos (tests/data/rtklib/spp_summary.txt) to its printed digits
  EXPECT_NEAR(rad2deg(g.lat_rad), 35.132066140, 5e-9);
  EXPECT_NEAR(rad2deg(g.lon_rad), 139.624302130, 5e-9);
  EXPECT_NEAR(g.h_ell_m, 75.8027, 5e-4);
}

TEST(Geodesy, EquatorAndPoleHaveClosedFormEcef) {
  const Eigen::Vector3d eq = geodeticToEcef({0.0, 0.0, 0.0});
  EXPECT_NEAR(eq.x(), kWgs84A_m, 1e-6);
  EXPECT_NEAR(eq.y(), 0.0, 1e-6);
  const double b = kWgs84A_m * (1 - kWgs84F);
  const Eigen::Vector3d pole = geodeticToEcef({M_PI / 2, 1.0, 100.0});
  EXPECT_NEAR(pole.z(), b + 100.0, 1e-6);
  EXPECT_NEAR(std::hypot(pole.x(), pole.y()), 0.0, 1e-6);
}

TEST(Geodesy, GeodeticEcefRoundTripHoldsEverywhereIncludingPolesAndAntimeridian) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> lat(-M_PI / 2, M_PI / 2), lon(-M_PI, M_PI), h(-500.0, 30000.0);
  std::vector<Geodetic> pts = {{M_PI / 2, 0, 0}, {-M_PI / 2, 0, 0}, {0, M_PI, 10}, {0.5, -M_PI + 1e-12, 5}};
  for (int i = 0; i < 500; ++i) pts.push_back({lat(rng), lon(rng), h(rng)});
  for (const Geodetic& g : pts) {
    const Eigen::Vector3d p = geodeticToEcef(g);
    const Eigen::Vector3d q = geodeticToEcef(ecefToGeodetic(p));
    EXPECT_LT((p - q).norm(), kRoundTripTol_m) << "lat " << g.lat_rad << " lon " << g.lon_rad;
  }
}

TEST(Geodesy, LocalFrameRoundTripAndAxes) {
  const LocalFrame f({deg2rad(47.4), deg2rad(8.55), 420.0});
  const Eigen::Vector3d p_enu(1234.5, -987.6, 55.0);
  EXPECT_TRUE(test::nearVec(f.toEnu(f.fromEnu(p_enu)), p_enu, kRoundTripTol_m));
  // A point 100 m straight up is (0, 0, 100) in ENU.
  Geodetic up = f.origin();
  up.h_ell_m += 100.0;
  EXPECT_TRUE(test::nearVec(f.toEnu(up), Eigen::Vector3d(0, 0, 100), 1e-6));
  // A point slightly north has positive north, ~zero east.
  Geodetic north = f.origin();
  north.lat_rad += 1e-5;
  const Eigen::Vector3d n = f.toEnu(north);
  EXPECT_GT(n.y(), 60.0);
  EXPECT_NEAR(n.x(), 0.0, 1e-6);
}

TEST(Geodesy, LookAnglesOfZenithAndHorizonTargets) {
  const Geodetic site{deg2rad(35.0), deg2rad(139.0), 50.0};
  const LocalFrame f(site);
  const Eigen::Vector3d site_ecef = geodeticToEcef(site);
  const LookAngles zen = lookAngles(site_ecef, f.enuToEcef({0, 0, 20000e3}));
  EXPECT_NEAR(zen.elevation_rad, M_PI / 2, 1e-9);
  const LookAngles east = lookAngles(site_ecef, f.enuToEcef({1000.0, 0, 0}));
  EXPECT_NEAR(east.azimuth_rad, M_PI / 2, 1e-9);
  EXPECT_NEAR(east.elevation_rad, 0.0, 1e-9);
  const LookAngles sw = lookAngles(site_ecef, f.enuToEcef({-1000.0, -1000.0, 1000.0 * std::sqrt(2.0)}));
  EXPECT_NEAR(sw.azimuth_rad, deg2rad(225.0), 1e-9);
  EXPECT_NEAR(sw.elevation_rad, deg2rad(45.0), 1e-9);
  // losEnu is the unit vector of the same direction.
  EXPECT_TRUE(test::nearVec(losEnu(sw), Eigen::Vector3d(-0.5, -0.5, std::sqrt(0.5)), 1e-12));
}

TEST(Geodesy, NonFiniteOrOutOfRangeInputIsRejectedWithMessage) {
  const std::string msg = test::messageOf<std::invalid_argument>([] { (void)geodeticToEcef({NAN, 0, 0}); });
  EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
  EXPECT_THROW((void)geodeticToEcef({2.0, 0, 0}), std::invalid_argument);
  EXPECT_THROW((void)ecefToGeodetic(Eigen::Vector3d(NAN, 0, 0)), std::invalid_argument);
}

}  // namespace
}  // namespace skylane::maps
