#pragma once
/// \file
/// \brief The map frame's inverse projection tabulated over a planning box, and the ground
/// height under a map point through it (docs/method.md §7.1, "Ground height in the map frame").
///
/// PlaneFrame::toLatLon solves a geodesic direct problem per call (GeographicLib's azimuthal
/// equidistant projection, Karney 2013): microseconds, called for every planner state to find
/// the ground under it. This grid projects the box's nodes once and interpolates (latitude,
/// longitude) bilinearly between them; the ground's height is then read from the terrain and the
/// geoid at that (latitude, longitude) exactly as before. Interpolating the position rather than
/// the height keeps the DEM's and the geoid's own piecewise-bilinear surfaces (their kinks at
/// their cell edges): the height error is the position error times the ground's slope.
///
/// **Bound.** Tensor-product linear interpolation of a C² function f on cells hx × hy errs by at
/// most hx²/8·max|f_xx| + hy²/8·max|f_yy| (the xy term is reproduced exactly). The grid
/// estimates hx²·max|f_xx| by the largest second difference of its nodes along x (and likewise
/// along y), doubles it for the sampling of the maximum, and states the result in metres on the
/// ground (positionErrorBound_m). The projection's curvature is dominated by the meridians'
/// convergence (∂²φ/∂x² ≈ tan φ / R²): at 50 m spacing the bound is about 0.1 mm at 47° latitude
/// (3·10⁻⁵ m at 16°), so a height differs from the exact path's by at most 0.1 mm × the slope —
/// 10⁻⁸ m on flat ground, where only the geoid (slope ≲ 10⁻⁴) varies.

#include "maps/plane_frame.hpp"
#include "maps/terrain.hpp"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace skylane::maps {

/// \brief (latitude, longitude) at the nodes of a regular grid over a box of the map frame.
class MapGroundGrid {
 public:
  /// \brief Largest node spacing [m]; the spacing grows above it only to keep ≤ kMaxNodes nodes.
  static constexpr double kSpacing_m = 50.0;
  /// \brief Most nodes held (16 bytes each: 8 MB).
  static constexpr int kMaxNodes = 500000;

  /// \brief Projects the nodes of the box [lo_xy, hi_xy] (map frame, metres). A box the grid
  /// cannot serve — one that reaches a pole or folds longitudes (more than 1° between nodes) —
  /// leaves it empty: every query is then exact.
  MapGroundGrid(const PlaneFrame& frame, Terrain terrain, const Eigen::Vector2d& lo_xy, const Eigen::Vector2d& hi_xy);

  /// \brief Whether `p_xy` lies in the tabulated box (queries elsewhere are exact).
  [[nodiscard]] bool covers(const Eigen::Vector2d& p_xy) const;
  /// \brief (lat, lon) [rad] of a map point: interpolated inside the box (within
  /// positionErrorBound_m), PlaneFrame::toLatLon outside.
  [[nodiscard]] Eigen::Vector2d toLatLon(const Eigen::Vector2d& p_xy) const;
  /// \brief Terrain::heightEllipsoid_m at toLatLon(p_xy); none outside the terrain model.
  [[nodiscard]] std::optional<double> heightEllipsoid_m(const Eigen::Vector2d& p_xy) const;
  /// \brief Largest distance on the ground between toLatLon inside the box and the exact
  /// projection [m] (see the file comment); 0 when the grid is empty.
  [[nodiscard]] double positionErrorBound_m() const { return bound_m_; }
  /// \brief Node spacing [m] along x and y; 0 when the grid is empty.
  [[nodiscard]] Eigen::Vector2d spacing_m() const { return step_; }

 private:
  void projectNodes();
  void estimateBound();
  [[nodiscard]] const Eigen::Vector2d& node(int i, int j) const {
    return lat_lon_[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(i)];
  }

  PlaneFrame frame_;
  Terrain terrain_;
  Eigen::Vector2d lo_, hi_, step_ = Eigen::Vector2d::Zero();
  int nx_ = 0, ny_ = 0;                   ///< nodes along x and y
  std::vector<Eigen::Vector2d> lat_lon_;  ///< (lat, lon) [rad] per node, longitudes unwrapped
  double bound_m_ = 0.0;
};

}  // namespace skylane::maps
