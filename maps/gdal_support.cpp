#include "maps/gdal_support.hpp"

#include "maps/geodesy.hpp"

#include <cpl_error.h>
#include <gdal.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace skylane::maps::detail {

/// Latitudes may exceed ±π/2 by this much (rounding of a degree → radian conversion).
constexpr double kLatSlack_rad = 1e-12;

void registerGdalOnce() {
  static const bool registered = [] {
    GDALAllRegister();
    return true;
  }();
  (void)registered;
}

std::string gdalMessage(const char* fallback) {
  const char* msg = CPLGetLastErrorMsg();
  return (msg != nullptr && *msg != '\0') ? std::string(msg) : std::string(fallback);
}

void requireLatLon(double lat_rad, double lon_rad, const char* what) {
  if (!std::isfinite(lat_rad) || !std::isfinite(lon_rad) || std::abs(lat_rad) > M_PI / 2 + kLatSlack_rad) {
    std::ostringstream msg;
    msg << what << ": position (lat " << rad2deg(lat_rad) << " deg, lon " << rad2deg(lon_rad)
        << " deg) is not finite or latitude is outside [-90, 90] deg";
    throw std::invalid_argument(msg.str());
  }
}

}  // namespace skylane::maps::detail
