#pragma once
/// \file
/// \brief The raster readers' access to GDAL, internal to maps/ (geoid grids, terrain DEMs).
///
/// GDAL and the hundred shared libraries it pulls in (PROJ, HDF5, poppler, curl, …) are not
/// linked into skylane: they cost 40 ms and 30 MiB at every start of a process that reads no
/// raster at all (`skylane --help`, `integrity spp`). The GDAL calls live in a small module,
/// `libskylane_gdal.so` (maps/gdal_module.cpp), that rasterModule() loads with dlopen the
/// first time a raster is opened. The interface below is all the readers need of GDAL: open a
/// file, its size, geotransform and CRS, band 1 row by row, and a WGS-84 ⇄ raster CRS
/// transformation. Errors come back as GDAL's message; the readers raise the ParseError.

#include <memory>
#include <string>

namespace skylane::maps::detail {

/// \brief A coordinate transformation of one point at a time (GDAL's OGRCoordinateTransformation,
/// traditional GIS axis order: longitude/easting first). Not re-entrant: callers serialise.
class CrsTransform {
 public:
  virtual ~CrsTransform() = default;
  /// \brief Transforms (x, y) in place; false when the point has no image.
  virtual bool transform(double& x, double& y) = 0;
};

/// \brief What the readers need to know of a raster's CRS.
struct RasterCrs {
  bool present = false;            ///< False: the file has none (or an empty one).
  std::string name;                ///< Its name ("unnamed" when it has none).
  bool geographic = false;         ///< A geographic (latitude/longitude) CRS.
  double angular_unit_rad = 0.0;   ///< Its angular unit [rad] (geographic CRS only).
  bool same_as_wgs84 = false;      ///< The same CRS as WGS-84 longitude/latitude.
};

/// \brief Band 1's nodata value, scale and offset (each only when the file sets it).
struct BandScaling {
  bool has_nodata = false;
  double nodata = 0.0;
  bool has_scale = false;
  double scale = 1.0;
  bool has_offset = false;
  double offset = 0.0;
};

/// \brief One raster file opened read-only with at least one band. Used from one thread.
class RasterDataset {
 public:
  virtual ~RasterDataset() = default;
  /// \brief GDAL's driver name ("GTiff", "AAIGrid", "GTX", …).
  [[nodiscard]] virtual std::string driver() const = 0;
  [[nodiscard]] virtual int cols() const = 0;
  [[nodiscard]] virtual int rows() const = 0;
  /// \brief The geotransform (GDAL layout: pixel (u, v) → CRS (x, y)); false when the file has none.
  virtual bool geoTransform(double gt[6]) const = 0;
  /// \brief The inverse of `gt` (GDALInvGeoTransform); false when it is singular.
  virtual bool invertGeoTransform(const double gt[6], double inv_gt[6]) const = 0;
  [[nodiscard]] virtual RasterCrs crs() const = 0;
  /// \brief WGS-84 longitude/latitude → the raster's CRS (`to_raster`) or back; null when PROJ
  /// has no such transformation (lastError() says why).
  [[nodiscard]] virtual std::unique_ptr<CrsTransform> wgs84Transform(bool to_raster) const = 0;
  [[nodiscard]] virtual BandScaling band1Scaling() const = 0;
  /// \brief Row `row` of band 1 as doubles into `out` (cols() values); false on a read error.
  virtual bool readBand1Row(int row, double* out) = 0;
  /// \brief GDAL's last error message on this thread, or `fallback` when it left none.
  [[nodiscard]] virtual std::string lastError(const char* fallback) const = 0;
};

/// \brief The entry points of the GDAL module.
struct RasterModule {
  /// \brief Opens `path`; null when GDAL cannot, or it has no band, with the reason in `error`.
  std::unique_ptr<RasterDataset> (*open)(const std::string& path, std::string& error);
};

/// \brief The interface version the module and skylane agree on (the entry point's name
/// carries it: a module from another build is refused, not misread).
inline constexpr int kRasterModuleAbi = 1;
/// \brief File name of the module.
inline constexpr const char* kRasterModuleFile = "libskylane_gdal.so";

/// \brief The GDAL module, loaded on the first call (thread-safe; maps/module_loader.hpp says
/// where it is looked for, $SKYLANE_GDAL_MODULE first).
/// \throws std::runtime_error naming the places looked at when it is missing or cannot load.
[[nodiscard]] const RasterModule& rasterModule();

/// \brief Throws std::invalid_argument naming `what` unless lat/lon are finite and |lat| ≤ 90°.
void requireLatLon(double lat_rad, double lon_rad, const char* what);

}  // namespace skylane::maps::detail
