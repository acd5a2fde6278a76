#pragma once
/// \file
/// \brief Test rasters written with GDAL at test time (geoid and terrain tests).

#include "tests/test_util.hpp"

#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

namespace skylane::test {

/// Writes a one-band Float32 GeoTIFF; `srs_user_input` like "EPSG:4326" ("" = no CRS),
/// value(row, col); `nodata` set when finite.
inline std::string writeGeoTiff(const std::string& name, int cols, int rows, const double (&gt)[6],
                         const std::string& srs_user_input, const std::function<double(int, int)>& value,
                         double nodata = NAN) {
  GDALAllRegister();
  const std::string path = test::scratchPath(name);
  GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
  GDALDatasetUniquePtr ds(gtiff->Create(path.c_str(), cols, rows, 1, GDT_Float32, nullptr));
  double geo[6];
  std::copy(std::begin(gt), std::end(gt), geo);
  EXPECT_EQ(ds->SetGeoTransform(geo), CE_None);
  if (!srs_user_input.empty()) {
    OGRSpatialReference srs;
    EXPECT_EQ(srs.SetFromUserInput(srs_user_input.c_str()), OGRERR_NONE);
    EXPECT_EQ(ds->SetSpatialRef(&srs), CE_None);
  }
  if (std::isfinite(nodata)) {
    EXPECT_EQ(ds->GetRasterBand(1)->SetNoDataValue(nodata), CE_None);
  }
  std::vector<float> z(static_cast<std::size_t>(cols) * rows);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) z[static_cast<std::size_t>(r) * cols + c] = static_cast<float>(value(r, c));
  EXPECT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, cols, rows, z.data(), cols, rows, GDT_Float32, 0, 0, nullptr),
            CE_None);
  return path;
}

}  // namespace skylane::test
