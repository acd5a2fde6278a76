#pragma once
/// \file
/// \brief Sky mask at a point: the elevation angle blocked by buildings and terrain in every
/// azimuth bin, for the integrity prediction to drop satellites behind them (docs/method.md §7.1 step 3).
///
/// **Geometry.** Seen from an observer at ellipsoidal height h_obs, a point at horizontal
/// distance d whose ellipsoidal height is h appears at elevation
///   e(d) = atan2(h − h_obs − d²/(2R), d),
/// where d²/(2R) is the drop of the curved Earth below the observer's horizontal plane: the
/// sagitta R − √(R² − d²) = d²/(2R) + d⁴/(8R³) + …, to first order (0.31 m at 2 km, 7.8 m at
/// 10 km). R is the prime-vertical radius N(φ) at the observer — the largest normal radius of
/// curvature there (1/R_α = cos²α/M + sin²α/N, M ≤ N), so the drop is never overestimated and
/// the mask never underestimated; `refraction_k` > 1 (4/3 for the standard radio atmosphere)
/// scales R up for the bending of low rays. The first-order sagitta is itself below the exact
/// one, again on the safe side.
///
/// **Bins.** Azimuth clockwise from north; bin k covers [k·w, (k+1)·w), w = 2π / bins. A bin's
/// value is the highest elevation of anything that lies in it (buildings: exactly, below).
/// Where nothing blocks a bin it holds kOpenSky_rad.

#include "maps/buildings.hpp"
#include "maps/geodesy.hpp"
#include "maps/terrain.hpp"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <vector>

namespace skylane::maps {

/// \brief The value of a bin that nothing blocks: −90°.
inline constexpr double kOpenSky_rad = -M_PI / 2.0;

/// \brief Blocked elevation per azimuth bin.
class SkyMask {
 public:
  /// \brief An open sky (every bin kOpenSky_rad) with bins of `bin_width_rad`.
  /// \throws std::invalid_argument unless 2π / bin_width is a whole number of bins (to 1e-9)
  /// between 1 and 36 000 (0.01°).
  explicit SkyMask(double bin_width_rad = deg2rad(1.0));

  /// \brief Number of bins.
  [[nodiscard]] int bins() const { return static_cast<int>(blocked_rad_.size()); }
  /// \brief Bin width [rad].
  [[nodiscard]] double binWidth_rad() const { return width_rad_; }
  /// \brief The bin an azimuth falls in (any azimuth; wrapped into [0, 2π)).
  /// \throws std::invalid_argument when the azimuth is not finite.
  [[nodiscard]] int binOf(double azimuth_rad) const;
  /// \brief Blocked elevation [rad] in the bin of `azimuth_rad`.
  [[nodiscard]] double blockedElevation_rad(double azimuth_rad) const { return blocked_rad_[static_cast<std::size_t>(binOf(azimuth_rad))]; }
  /// \brief Blocked elevation [rad] of bin k.
  [[nodiscard]] double binBlocked_rad(int k) const { return blocked_rad_.at(static_cast<std::size_t>(k)); }
  /// \brief All bins, k = 0 … bins() − 1.
  [[nodiscard]] const std::vector<double>& blocked_rad() const { return blocked_rad_; }
  /// \brief True when the line of sight clears the mask: elevation strictly above the blocked
  /// elevation of its bin (a ray grazing a roof edge counts as blocked).
  [[nodiscard]] bool isVisible(const LookAngles& look) const {
    return look.elevation_rad > blockedElevation_rad(look.azimuth_rad);
  }
  /// \brief Raises bin k to at least `elevation_rad`.
  void raise(int k, double elevation_rad);
  /// \brief Raises every bin to the other mask's value (same bins required).
  /// \throws std::invalid_argument when the bin counts differ.
  void raise(const SkyMask& other);

 private:
  double width_rad_;
  std::vector<double> blocked_rad_;
};

/// \brief How to compute a mask.
struct SkyMaskOptions {
  double bin_width_rad = deg2rad(1.0);
  /// Terrain farther than this is not looked at [m] (default 10 km: a 300 m ridge at 10 km
  /// stands 1.7° high; beyond, only mountains matter — raise it in mountains).
  double terrain_max_range_m = 10000.0;
  /// Step along a terrain ray [m]; 0: the raster's cell size (Terrain::cellSize_m).
  double terrain_step_m = 0.0;
  /// Terrain rays per bin: at its two edges and evenly between (≥ 2; 3 = edges and centre).
  int terrain_rays_per_bin = 3;
  double refraction_k = 1.0;  ///< effective Earth radius = k·N (4/3: standard radio refraction)
  bool cull = true;           ///< skip buildings that cannot raise the mask (false: the brute-force reference)
  /// Every bin starts at this elevation [rad] (default: open sky). A receiver ignores
  /// satellites below its elevation mask anyway, so starting there loses nothing and lets the
  /// culling skip every building that cannot reach above it (from high up, most of them).
  double floor_rad = kOpenSky_rad;
};

/// \brief Buildings held for fast sky-mask queries: their corners in the ENU frame of an index
/// origin, and a uniform grid over their footprints.
///
/// Each corner is kept as the point where its vertical line meets the ellipsoid and that
/// line's direction (both in the origin's ENU frame), so that the corner at the observer's own
/// height can be placed exactly in the observer's horizontal plane. Queries are const and
/// thread-safe. Meant for a city-sized area (tens of kilometres) around the origin.
class BuildingIndex {
 public:
  /// \brief Indexes `buildings` in a frame at `origin` with grid cells of `cell_m` metres.
  /// \throws std::invalid_argument when cell_m is not positive and finite.
  explicit BuildingIndex(const std::vector<Building>& buildings, const Geodetic& origin,
                         double cell_m = kDefaultCell_m);
  /// \brief Indexes around the buildings' own centre (the mean of their first corners).
  explicit BuildingIndex(const std::vector<Building>& buildings);

  /// \brief Default grid cell [m]: a few city blocks' worth of buildings per cell.
  static constexpr double kDefaultCell_m = 50.0;

  /// \brief Number of buildings.
  [[nodiscard]] std::size_t size() const { return items_.size(); }
  /// \brief Number of grid cells: at most about 3·max(4096, 64·size()) (coarser cells for a
  /// wider spread), whatever the spread of the buildings.
  [[nodiscard]] std::size_t cells() const { return cells_.size(); }
  /// \brief The frame the index lives in.
  [[nodiscard]] const LocalFrame& frame() const { return frame_; }

  /// \brief Raises `mask` to what the buildings block at `observer` (see the file comment).
  ///
  /// Per building: when the observer stands inside (or on) a footprint below its top, every
  /// bin is blocked (π/2). Otherwise each footprint edge is clipped to each bin's wedge and
  /// the clipped piece's closest point gives the bin's elevation for that building (for a top
  /// above the observer e(d) falls with d; for a top below, the piece's largest e is used, at
  /// the tangent distance √(2R·(h_obs − h)) when the piece reaches it). Exact up to the
  /// floating-point rounding and the plane geometry of the class comment.
  /// With `cull`, grid cells are visited in rings outward from the observer, and a cell or a
  /// building is skipped when an upper bound of its elevation (its top at its nearest distance)
  /// does not exceed the mask over the bins it spans; the result equals the brute force.
  void raiseMask(SkyMask& mask, const Geodetic& observer, double refraction_k = 1.0, bool cull = true) const;

 private:
  struct Item {
    std::vector<Eigen::Vector3d> p_foot_o;  ///< corners on the ellipsoid, origin ENU [m]
    std::vector<Eigen::Vector3d> up_o;      ///< unit vertical at each corner, origin ENU
    Eigen::Vector2d centre_en;              ///< bounding circle of the footprint (EN)
    double radius_m = 0;
    double base_h_ell_m = 0, top_h_ell_m = 0;
  };
  struct Cell {
    std::vector<std::uint32_t> items;
    double top_h_ell_m = -1e300;  ///< highest top among them
  };

  LocalFrame frame_;
  double cell_m_;
  std::vector<Item> items_;
  double max_top_h_ell_m_ = -1e300;
  Eigen::Vector2d grid_min_en_{0, 0};
  int cols_ = 0, rows_ = 0;
  std::vector<Cell> cells_;  ///< row-major, rows_ × cols_
};

/// \brief Raises `mask` to the terrain's horizon seen from `observer` (see SkyMaskOptions).
///
/// Flat terrain: the horizon of the curved Earth, the same in every bin, exact within the range:
/// e = max over d ≤ range of atan2(H − d²/(2R), d), H = ground − h_obs (at the tangent
/// distance √(2R|H|) when that is within range). A raster: rays at `terrain_rays_per_bin`
/// azimuths across each bin (both edges included, so a bin shares its edge rays with its
/// neighbours) are marched from one step out to the range in steps of the raster's cell size,
/// each sample's elevation taken with e(d) above. Sampling, not exact: a peak narrower than the
/// ray spacing (w·d / (rays − 1), 87 m at 10 km for 1° and 3 rays) can slip between rays.
/// Samples outside the raster or on a void are skipped (nothing known blocks there).
void raiseMaskByTerrain(SkyMask& mask, const Geodetic& observer, const Terrain& terrain, const SkyMaskOptions& options);

/// \brief The sky mask at `observer` from buildings and terrain (either may be absent).
[[nodiscard]] SkyMask computeSkyMask(const Geodetic& observer, const BuildingIndex* buildings, const Terrain* terrain,
                                     const SkyMaskOptions& options = {});

/// \brief e(d) = atan2(dh − d²/(2R), d) (file comment): elevation [rad] of a point `dh_m` above
/// the observer (ellipsoidal heights) at horizontal distance d_m, over an Earth of radius R.
[[nodiscard]] inline double curvedElevation_rad(double dh_m, double d_m, double earth_radius_m) {
  return std::atan2(dh_m - d_m * d_m / (2.0 * earth_radius_m), d_m);
}

/// \brief The radius used for the Earth-curvature drop at latitude φ: the prime-vertical
/// radius N = a / √(1 − e² sin² φ) (WGS-84), times the refraction factor k.
[[nodiscard]] double dropRadius_m(double lat_rad, double refraction_k = 1.0);

}  // namespace skylane::maps
