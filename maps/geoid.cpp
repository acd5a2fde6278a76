#include "maps/geoid.hpp"

#include "maps/geodesy.hpp"
#include "maps/gtx_grid.hpp"
#include "maps/parse_error.hpp"
#include "maps/raster_module.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#ifndef SKYLANE_GEOID_GRID
// CMake defines this for skylane_maps; the fallback is where Debian's proj-data installs it.
#define SKYLANE_GEOID_GRID "/usr/share/proj/egm96_15.gtx"
#endif

namespace skylane::maps {
namespace {

/// What a grid file must be, in every ParseError this file raises.
constexpr const char* kExpectedGrid =
    "a geoid grid GDAL can read (EGM96 15': /usr/share/proj/egm96_15.gtx from Debian proj-data)";

/// A grid spacing divides 360° when 360/step is this close to an integer (GDAL computes the
/// GTX step from doubles in the header; 1e-6 columns is far below any real rounding).
constexpr double kPeriodTol_cols = 1e-6;
/// Slack when comparing a latitude with ±90° (degrees): rounding in the geotransform.
constexpr double kPoleTol_deg = 1e-9;
/// One degree is this many degrees of a geographic CRS's angular unit when that unit is the
/// degree (to rounding); other angular units (grads, radians) are refused.
constexpr double kDegreeUnitTol = 1e-9;

/// The grid file, opened read-only, with at least one band: a GTX file by skylane's own
/// reader (maps/gtx_grid.hpp), anything else through the GDAL module.
std::unique_ptr<detail::RasterDataset> openGrid(const std::string& path) {
  if (std::unique_ptr<detail::RasterDataset> gtx = detail::openGtxGrid(path)) return gtx;
  std::string error;
  std::unique_ptr<detail::RasterDataset> ds = detail::rasterModule().open(path, error);
  if (!ds) throw ParseError(path, 0, "grid", error, kExpectedGrid);
  return ds;
}

/// A grid's CRS, when it has one, must be geographic in degrees.
void requireGeographicDegrees(const detail::RasterDataset& ds, const std::string& path) {
  const detail::RasterCrs srs = ds.crs();
  if (!srs.present) return;
  if (!srs.geographic || std::abs(rad2deg(srs.angular_unit_rad) - 1.0) > kDegreeUnitTol) {
    throw ParseError(path, 0, "grid.crs", srs.name, std::string("a geographic CRS in degrees; ") + kExpectedGrid);
  }
}

/// The geotransform of an axis-aligned grid (GDAL layout).
std::array<double, 6> axisAlignedGeoTransform(const detail::RasterDataset& ds, const std::string& path) {
  std::array<double, 6> gt = {0, 1, 0, 0, 0, 1};
  if (!ds.geoTransform(gt.data()) || gt[2] != 0.0 || gt[4] != 0.0 || !(gt[1] > 0.0) || gt[5] == 0.0) {
    std::ostringstream v;
    v << "geotransform (" << gt[0] << ", " << gt[1] << ", " << gt[2] << ", " << gt[3] << ", " << gt[4]
      << ", " << gt[5] << ")";
    throw ParseError(path, 0, "grid.geotransform", v.str(),
                     std::string("an axis-aligned geographic grid; ") + kExpectedGrid);
  }
  return gt;
}

/// Columns in 360° of longitude at dlon_deg spacing: a whole number, at most `cols`.
int globalPeriodColumns(int cols, double dlon_deg, const std::string& path) {
  const double period = 360.0 / dlon_deg;
  const int period_cols = static_cast<int>(std::lround(period));
  if (std::abs(period - period_cols) > kPeriodTol_cols || cols < period_cols) {
    std::ostringstream v;
    v << cols << " columns of " << dlon_deg << " deg";
    throw ParseError(path, 0, "grid.columns", v.str(),
                     std::string("a global grid (360 deg of longitude); ") + kExpectedGrid);
  }
  return period_cols;
}

/// The rows must reach to within one row of both poles.
void requirePoleRows(double lat0_deg, int rows, double dlat_deg, const std::string& path) {
  const double lat_first = lat0_deg;
  const double lat_last = lat0_deg + (rows - 1) * dlat_deg;
  const double row_step = std::abs(dlat_deg);
  if (std::max(lat_first, lat_last) < 90.0 - row_step - kPoleTol_deg ||
      std::min(lat_first, lat_last) > -90.0 + row_step + kPoleTol_deg) {
    std::ostringstream v;
    v << "rows from lat " << lat_first << " to " << lat_last << " deg";
    throw ParseError(path, 0, "grid.rows", v.str(),
                     std::string("a global grid reaching to within one row of both poles; ") + kExpectedGrid);
  }
}

/// Band 1, row-major, scaled and offset; a void node is an error.
std::vector<float> readUndulations(detail::RasterDataset& ds, int rows, int cols, const std::string& path) {
  const detail::BandScaling b = ds.band1Scaling();
  std::vector<double> row(static_cast<std::size_t>(cols));
  std::vector<float> n_m(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols));
  for (int r = 0; r < rows; ++r) {
    if (!ds.readBand1Row(r, row.data())) {
      throw ParseError(path, 0, "grid.band1", "unreadable row " + std::to_string(r) + " (" +
                       ds.lastError("read error") + ")", kExpectedGrid);
    }
    for (int c = 0; c < cols; ++c) {
      const double raw = row[static_cast<std::size_t>(c)];
      if (!std::isfinite(raw) || (b.has_nodata && raw == b.nodata)) {
        std::ostringstream v;
        v << "void (nodata) node at row " << r << ", column " << c;
        throw ParseError(path, 0, "grid.band1", v.str(), std::string("a void-free grid; ") + kExpectedGrid);
      }
      n_m[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c)] =
          static_cast<float>(raw * (b.has_scale ? b.scale : 1.0) + (b.has_offset ? b.offset : 0.0));
    }
  }
  return n_m;
}

}  // namespace

Geoid::Geoid(const std::string& grid_path) : path_(grid_path) {
  const std::unique_ptr<detail::RasterDataset> ds = openGrid(path_);
  requireGeographicDegrees(*ds, path_);
  const std::array<double, 6> gt = axisAlignedGeoTransform(*ds, path_);
  rows_ = ds->rows();
  cols_ = ds->cols();
  dlon_deg_ = gt[1];
  dlat_deg_ = gt[5];
  // GDAL pixel centres are the grid nodes (for GTX, GDAL shifts the origin by half a cell).
  lon0_deg_ = gt[0] + 0.5 * gt[1];
  lat0_deg_ = gt[3] + 0.5 * gt[5];
  period_cols_ = globalPeriodColumns(cols_, dlon_deg_, path_);
  requirePoleRows(lat0_deg_, rows_, dlat_deg_, path_);
  n_m_ = readUndulations(*ds, rows_, cols_, path_);
}

const Geoid& Geoid::egm96() {
  // A function-local static is initialised once even under concurrent first calls (C++11
  // [stmt.dcl]/4); if the constructor throws, the next call tries again.
  static const Geoid geoid([] {
    const char* env = std::getenv("SKYLANE_GEOID_GRID");
    return (env != nullptr && *env != '\0') ? std::string(env) : std::string(SKYLANE_GEOID_GRID);
  }());
  return geoid;
}

double Geoid::wrappedColumn(double lon_deg) const {
  double x = std::fmod((lon_deg - lon0_deg_) / dlon_deg_, static_cast<double>(period_cols_));
  if (x < 0.0) x += period_cols_;
  if (x >= period_cols_) x -= period_cols_;  // -tiny + period rounds up to period
  return x;
}

double Geoid::clampedRow(double lat_deg) const {
  return std::clamp((lat_deg - lat0_deg_) / dlat_deg_, 0.0, static_cast<double>(rows_ - 1));
}

double Geoid::undulation_m(double lat_rad, double lon_rad) const {
  detail::requireLatLon(lat_rad, lon_rad, "Geoid::undulation_m");
  const double x = wrappedColumn(rad2deg(lon_rad));
  const double y = clampedRow(rad2deg(lat_rad));
  const int c0 = std::min(static_cast<int>(x), period_cols_ - 1);
  const int c1 = (c0 + 1) % period_cols_;
  const int r0 = std::min(static_cast<int>(y), rows_ - 1);
  const int r1 = std::min(r0 + 1, rows_ - 1);
  const double fx = x - c0, fy = y - r0;
  const double top = (1.0 - fx) * node_m(r0, c0) + fx * node_m(r0, c1);
  const double bottom = (1.0 - fx) * node_m(r1, c0) + fx * node_m(r1, c1);
  return (1.0 - fy) * top + fy * bottom;
}

double Geoid::ellipsoidalFromAmsl_m(double lat_rad, double lon_rad, double alt_amsl_m) const {
  if (!std::isfinite(alt_amsl_m)) throw std::invalid_argument("Geoid::ellipsoidalFromAmsl_m: altitude AMSL is not finite");
  return alt_amsl_m + undulation_m(lat_rad, lon_rad);
}

double Geoid::amslFromEllipsoidal_m(double lat_rad, double lon_rad, double h_ell_m) const {
  if (!std::isfinite(h_ell_m)) throw std::invalid_argument("Geoid::amslFromEllipsoidal_m: ellipsoidal height is not finite");
  return h_ell_m - undulation_m(lat_rad, lon_rad);
}

std::pair<double, double> Geoid::undulationRange_m(double lat_min_rad, double lat_max_rad,
                                                   double lon_west_rad, double lon_east_rad) const {
  if (!std::isfinite(lat_min_rad) || !std::isfinite(lat_max_rad) || !std::isfinite(lon_west_rad) ||
      !std::isfinite(lon_east_rad) || lat_min_rad > lat_max_rad || lon_east_rad < lon_west_rad) {
    std::ostringstream msg;
    msg << "Geoid::undulationRange_m: box lat " << rad2deg(lat_min_rad) << ".." << rad2deg(lat_max_rad)
        << " deg, lon " << rad2deg(lon_west_rad) << ".." << rad2deg(lon_east_rad)
        << " deg is not finite or not ordered (min <= max, west <= east)";
    throw std::invalid_argument(msg.str());
  }
  const double ya = clampedRow(rad2deg(std::clamp(lat_min_rad, -M_PI / 2, M_PI / 2)));
  const double yb = clampedRow(rad2deg(std::clamp(lat_max_rad, -M_PI / 2, M_PI / 2)));
  const int r_lo = static_cast<int>(std::floor(std::min(ya, yb)));
  const int r_hi = std::min(static_cast<int>(std::ceil(std::max(ya, yb))), rows_ - 1);
  // Columns: from the west edge's left node eastwards, span columns (whole circle at most).
  const double span_cols = (rad2deg(lon_east_rad) - rad2deg(lon_west_rad)) / dlon_deg_;
  const double x_west = wrappedColumn(rad2deg(lon_west_rad));
  const int c_first = static_cast<int>(std::floor(x_west));
  const int n_cols = std::min(static_cast<int>(std::ceil(x_west + span_cols)) - c_first + 1, period_cols_);
  double lo = node_m(r_lo, c_first % period_cols_), hi = lo;
  for (int r = r_lo; r <= r_hi; ++r) {
    for (int k = 0; k < n_cols; ++k) {
      const double n = node_m(r, (c_first + k) % period_cols_);
      lo = std::min(lo, n);
      hi = std::max(hi, n);
    }
  }
  return {lo, hi};
}

}  // namespace skylane::maps
