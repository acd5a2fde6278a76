#include "maps/terrain.hpp"

#include "maps/geodesy.hpp"
#include "maps/geoid.hpp"
#include "maps/parse_error.hpp"
#include "maps/plane_frame.hpp"
#include "maps/raster_module.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace skylane::maps {
namespace {

/// What a terrain file must be, in every ParseError this file raises.
constexpr const char* kExpectedRaster =
    "an elevation raster GDAL can read (GeoTIFF, ESRI ASCII grid .asc, SRTM .hgt) with a geotransform";

/// Points per edge when a latitude/longitude box is traced into the raster's CRS (box of
/// rangeAmsl_m) or the raster's footprint into WGS-84 (describe()). A box edge's image in a
/// projected CRS bends by far less than a cell between samples this close (a 100 km edge in
/// UTM: sagitta ~5 cm), and kProjectedPad_px covers the rest.
constexpr int kEdgeSamples = 64;
/// Pixels added around a box traced into a projected CRS, for the bending between samples.
constexpr double kProjectedPad_px = 1.0;
/// One degree is this many degrees of a geographic CRS's angular unit when that unit is the
/// degree (to rounding); only then are longitudes wrapped by 360.
constexpr double kDegreeUnitTol = 1e-9;

/// x wrapped by whole turns into [centre − 180, centre + 180).
double wrapDeg(double x_deg, double centre_deg) {
  return x_deg - 360.0 * std::floor((x_deg - centre_deg + 180.0) / 360.0);
}

using CtPtr = std::unique_ptr<detail::CrsTransform>;

/// A raster's geotransform: pixel (u, v) → raster CRS (x, y), GDAL layout.
struct GeoTransform {
  double gt[6] = {0, 1, 0, 0, 0, 1};

  [[nodiscard]] double x(double u, double v) const { return gt[0] + u * gt[1] + v * gt[2]; }
  [[nodiscard]] double y(double u, double v) const { return gt[3] + u * gt[4] + v * gt[5]; }
};

/// The raster file, opened read-only (through the GDAL module), with at least one band.
std::unique_ptr<detail::RasterDataset> openRaster(const std::string& path) {
  std::string error;
  std::unique_ptr<detail::RasterDataset> ds = detail::rasterModule().open(path, error);
  if (!ds) throw ParseError(path, 0, "raster", error, kExpectedRaster);
  return ds;
}

}  // namespace

struct Terrain::Raster {
  std::string path;
  std::string driver;
  std::string crs;            ///< CRS name, or the no-CRS assumption spelled out.
  int cols = 0;
  int rows = 0;
  double inv_gt[6] = {0, 1, 0, 0, 0, 1};  ///< Raster CRS (x, y) → pixel (u, v), GDAL layout.
  std::vector<float> z_m;     ///< Band 1, row-major; NaN marks a void.
  bool identity = false;      ///< Raster CRS is WGS-84 lon/lat (or assumed so): no transformation.
  bool wrap_lon = false;      ///< Geographic CRS in degrees: longitudes wrap by 360.
  double lon_centre_deg = 0;  ///< Longitude of the raster's centre (wrap reference).
  CtPtr to_raster;            ///< WGS-84 lon/lat → raster CRS (when not identity).
  mutable std::mutex ct_mutex;
  double lat_min_deg = 0, lat_max_deg = 0, lon_min_deg = 0, lon_max_deg = 0;  ///< WGS-84 footprint.
  double cell_m = NAN;        ///< Cell size on the ground at the centre (NaN: unknown).

  [[nodiscard]] float at(int r, int c) const {
    return z_m[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c)];
  }

  /// Pixel coordinates (u, v) of a WGS-84 point: u = 0 at the raster's left edge, u = cols at
  /// its right edge, the centre of column i at u = i + 0.5 (GDAL convention). nullopt when the
  /// transformation fails (point outside the CRS's domain).
  [[nodiscard]] std::optional<std::pair<double, double>> toPixel(double lat_deg, double lon_deg) const {
    double x = lon_deg, y = lat_deg;
    if (!identity) {
      const std::lock_guard<std::mutex> lock(ct_mutex);
      if (!to_raster->transform(x, y) || !std::isfinite(x) || !std::isfinite(y)) return std::nullopt;
    }
    if (wrap_lon) x = wrapDeg(x, lon_centre_deg);
    return std::make_pair(inv_gt[0] + inv_gt[1] * x + inv_gt[2] * y, inv_gt[3] + inv_gt[4] * x + inv_gt[5] * y);
  }

  /// Bilinear between pixel centres; nullopt outside the footprint or next to a void.
  [[nodiscard]] std::optional<double> interpolate(double u, double v) const {
    if (!(u >= 0.0 && u <= cols && v >= 0.0 && v <= rows)) return std::nullopt;
    const double s = std::clamp(u - 0.5, 0.0, static_cast<double>(cols - 1));
    const double t = std::clamp(v - 0.5, 0.0, static_cast<double>(rows - 1));
    const int c0 = std::min(static_cast<int>(s), cols - 1), c1 = std::min(c0 + 1, cols - 1);
    const int r0 = std::min(static_cast<int>(t), rows - 1), r1 = std::min(r0 + 1, rows - 1);
    const double z00 = at(r0, c0), z01 = at(r0, c1), z10 = at(r1, c0), z11 = at(r1, c1);
    if (std::isnan(z00) || std::isnan(z01) || std::isnan(z10) || std::isnan(z11)) return std::nullopt;
    const double fs = s - c0, ft = t - r0;
    return (1.0 - ft) * ((1.0 - fs) * z00 + fs * z01) + ft * ((1.0 - fs) * z10 + fs * z11);
  }

  // Loading steps of Terrain::fromRaster, in order.
  /// Driver and size (at most kMaxRasterCells).
  void readSize(const detail::RasterDataset& ds);
  /// The geotransform; its inverse goes into inv_gt.
  [[nodiscard]] GeoTransform readGeoTransform(const detail::RasterDataset& ds);
  /// The CRS and the transformation WGS-84 lon/lat → raster CRS; returns the way back (null
  /// when the raster CRS is WGS-84 lon/lat).
  [[nodiscard]] CtPtr readCrs(const detail::RasterDataset& ds);
  /// The WGS-84 footprint, traced along the raster's edges.
  void traceFootprint(const GeoTransform& gt, detail::CrsTransform* to_wgs84);
  /// Cell size on the ground at the centre: geodesics to the neighbouring cell centres.
  void measureCell(const GeoTransform& gt, detail::CrsTransform* to_wgs84);
  /// Band 1, whole, voids as NaN.
  void readBand(detail::RasterDataset& ds);
};

void Terrain::Raster::readSize(const detail::RasterDataset& ds) {
  driver = ds.driver();
  cols = ds.cols();
  rows = ds.rows();
  if (static_cast<long long>(cols) * rows > kMaxRasterCells) {
    throw ParseError(path, 0, "raster.size", std::to_string(cols) + " x " + std::to_string(rows) + " cells",
                     "at most " + std::to_string(kMaxRasterCells) + " cells (crop the DEM to the mission area)");
  }
}

GeoTransform Terrain::Raster::readGeoTransform(const detail::RasterDataset& ds) {
  GeoTransform g;
  if (!ds.geoTransform(g.gt) || !ds.invertGeoTransform(g.gt, inv_gt)) {
    throw ParseError(path, 0, "raster.geotransform", "none or singular", kExpectedRaster);
  }
  return g;
}

CtPtr Terrain::Raster::readCrs(const detail::RasterDataset& ds) {
  CtPtr to_wgs84;
  const detail::RasterCrs srs = ds.crs();
  if (!srs.present) {
    identity = true;
    wrap_lon = true;
    crs = "none (assumed WGS-84 lon/lat, degrees)";
    return to_wgs84;
  }
  crs = srs.name;
  wrap_lon = srs.geographic && std::abs(rad2deg(srs.angular_unit_rad) - 1.0) <= kDegreeUnitTol;
  identity = srs.same_as_wgs84;
  if (!identity) {
    to_raster = ds.wgs84Transform(true);
    to_wgs84 = ds.wgs84Transform(false);
    if (!to_raster || !to_wgs84) {
      throw ParseError(path, 0, "raster.crs", crs + " (" + ds.lastError("no transformation from WGS-84") + ")",
                       "a CRS PROJ can transform WGS-84 longitude/latitude into");
    }
  }
  return to_wgs84;
}

void Terrain::Raster::traceFootprint(const GeoTransform& gt, detail::CrsTransform* to_wgs84) {
  bool first = true;
  for (int k = 0; k <= kEdgeSamples; ++k) {
    const double f = static_cast<double>(k) / kEdgeSamples;
    const double uv[4][2] = {{f * cols, 0.0}, {f * cols, 1.0 * rows}, {0.0, f * rows}, {1.0 * cols, f * rows}};
    for (const auto& p : uv) {
      double x = gt.x(p[0], p[1]), y = gt.y(p[0], p[1]);
      if (to_wgs84 && (!to_wgs84->transform(x, y) || !std::isfinite(x) || !std::isfinite(y))) continue;
      if (first) {
        lon_min_deg = lon_max_deg = x;
        lat_min_deg = lat_max_deg = y;
        first = false;
      }
      lon_min_deg = std::min(lon_min_deg, x);
      lon_max_deg = std::max(lon_max_deg, x);
      lat_min_deg = std::min(lat_min_deg, y);
      lat_max_deg = std::max(lat_max_deg, y);
    }
  }
  if (first) throw ParseError(path, 0, "raster.crs", crs, "a raster whose footprint maps to WGS-84 longitude/latitude");
}

void Terrain::Raster::measureCell(const GeoTransform& gt, detail::CrsTransform* to_wgs84) {
  const double uc = std::floor(0.5 * cols) + 0.5, vc = std::floor(0.5 * rows) + 0.5;
  const double uv[3][2] = {{uc, vc}, {uc + 1.0, vc}, {uc, vc + 1.0}};
  double lon[3], lat[3];
  bool ok = true;
  for (int k = 0; k < 3; ++k) {
    lon[k] = gt.x(uv[k][0], uv[k][1]);
    lat[k] = gt.y(uv[k][0], uv[k][1]);
    if (to_wgs84 && (!to_wgs84->transform(lon[k], lat[k]))) ok = false;
    ok = ok && std::isfinite(lon[k]) && std::abs(lat[k]) <= 90.0;
  }
  if (ok) {
    cell_m = std::min(geodesicDistance_m(deg2rad(lat[0]), deg2rad(lon[0]), deg2rad(lat[1]), deg2rad(lon[1])),
                      geodesicDistance_m(deg2rad(lat[0]), deg2rad(lon[0]), deg2rad(lat[2]), deg2rad(lon[2])));
  }
}

void Terrain::Raster::readBand(detail::RasterDataset& ds) {
  const detail::BandScaling b = ds.band1Scaling();
  std::vector<double> row(static_cast<std::size_t>(cols));
  z_m.resize(static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows));
  for (int j = 0; j < rows; ++j) {
    if (!ds.readBand1Row(j, row.data())) {
      throw ParseError(path, 0, "raster.band1", "unreadable row " + std::to_string(j) + " (" + ds.lastError("read error") + ")",
                       kExpectedRaster);
    }
    float* out = z_m.data() + static_cast<std::size_t>(j) * static_cast<std::size_t>(cols);
    for (int i = 0; i < cols; ++i) {
      const double raw = row[static_cast<std::size_t>(i)];
      const bool is_void = !std::isfinite(raw) || (b.has_nodata && raw == b.nodata);
      out[i] = is_void ? std::numeric_limits<float>::quiet_NaN()
                       : static_cast<float>(raw * (b.has_scale ? b.scale : 1.0) + (b.has_offset ? b.offset : 0.0));
    }
  }
}

Terrain Terrain::flat(double alt_amsl_m) {
  if (!std::isfinite(alt_amsl_m)) throw std::invalid_argument("Terrain::flat: altitude AMSL is not finite");
  Terrain t;
  t.flat_alt_amsl_m_ = alt_amsl_m;
  return t;
}

Terrain Terrain::fromRaster(const std::string& path, HeightDatum datum) {
  const std::unique_ptr<detail::RasterDataset> ds = openRaster(path);
  auto r = std::make_shared<Raster>();
  r->path = path;
  r->readSize(*ds);
  const GeoTransform gt = r->readGeoTransform(*ds);
  const CtPtr to_wgs84 = r->readCrs(*ds);
  r->lon_centre_deg = gt.x(0.5 * r->cols, 0.5 * r->rows);
  r->traceFootprint(gt, to_wgs84.get());
  r->measureCell(gt, to_wgs84.get());
  r->readBand(*ds);

  Terrain t;
  t.raster_ = std::move(r);
  t.datum_ = datum;
  return t;
}

std::optional<double> Terrain::altAmsl_m(double lat_rad, double lon_rad) const {
  detail::requireLatLon(lat_rad, lon_rad, "Terrain::altAmsl_m");
  if (!raster_) return flat_alt_amsl_m_;
  const auto uv = raster_->toPixel(rad2deg(lat_rad), rad2deg(lon_rad));
  if (!uv) return std::nullopt;
  const std::optional<double> z_m = raster_->interpolate(uv->first, uv->second);
  if (!z_m || datum_ == HeightDatum::kAmslEgm96) return z_m;
  return Geoid::egm96().amslFromEllipsoidal_m(lat_rad, lon_rad, *z_m);
}

std::optional<double> Terrain::cellSize_m() const {
  if (!raster_ || !(raster_->cell_m > 0.0)) return std::nullopt;
  return raster_->cell_m;
}

std::optional<double> Terrain::heightEllipsoid_m(double lat_rad, double lon_rad) const {
  detail::requireLatLon(lat_rad, lon_rad, "Terrain::heightEllipsoid_m");
  if (!raster_) return Geoid::egm96().ellipsoidalFromAmsl_m(lat_rad, lon_rad, flat_alt_amsl_m_);
  const auto uv = raster_->toPixel(rad2deg(lat_rad), rad2deg(lon_rad));
  if (!uv) return std::nullopt;
  const std::optional<double> z_m = raster_->interpolate(uv->first, uv->second);
  if (!z_m || datum_ == HeightDatum::kEllipsoid) return z_m;
  return Geoid::egm96().ellipsoidalFromAmsl_m(lat_rad, lon_rad, *z_m);
}

std::optional<std::pair<double, double>> Terrain::rangeAmsl_m(
    const std::vector<std::pair<double, double>>& ring_lat_lon_rad) const {
  if (ring_lat_lon_rad.empty()) throw std::invalid_argument("Terrain::rangeAmsl_m: the ring has no vertex");
  for (const auto& [lat_rad, lon_rad] : ring_lat_lon_rad) detail::requireLatLon(lat_rad, lon_rad, "Terrain::rangeAmsl_m");
  if (!raster_) return std::make_pair(flat_alt_amsl_m_, flat_alt_amsl_m_);

  // --- bounding box in degrees; longitudes unwrapped along the ring -----------------------
  double lat_min = 90.0, lat_max = -90.0, lat_sum = 0.0;
  double lon_prev = rad2deg(ring_lat_lon_rad.front().second);
  double west = lon_prev, east = lon_prev;
  for (const auto& [lat_rad, lon_rad] : ring_lat_lon_rad) {
    const double lat = rad2deg(lat_rad);
    lat_min = std::min(lat_min, lat);
    lat_max = std::max(lat_max, lat);
    lat_sum += lat;
    const double lon = wrapDeg(rad2deg(lon_rad), lon_prev);  // the shorter way round from the previous vertex
    west = std::min(west, lon);
    east = std::max(east, lon);
    lon_prev = lon;
  }
  // Closing edge back to the first vertex: a ring around a pole comes back one turn off.
  const double lon_first = rad2deg(ring_lat_lon_rad.front().second);
  if (std::abs(wrapDeg(lon_first, lon_prev) - lon_first) > 180.0) {
    west = -180.0;
    east = 180.0;
    if (lat_sum >= 0.0) lat_max = 90.0;
    else lat_min = -90.0;
  }

  // --- the box traced into pixel coordinates ----------------------------------------------
  double u_min = std::numeric_limits<double>::infinity(), u_max = -u_min, v_min = u_min, v_max = -u_min;
  for (int k = 0; k <= kEdgeSamples; ++k) {
    const double f = static_cast<double>(k) / kEdgeSamples;
    const double lat_f = lat_min + f * (lat_max - lat_min), lon_f = west + f * (east - west);
    const double pts[4][2] = {{lat_min, lon_f}, {lat_max, lon_f}, {lat_f, west}, {lat_f, east}};
    for (const auto& p : pts) {
      const auto uv = raster_->toPixel(p[0], p[1]);
      if (!uv) return std::nullopt;  // part of the box has no image in the raster's CRS
      u_min = std::min(u_min, uv->first);
      u_max = std::max(u_max, uv->first);
      v_min = std::min(v_min, uv->second);
      v_max = std::max(v_max, uv->second);
    }
  }
  const int cols = raster_->cols, rows = raster_->rows;
  if (u_min < 0.0 || v_min < 0.0 || u_max > cols || v_max > rows) return std::nullopt;
  if (!raster_->identity) {
    u_min = std::max(0.0, u_min - kProjectedPad_px);
    v_min = std::max(0.0, v_min - kProjectedPad_px);
    u_max = std::min(static_cast<double>(cols), u_max + kProjectedPad_px);
    v_max = std::min(static_cast<double>(rows), v_max + kProjectedPad_px);
  }
  // Columns the interpolation can use for u in [u_min, u_max]: floor(u − ½) and the next one.
  const int c_lo = std::clamp(static_cast<int>(std::floor(u_min - 0.5)), 0, cols - 1);
  const int c_hi = std::clamp(static_cast<int>(std::floor(u_max - 0.5)) + 1, 0, cols - 1);
  const int r_lo = std::clamp(static_cast<int>(std::floor(v_min - 0.5)), 0, rows - 1);
  const int r_hi = std::clamp(static_cast<int>(std::floor(v_max - 0.5)) + 1, 0, rows - 1);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int j = r_lo; j <= r_hi; ++j) {
    for (int i = c_lo; i <= c_hi; ++i) {
      const double z = raster_->at(j, i);
      if (std::isnan(z)) return std::nullopt;  // a void: the terrain there is unknown
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
  }
  if (datum_ == HeightDatum::kEllipsoid) {
    const auto [n_lo, n_hi] = Geoid::egm96().undulationRange_m(deg2rad(lat_min), deg2rad(lat_max),
                                                                 deg2rad(west), deg2rad(east));
    return std::make_pair(lo - n_hi, hi - n_lo);
  }
  return std::make_pair(lo, hi);
}

std::string Terrain::describe() const {
  std::ostringstream out;
  if (!raster_) {
    out << "flat terrain at " << flat_alt_amsl_m_ << " m above the EGM96 geoid";
    return out.str();
  }
  const Raster& r = *raster_;
  out.precision(6);
  out << "raster '" << r.path << "' (" << r.driver << ", " << r.cols << " x " << r.rows << " cells, CRS "
      << r.crs << ", lat " << r.lat_min_deg << ".." << r.lat_max_deg << " deg, lon " << r.lon_min_deg << ".."
      << r.lon_max_deg << " deg, heights above the "
      << (datum_ == HeightDatum::kAmslEgm96 ? "EGM96 geoid" : "WGS-84 ellipsoid") << ")";
  return out.str();
}

}  // namespace skylane::maps
