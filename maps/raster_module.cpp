#include "maps/raster_module.hpp"

#include "maps/geodesy.hpp"
#include "maps/module_loader.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#ifndef SKYLANE_GDAL_MODULE_BUILD_PATH
// CMake defines both for skylane_maps: the module in the build tree and where it is installed.
#define SKYLANE_GDAL_MODULE_BUILD_PATH ""
#define SKYLANE_GDAL_MODULE_INSTALL_PATH ""
#endif

namespace skylane::maps::detail {
namespace {

/// Latitudes may exceed ±π/2 by this much (rounding of a degree → radian conversion).
constexpr double kLatSlack_rad = 1e-12;

/// The entry point's name carries kRasterModuleAbi.
constexpr const char* kEntryPoint = "skylane_gdal_module_v1";
static_assert(kRasterModuleAbi == 1, "rename kEntryPoint with the ABI version");

const RasterModule& loadModule() {
  const ModuleSpec spec{kRasterModuleFile, "SKYLANE_GDAL_MODULE", kEntryPoint, SKYLANE_GDAL_MODULE_BUILD_PATH,
                        SKYLANE_GDAL_MODULE_INSTALL_PATH, "reading rasters (terrain DEMs, geoid grids)"};
  return moduleTable<RasterModule>(spec);
}

}  // namespace

const RasterModule& rasterModule() {
  // A function-local static: loaded once even under concurrent first calls; a failure is
  // retried on the next call.
  static const RasterModule& module = loadModule();
  return module;
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
