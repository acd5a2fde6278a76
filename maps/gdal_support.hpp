#pragma once
/// \file
/// \brief Small helpers shared by the GDAL readers (geoid, terrain); internal to maps/.

#include <string>

namespace skylane::maps::detail {

/// \brief GDALAllRegister(), once per process (thread-safe).
void registerGdalOnce();
/// \brief GDAL's last error message, or `fallback` when GDAL left none.
[[nodiscard]] std::string gdalMessage(const char* fallback);
/// \brief Throws std::invalid_argument naming `what` unless lat/lon are finite and |lat| ≤ 90°.
void requireLatLon(double lat_rad, double lon_rad, const char* what);

}  // namespace skylane::maps::detail
