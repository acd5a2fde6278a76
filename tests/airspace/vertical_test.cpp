#include "airspace/vertical.hpp"

#include "maps/geodesy.hpp"
#include "tests/maps/raster_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace skylane::airspace {
namespace {

using maps::deg2rad;

// --- sloping terrain: 500 m at 7°E rising 20 m per 0.01° eastward ----------------------------
// 50 × 20 cells of 0.01° from 46.6°N 7.0°E: centres at 7.005 + 0.01c, 46.595 − 0.01r.
constexpr double kCell_deg = 0.01;
double slope_m(double lon_deg) { return 500.0 + 2000.0 * (lon_deg - 7.0); }

const std::string& slopeTiff() {
  static const std::string path = [] {
    const double gt[6] = {7.0, kCell_deg, 0.0, 46.6, 0.0, -kCell_deg};
    return test::writeGeoTiff("skylane_slope.tif", 50, 20, gt, "EPSG:4326",
                              [](int, int c) { return slope_m(7.0 + (c + 0.5) * kCell_deg); });
  }();
  return path;
}

struct Model {
  maps::Terrain terrain = maps::Terrain::fromRaster(slopeTiff());
  const maps::Geoid& geoid = maps::Geoid::egm96();
  VerticalModel model() const { return {terrain, geoid}; }
};

VerticalLimit limit(double v, VerticalReference ref) { return {v, ref, false, ""}; }

LatLon at(double lat_deg, double lon_deg) { return {deg2rad(lat_deg), deg2rad(lon_deg)}; }

Outline box(double lat_s, double lat_n, double lon_w, double lon_e) {
  Outline o;
  o.ring = {at(lat_s, lon_w), at(lat_s, lon_e), at(lat_n, lon_e), at(lat_n, lon_w)};
  return o;
}

TEST(ZoneVertical, AglLimitFollowsTheSlopeAndTheGeoidAtAPoint) {
  const Model m;
  // GIVEN a 120 m AGL ceiling
  for (double lon : {7.1, 7.2, 7.35}) {
    const LatLon p = at(46.5, lon);
    // THEN its ellipsoidal height is the ground (AMSL) + 120 m + the EGM96 undulation there
    const double n = m.geoid.undulation_m(p.lat_rad, p.lon_rad);
    const auto h = limitHeightEllipsoid_m(limit(120, VerticalReference::kAgl), true, p, m.model());
    ASSERT_TRUE(h.has_value());
    EXPECT_NEAR(*h, slope_m(lon) + 120.0 + n, 1e-6) << "lon " << lon;
  }
  // AMSL: + N; WGS-84: as given; beyond the raster AGL is unknown
  const LatLon p = at(46.5, 7.2);
  const double n = m.geoid.undulation_m(p.lat_rad, p.lon_rad);
  EXPECT_NEAR(*limitHeightEllipsoid_m(limit(1000, VerticalReference::kAmsl), true, p, m.model()), 1000 + n, 1e-9);
  EXPECT_EQ(*limitHeightEllipsoid_m(limit(1000, VerticalReference::kWgs84), true, p, m.model()), 1000.0);
  EXPECT_FALSE(limitHeightEllipsoid_m(limit(120, VerticalReference::kAgl), true, at(46.5, 8.0), m.model()).has_value());
}

TEST(ZoneVertical, AglRangeOverAPolygonBracketsTheSlopeByAtMostOneCell) {
  const Model m;
  // GIVEN a box from 7.1°E (ground 700 m) to 7.3°E (ground 1100 m), ceiling 120 m AGL
  const Outline o = box(46.45, 46.55, 7.1, 7.3);
  const auto r = limitRange(limit(120, VerticalReference::kAgl), true, o, m.model());
  ASSERT_TRUE(r.has_value());
  // THEN the AMSL range holds 820 … 1220 m and exceeds it by at most the 10 m rise to the next
  // cell centre that bilinear interpolation can reach on either side (7.095°E, 7.305°E).
  EXPECT_LE(r->alt_amsl_min_m, 820.0);
  EXPECT_GE(r->alt_amsl_min_m, 810.0);
  EXPECT_GE(r->alt_amsl_max_m, 1220.0);
  EXPECT_LE(r->alt_amsl_max_m, 1230.0);
  // AND the ellipsoidal range adds the geoid's range over the box
  const auto [n_min, n_max] = m.geoid.undulationRange_m(deg2rad(46.45), deg2rad(46.55), deg2rad(7.1), deg2rad(7.3));
  EXPECT_NEAR(r->h_ell_min_m, r->alt_amsl_min_m + n_min, 1e-9);
  EXPECT_NEAR(r->h_ell_max_m, r->alt_amsl_max_m + n_max, 1e-9);
  // AND every ellipsoidal height along the box's centre line lies in the range
  for (int k = 0; k <= 20; ++k) {
    const auto h = limitHeightEllipsoid_m(limit(120, VerticalReference::kAgl), true, at(46.5, 7.1 + 0.01 * k), m.model());
    EXPECT_GE(*h, r->h_ell_min_m);
    EXPECT_LE(*h, r->h_ell_max_m);
  }
}

TEST(ZoneVertical, AglRangeOverACircleUsesItsCircumscribedSquare) {
  const Model m;
  // GIVEN a 2 km circle at 46.5°N 7.25°E with a 30 m AGL floor
  Outline c;
  c.kind = Outline::Kind::kCircle;
  c.centre = at(46.5, 7.25);
  c.radius_m = 2000.0;
  const auto r = limitRange(limit(30, VerticalReference::kAgl), false, c, m.model());
  ASSERT_TRUE(r.has_value());
  // 2 km east and west on the ellipsoid at 46.5°N: ± 2000 / (N(φ) cos φ) rad, N(φ) the prime
  // vertical radius of curvature: ± 0.026° of longitude → ground 948 … 1052 m.
  const double phi = deg2rad(46.5), e2 = maps::kWgs84F * (2 - maps::kWgs84F);
  const double n_phi = maps::kWgs84A_m / std::sqrt(1 - e2 * std::sin(phi) * std::sin(phi));
  const double dlon_deg = maps::rad2deg(2000.0 / (n_phi * std::cos(phi)));
  EXPECT_LE(r->alt_amsl_min_m, 30.0 + slope_m(7.25 - dlon_deg));
  EXPECT_GE(r->alt_amsl_min_m, 30.0 + slope_m(7.25 - dlon_deg) - 20.0);
  EXPECT_GE(r->alt_amsl_max_m, 30.0 + slope_m(7.25 + dlon_deg));
  EXPECT_LE(r->alt_amsl_max_m, 30.0 + slope_m(7.25 + dlon_deg) + 20.0);
  // Unlimited limits are ±∞; AGL beyond the raster is unknown.
  VerticalLimit unlimited = limit(0, VerticalReference::kAgl);
  unlimited.unlimited = true;
  EXPECT_EQ(limitRange(unlimited, true, c, m.model())->h_ell_max_m, INFINITY);
  EXPECT_EQ(limitRange(unlimited, false, c, m.model())->h_ell_min_m, -INFINITY);
  EXPECT_FALSE(limitRange(limit(30, VerticalReference::kAgl), false, box(46.5, 46.55, 7.4, 7.6), m.model()).has_value());
}

}  // namespace
}  // namespace skylane::airspace
