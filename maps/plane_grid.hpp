#pragma once
/// \file
/// \brief PlaneFrame::toPlane for a stream of fixes: the projection interpolated on cells of
/// 0.05° × 0.05° around the origin, each the tensor Chebyshev series of degree 6 through the
/// exact projection at its 7 × 7 Chebyshev nodes (docs/method.md §1.1). It agrees with the exact
/// projection to within 1e-8 m (the geodesic solution itself is good to about 15 nm,
/// GeographicLib's documentation) and costs about 0.1 µs instead of 1.1 µs (BM_ProjectFixGrid
/// and BM_ProjectFixExact). A cell is built on first use (49 exact projections); points more
/// than 2° from the origin or beyond 85° of latitude are projected exactly.

#include "maps/plane_frame.hpp"

#include <Eigen/Core>

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

namespace skylane::maps {

/// \brief A PlaneFrame's forward projection, interpolated on cells built on first use. Safe to
/// use from several threads at once.
class PlaneGrid {
 public:
  explicit PlaneGrid(const PlaneFrame& frame);
  ~PlaneGrid();
  PlaneGrid(const PlaneGrid&) = delete;
  PlaneGrid& operator=(const PlaneGrid&) = delete;

  /// \brief (lat, lon) [rad] → plane (x east, y north) [m], within 1e-8 m of frame.toPlane.
  [[nodiscard]] Eigen::Vector2d toPlane(double lat_rad, double lon_rad) const;
  /// \brief The exact projection this one interpolates.
  [[nodiscard]] const PlaneFrame& frame() const { return frame_; }

  static constexpr int kDegree = 6;
  static constexpr double kCell_deg = 0.05;
  static constexpr int kCellsPerSide = 80;  ///< ±2° around the origin
  static constexpr double kMaxLat_deg = 85.0;

  struct Cell;

 private:
  [[nodiscard]] const Cell* cellAt(int i, int j) const;

  using Slot = std::atomic<const Cell*>;

  PlaneFrame frame_;
  Eigen::Vector2d origin_deg_;
  /// kCellsPerSide² slots, allocated with the first cell (a frame that projects no fix pays
  /// nothing); a slot is set once, when its cell is built.
  mutable std::atomic<Slot*> slots_{nullptr};
  mutable std::unique_ptr<Slot[]> slot_storage_;
  mutable std::mutex build_;
  mutable std::vector<std::unique_ptr<Cell>> built_;
};

}  // namespace skylane::maps
