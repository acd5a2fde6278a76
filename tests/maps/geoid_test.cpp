#include "maps/geoid.hpp"

#include "maps/geodesy.hpp"
#include "maps/gtx_grid.hpp"
#include "maps/module_loader.hpp"
#include "maps/raster_module.hpp"
#include "maps/parse_error.hpp"
#include "tests/maps/raster_fixture.hpp"
#include "tests/test_util.hpp"

#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <cstring>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace skylane::maps {
namespace {

/// Bilinear interpolation in the 15' grid against NGA's spherical-harmonic synthesis (F477):
/// measured |error| at the six readme points 0.019, 0.003, 0.042, 0.056, 0.030, 0.007 m (max
/// 0.056 m). 0.10 m keeps margin yet catches a half-cell misregistration of the grid, which
/// moves these points by 0.98 … 1.68 m.
constexpr double kEgm96BilinearTol_m = 0.10;
/// Arithmetic only (the same interpolated N added and subtracted).
constexpr double kRoundTripTol_m = 1e-9;
/// Two points 0.002° (≈ 220 m at the equator) apart: EGM96's steepest slopes are ~1e-4, so N
/// differs by < 0.03 m; a wrap bug would jump by metres.
constexpr double kAntimeridianStepTol_m = 0.05;
/// Values stored as float in the grid (synthetic grids below hold exact small integers).
constexpr double kExactTol_m = 1e-9;

struct ReferencePoint {
  const char* name;
  double lat_deg;
  double lon_east_deg;
  double n_m;
};

/// The test values of NGA's EGM96 readme (INTPT.F / F477.F output, WW15MGH.GRD).
const std::vector<ReferencePoint> kNgaReadmePoints = {
    {"38.63N 90.22W (Missouri)", 38.6281550, 269.7791550, -31.628},
    {"14.62S 54.98W (Brazil)", -14.6212170, 305.0211140, -2.969},
    {"46.87N 102.45E (Mongolia)", 46.8743190, 102.4487290, -43.575},
    {"23.62S 133.87E (Australia)", -23.6174460, 133.8747120, 15.871},
    {"38.63N 0.0005W (Spain, next to Greenwich)", 38.6254730, 359.9995000, 50.066},
    {"0.47S 0.0023E (Gulf of Guinea)", -0.4667440, 0.0023000, 17.329},
};

/// A one-band Float32 GeoTIFF in WGS-84 lon/lat with the given geotransform; value(row, col).
std::string writeGrid(const std::string& name, int cols, int rows, const double (&gt)[6],
                      const std::function<double(int, int)>& value) {
  return test::writeGeoTiff(name, cols, rows, gt, "WGS84", value);
}

TEST(Geoid, Egm96MatchesNgaReadmeValuesWithinBilinearGridError) {
  // GIVEN the EGM96 15' grid
  const Geoid& g = Geoid::egm96();
  for (const ReferencePoint& p : kNgaReadmePoints) {
    // WHEN N is interpolated at NGA's test points
    const double n_m = g.undulation_m(deg2rad(p.lat_deg), deg2rad(p.lon_east_deg));
    // THEN it matches the spherical-harmonic values to the grid's interpolation error
    EXPECT_NEAR(n_m, p.n_m, kEgm96BilinearTol_m) << p.name;
  }
}

TEST(Geoid, PoleRowIsOneValueWhateverTheLongitude) {
  const Geoid& g = Geoid::egm96();
  // EGM96 at the poles (the grid's first and last rows): +13.606 m north, -29.534 m south.
  const double north_m = g.undulation_m(M_PI / 2, 0.0);
  const double south_m = g.undulation_m(-M_PI / 2, 0.0);
  EXPECT_NEAR(north_m, 13.606, 5e-4);
  EXPECT_NEAR(south_m, -29.534, 5e-4);
  for (double lon_deg : {-180.0, -123.4, -0.1, 45.0, 179.9, 180.0}) {
    EXPECT_NEAR(g.undulation_m(M_PI / 2, deg2rad(lon_deg)), north_m, kExactTol_m) << lon_deg;
    EXPECT_NEAR(g.undulation_m(-M_PI / 2, deg2rad(lon_deg)), south_m, kExactTol_m) << lon_deg;
  }
}

TEST(Geoid, ContinuousAcrossTheAntimeridianAndPeriodicInLongitude) {
  const Geoid& g = Geoid::egm96();
  for (double lat_deg : {-89.9, -60.0, -17.3, 0.0, 0.1, 33.3, 65.0, 89.9}) {
    const double lat = deg2rad(lat_deg);
    const double east_m = g.undulation_m(lat, deg2rad(179.999));
    const double west_m = g.undulation_m(lat, deg2rad(-179.999));
    EXPECT_NEAR(east_m, west_m, kAntimeridianStepTol_m) << "lat " << lat_deg;
    EXPECT_NEAR(g.undulation_m(lat, M_PI), g.undulation_m(lat, -M_PI), kExactTol_m) << "lat " << lat_deg;
    EXPECT_NEAR(g.undulation_m(lat, deg2rad(10.3)), g.undulation_m(lat, deg2rad(10.3 + 720.0)), 1e-6)
        << "lat " << lat_deg;
  }
}

TEST(Geoid, AmslEllipsoidRoundTripAndSign) {
  const Geoid& g = Geoid::egm96();
  // h = H + N: at the Missouri point N ≈ -31.6 m, so sea level lies 31.6 m below the ellipsoid.
  const double lat = deg2rad(38.6281550), lon = deg2rad(269.7791550);
  EXPECT_NEAR(g.ellipsoidalFromAmsl_m(lat, lon, 0.0), -31.628, kEgm96BilinearTol_m);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u_lat(-M_PI / 2, M_PI / 2), u_lon(-M_PI, M_PI), u_h(-400.0, 9000.0);
  for (int i = 0; i < 200; ++i) {
    const double la = u_lat(rng), lo = u_lon(rng), alt_amsl_m = u_h(rng);
    const double h_ell_m = g.ellipsoidalFromAmsl_m(la, lo, alt_amsl_m);
    EXPECT_NEAR(g.amslFromEllipsoidal_m(la, lo, h_ell_m), alt_amsl_m, kRoundTripTol_m);
    EXPECT_NEAR(h_ell_m - alt_amsl_m, g.undulation_m(la, lo), kRoundTripTol_m);
  }
}

TEST(Geoid, UndulationRangeBoundsEveryInterpolatedValueInTheBox) {
  const Geoid& g = Geoid::egm96();
  std::mt19937 rng(11);
  struct Box {
    const char* name;
    double s, n, w, e;  // degrees
  };
  const std::vector<Box> boxes = {{"Alps", 45.5, 47.9, 5.8, 10.6},
                                  {"across the antimeridian", -20.0, -15.0, 178.0, 183.0},
                                  {"one point", 10.0, 10.0, 20.0, 20.0},
                                  {"polar cap", 85.0, 90.0, -180.0, 180.0}};
  for (const Box& b : boxes) {
    const auto [lo, hi] = g.undulationRange_m(deg2rad(b.s), deg2rad(b.n), deg2rad(b.w), deg2rad(b.e));
    EXPECT_LE(lo, hi) << b.name;
    std::uniform_real_distribution<double> la(b.s, b.n), lo_deg(b.w, b.e);
    for (int i = 0; i < 300; ++i) {
      const double n_m = g.undulation_m(deg2rad(la(rng)), deg2rad(lo_deg(rng)));
      EXPECT_GE(n_m, lo) << b.name;
      EXPECT_LE(n_m, hi) << b.name;
    }
  }
}

TEST(Geoid, GdalPixelCentresAreTheNodesOfASyntheticGeoTiffGrid) {
  // GIVEN a global 1° pixel-is-area GeoTIFF: centres at ±0.5°, …; N = column index + 1000·row
  const double gt[6] = {-180.0, 1.0, 0.0, 90.0, 0.0, -1.0};
  const std::string path = writeGrid("skylane_geoid_synthetic.tif", 360, 180, gt,
                                     [](int r, int c) { return c + 1000.0 * r; });
  const Geoid g(path);
  EXPECT_EQ(g.path(), path);
  // THEN a cell centre gives its own value, the midpoint of two centres their mean …
  EXPECT_NEAR(g.undulation_m(deg2rad(89.5), deg2rad(-179.5)), 0.0, kExactTol_m);
  EXPECT_NEAR(g.undulation_m(deg2rad(0.5), deg2rad(10.5)), 190.0 + 89000.0, kExactTol_m);
  EXPECT_NEAR(g.undulation_m(deg2rad(0.0), deg2rad(10.0)), 189.5 + 89500.0, kExactTol_m);
  // … across the antimeridian the last column (359) meets the first (0) …
  EXPECT_NEAR(g.undulation_m(deg2rad(89.5), M_PI), 179.5, kExactTol_m);
  EXPECT_NEAR(g.undulation_m(deg2rad(89.5), deg2rad(-179.75)), 0.25 * 359.0, kExactTol_m);
  // … and latitudes beyond the outer centres are clamped to the outer rows.
  EXPECT_NEAR(g.undulation_m(M_PI / 2, deg2rad(-179.5)), 0.0, kExactTol_m);
  EXPECT_NEAR(g.undulation_m(-M_PI / 2, deg2rad(-179.5)), 179000.0, kExactTol_m);
}

/// Every node, the geotransform and the band's nodata of a GTX file, bit for bit, from skylane's
/// own reader and from GDAL's GTX driver (through the GDAL module).
void expectGtxReadersAgree(const std::string& path) {
  const std::unique_ptr<detail::RasterDataset> own = detail::openGtxGrid(path);
  std::string error;
  const std::unique_ptr<detail::RasterDataset> gdal = detail::rasterModule().open(path, error);
  ASSERT_TRUE(own) << path;
  ASSERT_TRUE(gdal) << error;
  EXPECT_EQ(own->driver(), gdal->driver());
  ASSERT_EQ(own->rows(), gdal->rows());
  ASSERT_EQ(own->cols(), gdal->cols());
  double gt_own[6], gt_gdal[6];
  ASSERT_TRUE(own->geoTransform(gt_own));
  ASSERT_TRUE(gdal->geoTransform(gt_gdal));
  EXPECT_EQ(0, std::memcmp(gt_own, gt_gdal, sizeof gt_own));
  const detail::RasterCrs c_own = own->crs(), c_gdal = gdal->crs();
  EXPECT_EQ(c_own.present, c_gdal.present);
  EXPECT_EQ(c_own.geographic, c_gdal.geographic);
  EXPECT_EQ(c_own.angular_unit_rad, c_gdal.angular_unit_rad);
  EXPECT_EQ(c_own.same_as_wgs84, c_gdal.same_as_wgs84);
  const detail::BandScaling b_own = own->band1Scaling(), b_gdal = gdal->band1Scaling();
  EXPECT_EQ(b_own.has_nodata, b_gdal.has_nodata);
  EXPECT_EQ(b_own.nodata, b_gdal.nodata);
  EXPECT_EQ(b_own.has_scale, b_gdal.has_scale);
  EXPECT_EQ(b_own.has_offset, b_gdal.has_offset);
  std::vector<double> row_own(static_cast<std::size_t>(own->cols())), row_gdal(row_own.size());
  for (int r = 0; r < own->rows(); ++r) {
    ASSERT_TRUE(own->readBand1Row(r, row_own.data()));
    ASSERT_TRUE(gdal->readBand1Row(r, row_gdal.data()));
    ASSERT_EQ(0, std::memcmp(row_own.data(), row_gdal.data(), row_own.size() * sizeof(double))) << "row " << r;
  }
}

TEST(Geoid, OwnGtxReaderMatchesGdalOnTheEgm96GridBitForBit) {
  expectGtxReadersAgree(Geoid::egm96().path());
}

TEST(Geoid, OwnGtxReaderMatchesGdalOnAGridWrittenByGdal) {
  // GIVEN a 7 × 5 GTX grid written by GDAL's own GTX driver, origin in (0, 360) longitude
  GDALAllRegister();
  const std::string path = test::scratchPath("skylane_geoid_small.gtx");
  {
    GDALDriver* gtx = GetGDALDriverManager()->GetDriverByName("GTX");
    ASSERT_NE(gtx, nullptr);
    GDALDatasetUniquePtr ds(gtx->Create(path.c_str(), 7, 5, 1, GDT_Float32, nullptr));
    ASSERT_TRUE(ds);
    double gt[6] = {200.125, 0.25, 0.0, 48.375, 0.0, -0.25};
    ASSERT_EQ(ds->SetGeoTransform(gt), CE_None);
    std::vector<float> z(35);
    for (int i = 0; i < 35; ++i) z[static_cast<std::size_t>(i)] = 0.1f * static_cast<float>(i) - 1.7f;
    ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, 7, 5, z.data(), 7, 5, GDT_Float32, 0, 0, nullptr), CE_None);
  }
  // THEN both readers see the same grid
  expectGtxReadersAgree(path);
  // … and a file that is not *.gtx is left to GDAL
  EXPECT_FALSE(detail::openGtxGrid(test::scratchPath("skylane_geoid_synthetic.tif")));
}

TEST(Geoid, MissingModuleIsAnErrorNamingTheModuleAndWhereItWasLookedFor) {
  const detail::ModuleSpec spec{"libskylane_no_such_module.so", "SKYLANE_NO_SUCH_MODULE", "entry_v1", "", "",
                                "reading rasters"};
  const std::string msg = test::messageOf<std::runtime_error>([&] { (void)detail::loadModuleEntry(spec); });
  EXPECT_NE(msg.find("reading rasters needs skylane's module libskylane_no_such_module.so"), std::string::npos) << msg;
  EXPECT_NE(msg.find("SKYLANE_NO_SUCH_MODULE"), std::string::npos) << msg;
  EXPECT_NE(msg.find("absent"), std::string::npos) << msg;
}

TEST(Geoid, MissingGridIsAParseErrorNamingTheFileAndWhereToGetIt) {
  const std::string path = test::scratchPath("no_such_geoid.gtx");
  const std::string msg = test::messageOf<ParseError>([&] { Geoid g(path); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("'grid'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("proj-data"), std::string::npos) << msg;
}

TEST(Geoid, RegionalOrVoidGridIsRefusedWithReason) {
  const double regional_gt[6] = {5.0, 0.25, 0.0, 48.0, 0.0, -0.25};
  const std::string regional = writeGrid("skylane_geoid_regional.tif", 24, 16, regional_gt,
                                         [](int, int) { return 48.0; });
  std::string msg = test::messageOf<ParseError>([&] { Geoid g(regional); });
  EXPECT_NE(msg.find(regional), std::string::npos) << msg;
  EXPECT_NE(msg.find("global grid"), std::string::npos) << msg;

  const double global_gt[6] = {-180.0, 1.0, 0.0, 90.0, 0.0, -1.0};
  const std::string with_nan = writeGrid("skylane_geoid_void.tif", 360, 180, global_gt,
                                         [](int r, int c) { return (r == 7 && c == 9) ? NAN : 1.0; });
  msg = test::messageOf<ParseError>([&] { Geoid g(with_nan); });
  EXPECT_NE(msg.find("row 7, column 9"), std::string::npos) << msg;
}

TEST(Geoid, NonFiniteOrOutOfRangeInputIsRejectedWithMessage) {
  const Geoid& g = Geoid::egm96();
  std::string msg = test::messageOf<std::invalid_argument>([&] { (void)g.undulation_m(NAN, 0.0); });
  EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)g.undulation_m(0.0, INFINITY); });
  EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)g.undulation_m(2.0, 0.0); });
  EXPECT_NE(msg.find("[-90, 90]"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)g.ellipsoidalFromAmsl_m(0.1, 0.1, NAN); });
  EXPECT_NE(msg.find("altitude AMSL is not finite"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)g.amslFromEllipsoidal_m(0.1, 0.1, INFINITY); });
  EXPECT_NE(msg.find("ellipsoidal height is not finite"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)g.undulationRange_m(0.2, 0.1, 0.0, 0.1); });
  EXPECT_NE(msg.find("not ordered"), std::string::npos) << msg;
}

TEST(Geoid, ProcessWideGridComesFromTheEnvironmentOrTheBuild) {
  const Geoid& g = Geoid::egm96();
  const char* env = std::getenv("SKYLANE_GEOID_GRID");
  if (env != nullptr && *env != '\0') {
    EXPECT_EQ(g.path(), env);
  }
  EXPECT_FALSE(g.path().empty());
  EXPECT_EQ(&g, &Geoid::egm96());  // loaded once
}

}  // namespace
}  // namespace skylane::maps
