#pragma once
/// \file
/// \brief Terrain elevation: a flat plane or a digital elevation model raster read with GDAL.
///
/// Zones whose limits are "above ground level" are resolved with this model (docs/method.md §1.2
/// Frames, units, time). Heights above mean sea level mean above the EGM96 geoid (maps/geoid.hpp).
/// SRTM heights are EGM96 heights, so kAmslEgm96 is the default datum; other "sea level" DEMs
/// (Copernicus GLO-30 on EGM2008, national DEMs on their own geoids) are read the same way and
/// carry the difference between their geoid and EGM96 (decimetres, up to a few metres in places).

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace skylane::maps {

/// \brief What a raster's heights are measured from.
enum class HeightDatum {
  kAmslEgm96,  ///< Orthometric heights above the EGM96 geoid ("above mean sea level").
  kEllipsoid,  ///< Heights above the WGS-84 ellipsoid.
};

/// \brief Terrain elevation over a region: flat, or a raster held in memory.
///
/// A raster terrain reads band 1 of any raster GDAL can open — GeoTIFF, ESRI ASCII grid
/// (.asc), SRTM .hgt, … — whole into memory at load (as float: 1 mm resolution at 8 km,
/// far below any DEM's accuracy). Its CRS may be geographic or projected: queries in WGS-84
/// latitude/longitude are transformed into it with OGRCoordinateTransformation (traditional
/// GIS axis order, longitude first). **A raster with no CRS is taken to be WGS-84
/// longitude/latitude in degrees** (an .asc without .prj, a bare .hgt). Cells equal to the
/// band's nodata value, or not finite, are voids.
///
/// Interpolation is bilinear between pixel centres (GDAL's geotransform describes cells as
/// areas; the value of a cell is taken at its centre). In the outer half cell, between the
/// last centres and the raster's edge, the edge row/column is used. A point is "outside" when
/// it falls outside the raster's footprint (its cells' extent).
///
/// Copies share the loaded raster. All queries are const and thread-safe; for a raster whose
/// CRS is not WGS-84 longitude/latitude each query takes a mutex around the coordinate
/// transformation (GDAL's transformation objects are not re-entrant).
class Terrain {
 public:
  /// \brief Flat terrain at a constant altitude above the geoid, everywhere.
  /// \throws std::invalid_argument when the altitude is not finite.
  [[nodiscard]] static Terrain flat(double alt_amsl_m = 0.0);

  /// \brief Loads band 1 of the raster at `path`.
  /// \param datum what the raster's heights refer to (SRTM, GeoTIFF DEMs: the geoid).
  /// \throws ParseError naming the file when GDAL cannot read it, it has no geotransform, its
  /// CRS cannot be reached from WGS-84, or it is larger than kMaxRasterCells.
  [[nodiscard]] static Terrain fromRaster(const std::string& path,
                                          HeightDatum datum = HeightDatum::kAmslEgm96);

  /// \brief Largest raster loaded whole: 2^28 cells (1 GiB as float, above a 1° SRTM 1"
  /// tile's 13 M cells by far).
  static constexpr long long kMaxRasterCells = 1LL << 28;

  /// \brief Terrain altitude above the geoid [m]; nullopt outside the raster or when one of
  /// the four cells the interpolation uses is a void.
  /// \throws std::invalid_argument when a coordinate is not finite or |lat| > π/2.
  [[nodiscard]] std::optional<double> altAmsl_m(double lat_rad, double lon_rad) const;

  /// \brief Terrain height above the WGS-84 ellipsoid [m] (through Geoid::egm96() unless the
  /// raster's datum is already the ellipsoid); nullopt as for altAmsl_m.
  /// \throws ParseError when the geoid grid is needed and cannot be loaded.
  [[nodiscard]] std::optional<double> heightEllipsoid_m(double lat_rad, double lon_rad) const;

  /// \brief Smallest and largest terrain altitude above the geoid [m] that altAmsl_m can return
  /// anywhere in the bounding box of a ring of (lat, lon) vertices [rad]: the extremes over
  /// every raster cell the interpolation can use inside the box (conservative — wider than the
  /// polygon itself). The box follows the ring across the antimeridian; a ring that winds
  /// around a pole gets all longitudes and that pole. nullopt when part of the box lies
  /// outside the raster or on a void: the terrain there is unknown. For a raster on the
  /// ellipsoid the geoid's own range over the box is folded in (wider still).
  /// \throws std::invalid_argument when the ring is empty or a vertex is not finite.
  [[nodiscard]] std::optional<std::pair<double, double>> rangeAmsl_m(
      const std::vector<std::pair<double, double>>& ring_lat_lon_rad) const;

  /// \brief The raster's cell size on the ground [m]: the shorter of a cell's two sides at the
  /// raster's centre (geodesic lengths between neighbouring cell centres); nullopt for flat
  /// terrain or when the centre cannot be mapped to WGS-84.
  [[nodiscard]] std::optional<double> cellSize_m() const;

  /// \brief True for the constant-altitude terrain of flat().
  [[nodiscard]] bool isFlat() const { return raster_ == nullptr; }

  /// \brief One line: the source, its driver, size, CRS, WGS-84 bounds and datum.
  [[nodiscard]] std::string describe() const;

  /// \brief What the raster's heights refer to (kAmslEgm96 for flat terrain).
  [[nodiscard]] HeightDatum datum() const { return datum_; }

 private:
  struct Raster;  ///< The loaded raster and its transformation (terrain.cpp).

  Terrain() = default;

  std::shared_ptr<const Raster> raster_;  ///< nullptr: flat.
  double flat_alt_amsl_m_ = 0.0;
  HeightDatum datum_ = HeightDatum::kAmslEgm96;
};

}  // namespace skylane::maps
