#include "maps/map_ground_grid.hpp"


#include <algorithm>
#include <cmath>
#include <utility>

namespace skylane::maps {
namespace {

/// Largest radius of curvature of the WGS-84 ellipsoid, a²/b (at the poles) [m]: metres per
/// radian of latitude (and of longitude over cos φ) are at most this.
constexpr double kMaxCurvatureRadius_m = 6399593.6258;
/// Longitudes of neighbouring nodes further apart than this fold (a pole or the box too big).
constexpr double kMaxNodeLonStep_rad = M_PI / 180.0;
/// Nodes this close to a pole are not tabulated (the longitudes there turn fast).
constexpr double kMaxAbsLat_rad = 89.0 * M_PI / 180.0;

/// Nodes along one side of `length_m` at `step_m` at most, and at least 3 (second differences).
int nodesAlong(double length_m, double step_m) { return std::max(3, static_cast<int>(std::ceil(length_m / step_m)) + 1); }

}  // namespace

MapGroundGrid::MapGroundGrid(const PlaneFrame& frame, Terrain terrain, const Eigen::Vector2d& lo_xy,
                             const Eigen::Vector2d& hi_xy)
    : frame_(frame), terrain_(std::move(terrain)), lo_(lo_xy), hi_(hi_xy) {
  const Eigen::Vector2d size = hi_ - lo_;
  if (!(size.x() > 0.0 && size.y() > 0.0 && size.allFinite())) return;  // nothing to tabulate: exact
  double spacing = kSpacing_m;
  const double area_nodes = (size.x() / spacing + 1.0) * (size.y() / spacing + 1.0);
  if (area_nodes > kMaxNodes) spacing *= std::sqrt(area_nodes / kMaxNodes);
  nx_ = nodesAlong(size.x(), spacing);
  ny_ = nodesAlong(size.y(), spacing);
  step_ = Eigen::Vector2d(size.x() / (nx_ - 1), size.y() / (ny_ - 1));
  projectNodes();
  if (!lat_lon_.empty()) estimateBound();
}

void MapGroundGrid::projectNodes() {
  lat_lon_.resize(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_));
  const double lon_ref = frame_.toLatLon(lo_).y();
  bool usable = true;
  for (int j = 0; j < ny_ && usable; ++j) {
    for (int i = 0; i < nx_; ++i) {
      Eigen::Vector2d ll = frame_.toLatLon(Eigen::Vector2d(lo_.x() + i * step_.x(), lo_.y() + j * step_.y()));
      ll.y() = lon_ref + std::remainder(ll.y() - lon_ref, 2.0 * M_PI);  // continuous across the antimeridian
      lat_lon_[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(i)] = ll;
      const bool folds = (i > 0 && std::abs(ll.y() - node(i - 1, j).y()) > kMaxNodeLonStep_rad) ||
                         (j > 0 && std::abs(ll.y() - node(i, j - 1).y()) > kMaxNodeLonStep_rad);
      if (std::abs(ll.x()) > kMaxAbsLat_rad || folds) usable = false;
    }
  }
  if (usable) return;
  lat_lon_.clear();  // exact queries everywhere
  nx_ = ny_ = 0;
  step_.setZero();
}

void MapGroundGrid::estimateBound() {
  // Largest second differences of latitude and longitude along x and along y, each in metres.
  double lat_abs_max = 0.0;
  for (const Eigen::Vector2d& ll : lat_lon_) lat_abs_max = std::max(lat_abs_max, std::abs(ll.x()));
  const Eigen::Vector2d to_m(kMaxCurvatureRadius_m, kMaxCurvatureRadius_m * std::cos(lat_abs_max));
  double e_x = 0.0, e_y = 0.0;
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      if (i > 0 && i + 1 < nx_) {
        const Eigen::Vector2d d2 = node(i + 1, j) - 2.0 * node(i, j) + node(i - 1, j);
        e_x = std::max(e_x, d2.cwiseAbs().dot(to_m));
      }
      if (j > 0 && j + 1 < ny_) {
        const Eigen::Vector2d d2 = node(i, j + 1) - 2.0 * node(i, j) + node(i, j - 1);
        e_y = std::max(e_y, d2.cwiseAbs().dot(to_m));
      }
    }
  }
  // hx²/8·max|f_xx| + hy²/8·max|f_yy|, each maximum doubled for being read off the nodes.
  bound_m_ = 2.0 * (e_x + e_y) / 8.0;
}

bool MapGroundGrid::covers(const Eigen::Vector2d& p_xy) const {
  return !lat_lon_.empty() && p_xy.x() >= lo_.x() && p_xy.x() <= hi_.x() && p_xy.y() >= lo_.y() && p_xy.y() <= hi_.y();
}

Eigen::Vector2d MapGroundGrid::toLatLon(const Eigen::Vector2d& p_xy) const {
  if (!covers(p_xy)) return frame_.toLatLon(p_xy);
  const double u = (p_xy.x() - lo_.x()) / step_.x(), v = (p_xy.y() - lo_.y()) / step_.y();
  const int i = std::min(static_cast<int>(u), nx_ - 2), j = std::min(static_cast<int>(v), ny_ - 2);
  const double fx = u - i, fy = v - j;
  const Eigen::Vector2d bottom = (1.0 - fx) * node(i, j) + fx * node(i + 1, j);
  const Eigen::Vector2d top = (1.0 - fx) * node(i, j + 1) + fx * node(i + 1, j + 1);
  Eigen::Vector2d ll = (1.0 - fy) * bottom + fy * top;
  if (ll.y() > M_PI) ll.y() -= 2.0 * M_PI;  // back into [-π, π] as PlaneFrame gives it
  if (ll.y() < -M_PI) ll.y() += 2.0 * M_PI;
  return ll;
}

std::optional<double> MapGroundGrid::heightEllipsoid_m(const Eigen::Vector2d& p_xy) const {
  const Eigen::Vector2d ll = toLatLon(p_xy);
  return terrain_.heightEllipsoid_m(ll.x(), ll.y());
}

}  // namespace skylane::maps
