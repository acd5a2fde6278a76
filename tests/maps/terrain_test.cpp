#include "maps/terrain.hpp"

#include "maps/geodesy.hpp"
#include "maps/geoid.hpp"
#include "maps/parse_error.hpp"
#include "tests/maps/raster_fixture.hpp"
#include "tests/test_util.hpp"

#include <GeographicLib/UTMUPS.hpp>
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <cstdint>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace skylane::maps {
namespace {

using test::writeGeoTiff;

/// The synthetic rasters hold values exact in float, so bilinear interpolation of a plane is
/// exact up to double rounding.
constexpr double kExactTol_m = 1e-9;
/// PROJ's transverse Mercator (Poder/Engsager) and GeographicLib's (Karney) agree to well
/// under 1 mm inside a UTM zone; times the UTM plane's steepest slope (0.02) that is < 2e-5 m.
constexpr double kUtmPlaneTol_m = 1e-4;

using Ring = std::vector<std::pair<double, double>>;

/// A point in degrees.
struct LatLonDeg {
  double lat;
  double lon;
};

std::optional<double> altAt(const Terrain& t, LatLonDeg p) { return t.altAmsl_m(deg2rad(p.lat), deg2rad(p.lon)); }

Ring ringDeg(const std::vector<LatLonDeg>& pts) {
  Ring ring;
  for (const LatLonDeg& p : pts) ring.emplace_back(deg2rad(p.lat), deg2rad(p.lon));
  return ring;
}

// --- a plane in WGS-84 lon/lat ------------------------------------------------------------
// 16 × 12 cells of 1/8°, north-west corner 47°N 7°E: centres at 7 + (c + ½)/8, 47 − (r + ½)/8.
constexpr double kPlaneA_m = 400.0, kPlaneB_mPerDeg = 100.0, kPlaneC_mPerDeg = -50.0;
double plane_m(double lat_deg, double lon_deg) { return kPlaneA_m + kPlaneB_mPerDeg * lon_deg + kPlaneC_mPerDeg * lat_deg; }

const std::string& planeTiff() {
  static const std::string path = [] {
    const double gt[6] = {7.0, 0.125, 0.0, 47.0, 0.0, -0.125};
    return writeGeoTiff("skylane_plane.tif", 16, 12, gt, "EPSG:4326", [](int r, int c) {
      return plane_m(47.0 - (r + 0.5) * 0.125, 7.0 + (c + 0.5) * 0.125);
    });
  }();
  return path;
}

TEST(Terrain, BilinearReproducesAnAffinePlaneExactlyBetweenPixelCentres) {
  // GIVEN a GeoTIFF whose cell centres lie on the plane a + b·lon + c·lat
  const Terrain t = Terrain::fromRaster(planeTiff());
  EXPECT_FALSE(t.isFlat());
  // WHEN queried anywhere between the outermost centres
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> lat(47.0 - 11.5 * 0.125, 47.0 - 0.5 * 0.125), lon(7.0625, 7.0 + 15.5 * 0.125);
  for (int i = 0; i < 500; ++i) {
    const LatLonDeg p{lat(rng), lon(rng)};
    const std::optional<double> z = altAt(t, p);
    // THEN the plane comes back exactly
    ASSERT_TRUE(z.has_value()) << p.lat << " " << p.lon;
    EXPECT_NEAR(*z, plane_m(p.lat, p.lon), kExactTol_m) << p.lat << " " << p.lon;
  }
}

TEST(Terrain, OuterHalfCellTakesTheEdgeAndBeyondTheFootprintIsUnknown) {
  const Terrain t = Terrain::fromRaster(planeTiff());
  // West of the first centre (7.0625°E) but inside the raster: the first column's value.
  EXPECT_NEAR(*altAt(t, {46.5, 7.01}), plane_m(46.5, 7.0625), kExactTol_m);
  EXPECT_NEAR(*altAt(t, {47.0, 7.0}), plane_m(46.9375, 7.0625), kExactTol_m);  // the very corner
  EXPECT_FALSE(altAt(t, {46.5, 6.999}).has_value());
  EXPECT_FALSE(altAt(t, {47.001, 7.5}).has_value());
  EXPECT_FALSE(altAt(t, {45.0, 7.5}).has_value());
  EXPECT_FALSE(altAt(t, {46.5, -172.0}).has_value());  // 180° away, not wrapped onto the raster
}

TEST(Terrain, EllipsoidalHeightAddsTheEgm96Undulation) {
  const Terrain t = Terrain::fromRaster(planeTiff());
  const double lat = deg2rad(46.4), lon = deg2rad(7.6);
  const double n_m = Geoid::egm96().undulation_m(lat, lon);
  EXPECT_GT(n_m, 45.0);  // the Alps: the geoid is ~49 m above the ellipsoid
  EXPECT_NEAR(*t.heightEllipsoid_m(lat, lon), plane_m(46.4, 7.6) + n_m, kExactTol_m);
  EXPECT_FALSE(t.heightEllipsoid_m(deg2rad(40.0), lon).has_value());
}

TEST(Terrain, RangeOverAPolygonBoundsThePlaneConservativelyAndGrowsWithThePolygon) {
  const Terrain t = Terrain::fromRaster(planeTiff());
  // GIVEN a triangle inside the raster (bounding box lat 46.0..46.6, lon 7.3..7.9)
  const Ring small = ringDeg({{46.0, 7.3}, {46.6, 7.6}, {46.2, 7.9}});
  const auto range = t.rangeAmsl_m(small);
  ASSERT_TRUE(range.has_value());
  // THEN it contains the plane's extremes over the box, and exceeds them by at most one cell's rise
  const double box_lo = plane_m(46.6, 7.3), box_hi = plane_m(46.0, 7.9);
  const double cell_rise_m = 0.125 * (std::abs(kPlaneB_mPerDeg) + std::abs(kPlaneC_mPerDeg));
  EXPECT_LE(range->first, box_lo);
  EXPECT_GE(range->second, box_hi);
  EXPECT_GE(range->first, box_lo - cell_rise_m);
  EXPECT_LE(range->second, box_hi + cell_rise_m);
  // AND a larger polygon containing it never gets a narrower range (monotonicity)
  const auto larger = t.rangeAmsl_m(ringDeg({{45.8, 7.2}, {46.7, 7.2}, {46.7, 8.5}, {45.8, 8.5}}));
  ASSERT_TRUE(larger.has_value());
  EXPECT_LE(larger->first, range->first);
  EXPECT_GE(larger->second, range->second);
  // AND a polygon reaching outside the raster has an unknown range
  EXPECT_FALSE(t.rangeAmsl_m(ringDeg({{46.0, 7.3}, {46.6, 9.2}, {46.2, 7.9}})).has_value());
}

TEST(Terrain, VoidCellsMakeQueriesAndRangesUnknown) {
  // GIVEN the plane with one void cell (row 5, column 6: centre 46.3125°N, 7.8125°E)
  const double gt[6] = {7.0, 0.125, 0.0, 47.0, 0.0, -0.125};
  const std::string path = writeGeoTiff(
      "skylane_plane_void.tif", 16, 12, gt, "EPSG:4326",
      [](int r, int c) { return (r == 5 && c == 6) ? -9999.0 : plane_m(47.0 - (r + 0.5) * 0.125, 7.0 + (c + 0.5) * 0.125); },
      -9999.0);
  const Terrain t = Terrain::fromRaster(path);
  // THEN every query whose four neighbours include it is unknown …
  EXPECT_FALSE(altAt(t, {46.3125, 7.8125}).has_value());
  EXPECT_FALSE(altAt(t, {46.35, 7.85}).has_value());
  EXPECT_FALSE(altAt(t, {46.25, 7.75}).has_value());
  // … the others are still the plane …
  EXPECT_NEAR(*altAt(t, {46.1, 7.3}), plane_m(46.1, 7.3), kExactTol_m);
  // … and a polygon over the void has an unknown range, one beside it a known one.
  EXPECT_FALSE(t.rangeAmsl_m(ringDeg({{46.2, 7.7}, {46.4, 7.7}, {46.4, 7.9}})).has_value());
  EXPECT_TRUE(t.rangeAmsl_m(ringDeg({{46.0, 7.1}, {46.1, 7.1}, {46.1, 7.2}})).has_value());
}

// --- a plane in UTM zone 32N ------------------------------------------------------------------
// 50 × 40 cells of 100 m; north-west corner E 380 000, N 5 160 000 (≈ 46.58°N 7.43°E).
constexpr double kUtmE0_m = 380000.0, kUtmN0_m = 5160000.0, kUtmCell_m = 100.0;
/// 1 % up towards the east, 2 % down towards the north.
double utmPlane_m(double e_m, double n_m) { return 1000.0 + (e_m - kUtmE0_m) / 100.0 + (n_m - kUtmN0_m) / 50.0; }

const std::string& utmTiff() {
  static const std::string path = [] {
    const double gt[6] = {kUtmE0_m, kUtmCell_m, 0.0, kUtmN0_m, 0.0, -kUtmCell_m};
    return writeGeoTiff("skylane_utm32n.tif", 50, 40, gt, "EPSG:32632", [](int r, int c) {
      return utmPlane_m(kUtmE0_m + (c + 0.5) * kUtmCell_m, kUtmN0_m - (r + 0.5) * kUtmCell_m);
    });
  }();
  return path;
}

TEST(Terrain, ProjectedUtmRasterIsQueriedInLatLon) {
  const Terrain t = Terrain::fromRaster(utmTiff());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> e(kUtmE0_m + 50.0, kUtmE0_m + 4950.0), n(kUtmN0_m - 3950.0, kUtmN0_m - 50.0);
  for (int i = 0; i < 200; ++i) {
    // GIVEN a point between the raster's centres, WHEN expressed in lat/lon by GeographicLib
    const double e_m = e(rng), n_m = n(rng);
    double lat = 0, lon = 0;
    GeographicLib::UTMUPS::Reverse(32, true, e_m, n_m, lat, lon);
    // THEN the terrain (through PROJ) is the plane at that easting/northing
    const std::optional<double> z = altAt(t, {lat, lon});
    ASSERT_TRUE(z.has_value()) << lat << " " << lon;
    EXPECT_NEAR(*z, utmPlane_m(e_m, n_m), kUtmPlaneTol_m);
  }
  EXPECT_FALSE(altAt(t, {46.0, 7.43}).has_value());  // ~60 km south of the raster
  EXPECT_NE(t.describe().find("UTM zone 32N"), std::string::npos) << t.describe();
}

TEST(Terrain, UtmSlopeRisesTenMetresPerKilometreEast) {
  const Terrain t = Terrain::fromRaster(utmTiff());
  double lat_a = 0, lon_a = 0, lat_b = 0, lon_b = 0;
  GeographicLib::UTMUPS::Reverse(32, true, kUtmE0_m + 1000.0, kUtmN0_m - 2000.0, lat_a, lon_a);
  GeographicLib::UTMUPS::Reverse(32, true, kUtmE0_m + 2000.0, kUtmN0_m - 2000.0, lat_b, lon_b);
  EXPECT_NEAR(*altAt(t, {lat_b, lon_b}) - *altAt(t, {lat_a, lon_a}), 10.0, 2 * kUtmPlaneTol_m);
}

TEST(Terrain, ProjectedRangeContainsEverySampledAltitude) {
  const Terrain t = Terrain::fromRaster(utmTiff());
  const LatLonDeg sw{46.55, 7.45}, ne{46.56, 7.47};
  const auto range = t.rangeAmsl_m(ringDeg({sw, {ne.lat, sw.lon}, ne, {sw.lat, ne.lon}}));
  ASSERT_TRUE(range.has_value());
  for (int i = 0; i <= 10; ++i) {
    for (int j = 0; j <= 10; ++j) {
      const LatLonDeg p{sw.lat + i * (ne.lat - sw.lat) / 10, sw.lon + j * (ne.lon - sw.lon) / 10};
      const double z = *altAt(t, p);
      EXPECT_GE(z, range->first);
      EXPECT_LE(z, range->second);
    }
  }
}

TEST(Terrain, ConcurrentQueriesOnAProjectedRasterAgreeWithSerialOnes) {
  const Terrain t = Terrain::fromRaster(utmTiff());
  std::vector<LatLonDeg> pts;
  for (int i = 0; i < 400; ++i) pts.push_back({46.55 + 1e-5 * i, 7.45 + 2e-5 * i});
  std::vector<double> serial;
  for (const LatLonDeg& p : pts) serial.push_back(*altAt(t, p));
  std::vector<double> a(pts.size()), b(pts.size());
  std::thread ta([&] { for (std::size_t i = 0; i < pts.size(); ++i) a[i] = *altAt(t, pts[i]); });
  std::thread tb([&] { for (std::size_t i = pts.size(); i-- > 0;) b[i] = *altAt(t, pts[i]); });
  ta.join();
  tb.join();
  EXPECT_EQ(a, serial);
  EXPECT_EQ(b, serial);
}

// --- ESRI ASCII grid without CRS ---------------------------------------------------------------
TEST(Terrain, EsriAsciiGridWithoutCrsIsTakenAsWgs84LonLat) {
  // GIVEN 4 × 3 cells of 0.5° from 46°N 7°E, one void; centres lon 7.25 … 8.75, lat 47.25 … 46.25
  const std::string path = test::scratchPath("skylane_grid.asc");
  std::ofstream(path) << "ncols 4\nnrows 3\nxllcorner 7.0\nyllcorner 46.0\ncellsize 0.5\nNODATA_value -9999\n"
                         "100 110 120 130\n"
                         "200 210 -9999 230\n"
                         "300 310 320 330\n";
  const Terrain t = Terrain::fromRaster(path);
  EXPECT_NEAR(*altAt(t, {47.25, 7.25}), 100.0, kExactTol_m);         // a centre
  EXPECT_NEAR(*altAt(t, {47.0, 7.5}), 155.0, kExactTol_m);           // between four centres
  EXPECT_NEAR(*altAt(t, {46.25, 7.75}), 310.0, kExactTol_m);         // bottom row
  EXPECT_NEAR(*altAt(t, {46.25, 8.5}), 325.0, kExactTol_m);          // bottom row, between 320 and 330
  EXPECT_FALSE(altAt(t, {47.25, 8.25}).has_value());                 // a neighbour below is void
  EXPECT_FALSE(altAt(t, {46.5, 8.0}).has_value());                   // the void itself
  EXPECT_FALSE(altAt(t, {46.5, 6.9}).has_value());                   // west of the grid
  const std::string d = t.describe();
  EXPECT_NE(d.find(path), std::string::npos) << d;
  EXPECT_NE(d.find("4 x 3"), std::string::npos) << d;
  EXPECT_NE(d.find("assumed WGS-84"), std::string::npos) << d;
}

// --- SRTM .hgt ------------------------------------------------------------------------------------
TEST(Terrain, SrtmHgtTileHasItsCentresOnWholeDegreesAndAVoid) {
  // GIVEN N46E007.hgt: 1201 × 1201 big-endian int16, row 0 at 47°N, column 0 at 7°E, 3" apart;
  // z = 1000 + row − 2·column (a plane), with a void (−32768) at row 600, column 600 (46.5°N 7.5°E)
  const std::string path = test::scratchPath("N46E007.hgt");
  {
    std::ofstream out(path, std::ios::binary);
    for (int r = 0; r < 1201; ++r) {
      for (int c = 0; c < 1201; ++c) {
        const int v = (r == 600 && c == 600) ? -32768 : 1000 + r - 2 * c;
        const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
        const char be[2] = {static_cast<char>(u >> 8), static_cast<char>(u & 0xFF)};
        out.write(be, 2);
      }
    }
  }
  const Terrain t = Terrain::fromRaster(path);
  const auto hgt_plane_m = [](LatLonDeg p) { return 1000.0 + (47.0 - p.lat) * 1200.0 - 2.0 * (p.lon - 7.0) * 1200.0; };
  // THEN the tile's corners are its first and last samples …
  EXPECT_NEAR(*altAt(t, {47.0, 7.0}), 1000.0, 1e-6);
  EXPECT_NEAR(*altAt(t, {46.0, 8.0}), 1000.0 + 1200.0 - 2400.0, 1e-6);
  // … points in between lie on the plane …
  for (const LatLonDeg p : {LatLonDeg{46.2, 7.3}, LatLonDeg{46.77777, 7.123456}, LatLonDeg{46.0001, 7.9999}}) {
    EXPECT_NEAR(*altAt(t, p), hgt_plane_m(p), 1e-6) << p.lat << " " << p.lon;
  }
  // … the void and its surroundings are unknown, and so is anything off the tile.
  EXPECT_FALSE(altAt(t, {46.5, 7.5}).has_value());
  EXPECT_FALSE(altAt(t, {46.5 + 0.5 / 1200, 7.5 - 0.5 / 1200}).has_value());
  EXPECT_FALSE(altAt(t, {47.001, 7.5}).has_value());
  EXPECT_FALSE(altAt(t, {46.5, 8.001}).has_value());
  EXPECT_NE(t.describe().find("SRTMHGT"), std::string::npos) << t.describe();
}

// --- antimeridian and pole ---------------------------------------------------------------------
TEST(Terrain, GeographicRasterAcrossTheAntimeridianIsReachedFromBothSides) {
  // GIVEN cells of 0.1° from 179.5°E to 180.5°E (= −179.5°), z = 10·(column + 1)
  const double gt[6] = {179.5, 0.1, 0.0, -16.0, 0.0, -0.1};
  const std::string path = writeGeoTiff("skylane_fiji.tif", 10, 10, gt, "EPSG:4326",
                                        [](int, int c) { return 10.0 * (c + 1); });
  const Terrain t = Terrain::fromRaster(path);
  EXPECT_NEAR(*altAt(t, {-16.5, 179.55}), 10.0, kExactTol_m);
  EXPECT_NEAR(*altAt(t, {-16.5, -179.55}), 100.0, kExactTol_m);
  EXPECT_NEAR(*altAt(t, {-16.5, 180.0}), 55.0, kExactTol_m);
  EXPECT_NEAR(*altAt(t, {-16.5, -180.0}), 55.0, kExactTol_m);
  // A ring across the antimeridian spans a narrow box, not the whole raster
  const auto range = t.rangeAmsl_m(ringDeg({{-16.2, 179.92}, {-16.8, 179.92}, {-16.8, -179.92}, {-16.2, -179.92}}));
  ASSERT_TRUE(range.has_value());
  EXPECT_NEAR(range->first, 40.0, kExactTol_m);
  EXPECT_NEAR(range->second, 70.0, kExactTol_m);
}

TEST(Terrain, RingAroundThePoleCoversThePoleRow) {
  // GIVEN a global 10° raster, z = 1000 − 10·row (row 0: 80…90°N)
  const double gt[6] = {-180.0, 10.0, 0.0, 90.0, 0.0, -10.0};
  const std::string path = writeGeoTiff("skylane_global.tif", 36, 18, gt, "EPSG:4326",
                                        [](int r, int) { return 1000.0 - 10.0 * r; });
  const Terrain t = Terrain::fromRaster(path);
  // WHEN a ring at 60…65°N (rows 2 and 3 alone: 980, 970 m) winds once around the north pole
  const auto range = t.rangeAmsl_m(ringDeg({{62.0, 0.0}, {60.0, 90.0}, {65.0, 180.0}, {61.0, -90.0}}));
  // THEN its box reaches the pole: the pole row's 1000 m is in the range
  ASSERT_TRUE(range.has_value());
  EXPECT_NEAR(range->second, 1000.0, kExactTol_m);
  EXPECT_NEAR(range->first, 970.0, kExactTol_m);
}

// --- ellipsoidal datum, flat terrain, errors ----------------------------------------------------
TEST(Terrain, EllipsoidDatumRasterConvertsThroughTheGeoid) {
  const Terrain t = Terrain::fromRaster(planeTiff(), HeightDatum::kEllipsoid);
  EXPECT_EQ(t.datum(), HeightDatum::kEllipsoid);
  const LatLonDeg p{46.4, 7.6};
  const double n_m = Geoid::egm96().undulation_m(deg2rad(p.lat), deg2rad(p.lon));
  EXPECT_NEAR(*t.heightEllipsoid_m(deg2rad(p.lat), deg2rad(p.lon)), plane_m(p.lat, p.lon), kExactTol_m);
  EXPECT_NEAR(*altAt(t, p), plane_m(p.lat, p.lon) - n_m, kExactTol_m);
  const auto range = t.rangeAmsl_m(ringDeg({{46.3, 7.5}, {46.5, 7.5}, {46.5, 7.7}}));
  ASSERT_TRUE(range.has_value());
  for (double la = 46.3; la <= 46.5; la += 0.02)
    for (double lo = 7.5; lo <= 7.7; lo += 0.02) {
      EXPECT_GE(*altAt(t, {la, lo}), range->first);
      EXPECT_LE(*altAt(t, {la, lo}), range->second);
    }
  EXPECT_NE(t.describe().find("WGS-84 ellipsoid"), std::string::npos) << t.describe();
}

TEST(Terrain, FlatTerrainIsTheSameEverywhere) {
  const Terrain t = Terrain::flat(432.0);
  EXPECT_TRUE(t.isFlat());
  EXPECT_EQ(*t.altAmsl_m(0.8, -2.0), 432.0);
  EXPECT_EQ(*t.altAmsl_m(-M_PI / 2, M_PI), 432.0);
  const auto range = t.rangeAmsl_m(ringDeg({{10, 10}, {11, 10}, {11, 11}}));
  ASSERT_TRUE(range.has_value());
  EXPECT_EQ(range->first, 432.0);
  EXPECT_EQ(range->second, 432.0);
  EXPECT_NEAR(*t.heightEllipsoid_m(0.8, -2.0), 432.0 + Geoid::egm96().undulation_m(0.8, -2.0), kExactTol_m);
  EXPECT_EQ(*Terrain::flat().altAmsl_m(0.1, 0.1), 0.0);
  EXPECT_NE(t.describe().find("flat"), std::string::npos);
}

TEST(Terrain, UnreadableFileIsAParseErrorNamingTheFile) {
  const std::string missing = test::scratchPath("no_such_dem.tif");
  std::string msg = test::messageOf<ParseError>([&] { (void)Terrain::fromRaster(missing); });
  EXPECT_NE(msg.find(missing), std::string::npos) << msg;
  EXPECT_NE(msg.find("'raster'"), std::string::npos) << msg;

  const std::string garbage = test::scratchPath("skylane_not_a_dem.tif");
  std::ofstream(garbage) << "this is not a raster\n";
  msg = test::messageOf<ParseError>([&] { (void)Terrain::fromRaster(garbage); });
  EXPECT_NE(msg.find(garbage), std::string::npos) << msg;
  EXPECT_NE(msg.find("GeoTIFF"), std::string::npos) << msg;
}

TEST(Terrain, NonFiniteQueriesAreRejectedWithMessage) {
  const Terrain t = Terrain::fromRaster(planeTiff());
  std::string msg = test::messageOf<std::invalid_argument>([&] { (void)t.altAmsl_m(NAN, 0.1); });
  EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)t.rangeAmsl_m({}); });
  EXPECT_NE(msg.find("no vertex"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)t.rangeAmsl_m({{0.8, INFINITY}}); });
  EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)Terrain::flat(NAN); });
  EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
}

}  // namespace
}  // namespace skylane::maps
