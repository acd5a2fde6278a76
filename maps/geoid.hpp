#pragma once
/// \file
/// \brief EGM96 geoid undulation from a global grid: h_ell = H_amsl + N.
///
/// The model is the NGA/NASA Earth Gravitational Model 1996 (F. G. Lemoine et al., "The
/// Development of the Joint NASA GSFC and NIMA Geopotential Model EGM96", NASA/TP-1998-206861),
/// read as a grid of undulations N [m] above the WGS-84 ellipsoid — by default PROJ's 15'
/// grid `egm96_15.gtx` (Debian package proj-data). Heights "above mean sea level" in skylane
/// mean orthometric heights above this geoid (what SRTM, aeronautical charts and barometric
/// QNH altitudes refer to, to within the model's decimetres).

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace skylane::maps {

/// \brief A global geoid-undulation grid held in memory, interpolated bilinearly.
///
/// The grid is read once with GDAL at construction (GTX, GeoTIFF or any raster GDAL reads
/// whose CRS is geographic — or absent, then WGS-84 longitude/latitude is assumed) and GDAL is
/// not used afterwards, so a `Geoid` is immutable and its queries are thread-safe. The grid
/// must be axis-aligned (no rotation terms in its geotransform), cover all 360° of longitude
/// (a duplicated ±180° column is allowed), reach to within one row of both poles, and hold no
/// void (nodata) node.
///
/// Grid nodes are GDAL pixel centres: GDAL describes a GTX grid, whose nodes are points, with
/// a geotransform shifted by half a cell (egm96_15.gtx: origin −180.125°, 90.125°, step
/// 0.25°), so the centre of pixel (0, 0) is the node at lon −180°, lat 90°.
/// Between nodes N is bilinear in (lon, lat) degrees; longitudes wrap across ±180°; a latitude
/// beyond the first or last row is clamped to that row (for EGM96 those rows are the poles).
class Geoid {
 public:
  /// \brief Loads the whole grid at `grid_path` into memory.
  /// \throws ParseError naming the file when GDAL cannot read it or it is not a global,
  /// void-free, axis-aligned geographic grid.
  explicit Geoid(const std::string& grid_path);

  /// \brief The process-wide EGM96 grid: the path in environment variable SKYLANE_GEOID_GRID
  /// when set and not empty, else the build's SKYLANE_GEOID_GRID (default
  /// /usr/share/proj/egm96_15.gtx). Loaded on first use, once, thread-safe (a failed load
  /// throws and is retried on the next call).
  /// \throws ParseError when the grid cannot be loaded.
  [[nodiscard]] static const Geoid& egm96();

  /// \brief Geoid undulation N [m]: height of the geoid above the WGS-84 ellipsoid.
  /// \throws std::invalid_argument when a coordinate is not finite or |lat| > π/2.
  [[nodiscard]] double undulation_m(double lat_rad, double lon_rad) const;

  /// \brief Ellipsoidal height h = H + N of a point at `alt_amsl_m` above the geoid.
  [[nodiscard]] double ellipsoidalFromAmsl_m(double lat_rad, double lon_rad, double alt_amsl_m) const;

  /// \brief Height above the geoid H = h − N of a point at ellipsoidal height `h_ell_m`.
  [[nodiscard]] double amslFromEllipsoidal_m(double lat_rad, double lon_rad, double h_ell_m) const;

  /// \brief Smallest and largest N [m] over a latitude/longitude box, conservative: the
  /// extremes of every grid node that bilinear interpolation anywhere in the box can use (so
  /// every `undulation_m` inside the box lies in the range). The box runs east from
  /// `lon_west_rad` to `lon_east_rad` (east ≥ west; either may lie outside ±π, so a box across
  /// the antimeridian is e.g. west 3.1, east 3.2).
  /// \throws std::invalid_argument on non-finite bounds, lat_min > lat_max or east < west.
  [[nodiscard]] std::pair<double, double> undulationRange_m(double lat_min_rad, double lat_max_rad,
                                                            double lon_west_rad,
                                                            double lon_east_rad) const;

  /// \brief The file the grid was read from.
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  /// \brief N at grid node (row, col), col already wrapped into [0, period_cols_).
  [[nodiscard]] double node_m(int row, int col) const {
    return static_cast<double>(n_m_[static_cast<std::size_t>(row) * static_cast<std::size_t>(cols_) +
                                    static_cast<std::size_t>(col)]);
  }
  /// \brief Fractional column of a longitude, wrapped into [0, period_cols_).
  [[nodiscard]] double wrappedColumn(double lon_deg) const;
  /// \brief Fractional row of a latitude, clamped to [0, rows_ − 1].
  [[nodiscard]] double clampedRow(double lat_deg) const;

  std::string path_;
  std::vector<float> n_m_;     ///< Undulations, row-major, rows_ × cols_.
  int rows_ = 0;
  int cols_ = 0;
  int period_cols_ = 0;        ///< Columns in 360° of longitude (≤ cols_).
  double lon0_deg_ = 0.0;      ///< Longitude of the centre of column 0.
  double dlon_deg_ = 0.0;      ///< Column spacing (> 0).
  double lat0_deg_ = 0.0;      ///< Latitude of the centre of row 0.
  double dlat_deg_ = 0.0;      ///< Row spacing, signed (< 0 for a north-up grid).
};

}  // namespace skylane::maps
