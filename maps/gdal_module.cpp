/// \file
/// \brief libskylane_gdal.so: the GDAL side of maps/raster_module.hpp, loaded with dlopen on
/// the first raster read (the only file of skylane that includes GDAL).

#include "maps/raster_module.hpp"

#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <memory>
#include <string>

namespace skylane::maps::detail {
namespace {

/// WGS-84 geographic, longitude first (what skylane's radians become before GDAL sees them).
OGRSpatialReference wgs84LonLat() {
  OGRSpatialReference srs;
  srs.SetWellKnownGeogCS("WGS84");
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return srs;
}

struct CtDeleter {
  void operator()(OGRCoordinateTransformation* ct) const { OGRCoordinateTransformation::DestroyCT(ct); }
};

class GdalTransform final : public CrsTransform {
 public:
  explicit GdalTransform(OGRCoordinateTransformation* ct) : ct_(ct) {}
  bool transform(double& x, double& y) override { return ct_->Transform(1, &x, &y) != FALSE; }

 private:
  std::unique_ptr<OGRCoordinateTransformation, CtDeleter> ct_;
};

class GdalRaster final : public RasterDataset {
 public:
  explicit GdalRaster(GDALDatasetUniquePtr ds) : ds_(std::move(ds)) {
    const OGRSpatialReference* srs = ds_->GetSpatialRef();
    if (srs != nullptr && !srs->IsEmpty()) {
      srs_ = std::make_unique<OGRSpatialReference>(*srs);
      srs_->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    }
  }

  std::string driver() const override {
    return ds_->GetDriver() != nullptr ? ds_->GetDriver()->GetDescription() : "?";
  }
  int cols() const override { return ds_->GetRasterXSize(); }
  int rows() const override { return ds_->GetRasterYSize(); }
  bool geoTransform(double gt[6]) const override { return ds_->GetGeoTransform(gt) == CE_None; }
  bool invertGeoTransform(const double gt[6], double inv_gt[6]) const override {
    double g[6] = {gt[0], gt[1], gt[2], gt[3], gt[4], gt[5]};
    return GDALInvGeoTransform(g, inv_gt) != FALSE;
  }

  RasterCrs crs() const override {
    RasterCrs c;
    if (!srs_) return c;
    c.present = true;
    const char* name = srs_->GetName();
    c.name = name != nullptr ? name : "unnamed";
    c.geographic = srs_->IsGeographic() != FALSE;
    c.angular_unit_rad = srs_->GetAngularUnits(nullptr);
    const OGRSpatialReference wgs84 = wgs84LonLat();
    c.same_as_wgs84 = srs_->IsSame(&wgs84) != FALSE;
    return c;
  }

  std::unique_ptr<CrsTransform> wgs84Transform(bool to_raster) const override {
    if (!srs_) return nullptr;
    const OGRSpatialReference wgs84 = wgs84LonLat();
    OGRCoordinateTransformation* ct = to_raster ? OGRCreateCoordinateTransformation(&wgs84, srs_.get())
                                                : OGRCreateCoordinateTransformation(srs_.get(), &wgs84);
    if (ct == nullptr) return nullptr;
    return std::make_unique<GdalTransform>(ct);
  }

  BandScaling band1Scaling() const override {
    GDALRasterBand* band = ds_->GetRasterBand(1);
    int has_nodata = 0, has_scale = 0, has_offset = 0;
    BandScaling s;
    s.nodata = band->GetNoDataValue(&has_nodata);
    s.scale = band->GetScale(&has_scale);
    s.offset = band->GetOffset(&has_offset);
    s.has_nodata = has_nodata != 0;
    s.has_scale = has_scale != 0;
    s.has_offset = has_offset != 0;
    return s;
  }

  bool readBand1Row(int row, double* out) override {
    const int cols = ds_->GetRasterXSize();
    return ds_->GetRasterBand(1)->RasterIO(GF_Read, 0, row, cols, 1, out, cols, 1, GDT_Float64, 0, 0, nullptr) ==
           CE_None;
  }

  std::string lastError(const char* fallback) const override {
    const char* msg = CPLGetLastErrorMsg();
    return (msg != nullptr && *msg != '\0') ? std::string(msg) : std::string(fallback);
  }

 private:
  GDALDatasetUniquePtr ds_;
  std::unique_ptr<OGRSpatialReference> srs_;  ///< The file's CRS, longitude first; null: none.
};

std::unique_ptr<RasterDataset> openRaster(const std::string& path, std::string& error) {
  CPLErrorReset();
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR));
  if (!ds) {
    const char* msg = CPLGetLastErrorMsg();
    error = "unreadable (" + ((msg != nullptr && *msg != '\0') ? std::string(msg) : std::string("GDAL cannot open it")) + ")";
    return nullptr;
  }
  if (ds->GetRasterCount() < 1) {
    error = "no raster band";
    return nullptr;
  }
  return std::make_unique<GdalRaster>(std::move(ds));
}

}  // namespace
}  // namespace skylane::maps::detail

/// The module's one exported symbol (its name carries kRasterModuleAbi). GDAL is registered
/// once, here, and reports through its quiet handler: its messages go into skylane's
/// ParseErrors (lastError()), never straight to stderr.
extern "C" __attribute__((visibility("default"))) const skylane::maps::detail::RasterModule* skylane_gdal_module_v1() {
  static const skylane::maps::detail::RasterModule module = [] {
    GDALAllRegister();
    CPLSetErrorHandler(CPLQuietErrorHandler);
    return skylane::maps::detail::RasterModule{&skylane::maps::detail::openRaster};
  }();
  return &module;
}
