#include "maps/sky_mask.hpp"

#include "maps/geoid.hpp"
#include "maps/grid_rings.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace skylane::maps {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
/// A bin count within this of a whole number is that number (360 / 0.1 in floating point).
constexpr double kWholeBinsTol = 1e-9;
/// Most bins (0.01°).
constexpr int kMaxBins = 36000;
/// An observer this close to a footprint's edge [m] counts as standing on it (inside).
constexpr double kOnBoundary_m = 1e-3;
/// Slack added to every bounding circle used for culling [m]: the grid and the circles live in
/// the index origin's horizontal plane, the exact geometry in the observer's; the two differ
/// by h·D/R (height h, distance D from the origin; 1.6 cm for 100 m at 1 km), added per query
/// on top of this fixed metre.
constexpr double kCullSlack_m = 1.0;
/// Most grid cells an index allocates: kGridCellsPerBuilding per building, at least
/// kMinGridCells, at most kMaxGridCells; a wider spread of buildings gets coarser cells. The
/// budget follows the count, not the spread, so a few buildings far apart (one mistyped
/// longitude puts a mast 150 km off a street block) get a small grid, not one as large as the
/// spread: the grid's memory and a query's walk over it stay O(buildings).
constexpr double kGridCellsPerBuilding = 64.0;
constexpr double kMinGridCells = 4096.0;
constexpr double kMaxGridCells = 4.0e6;
/// An observer at most this far below flat ground [m] stands on it (rounding of AMSL ⇄ h_ell).
constexpr double kOnGround_m = 0.01;

double wrapAzimuth(double az_rad) {
  double a = std::fmod(az_rad, kTwoPi);
  if (a < 0.0) a += kTwoPi;
  return a >= kTwoPi ? 0.0 : a;
}

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Largest elevation of a point dh above the observer at any horizontal distance in
/// [d_near, d_far]: e(d) falls with d when dh > 0; when dh ≤ 0 it rises to its peak at the
/// tangent distance d* = √(2R·|dh|) (where de/dd = 0: |dh|/d² = 1/(2R)) and falls after.
double maxElevation_rad(double dh_m, double d_near_m, double d_far_m, double earth_radius_m) {
  if (dh_m > 0.0) return curvedElevation_rad(dh_m, d_near_m, earth_radius_m);
  const double d_tangent = std::sqrt(2.0 * earth_radius_m * -dh_m);
  const double d = (d_tangent > d_near_m && d_tangent <= d_far_m) ? d_tangent : d_near_m;
  const double e = curvedElevation_rad(dh_m, d, earth_radius_m);
  return std::isfinite(d_far_m) ? std::max(e, curvedElevation_rad(dh_m, d_far_m, earth_radius_m)) : e;
}

/// Does a circle at `c` (observer at the origin, this plane) of radius r, reaching no higher
/// than dh, stay at or below the mask over every bin it spans? (its upper bound: its top at
/// its nearest distance — or its tangent peak — in the widest angular span it can cover)
bool circleHidden(const SkyMask& mask, const Eigen::Vector2d& c, double r, double dh, double earth_radius_m) {
  const double dc = c.norm();
  if (!(dc > r)) return false;  // the observer may be inside: never skip
  const double bound = maxElevation_rad(dh, dc - r, std::numeric_limits<double>::infinity(), earth_radius_m);
  const double half = std::asin(r / dc);
  const double az = std::atan2(c.x(), c.y());
  const double w = mask.binWidth_rad();
  const int n = mask.bins();
  const auto k0 = static_cast<long>(std::floor((az - half) / w));
  const auto k1 = static_cast<long>(std::floor((az + half) / w));
  const std::vector<double>& m = mask.blocked_rad();
  for (long k = k0; k <= k1; ++k) {
    const long b = ((k % n) + n) % n;
    if (m[static_cast<std::size_t>(b)] < bound) return false;
  }
  return true;
}

}  // namespace

// --- SkyMask -------------------------------------------------------------------------------

SkyMask::SkyMask(double bin_width_rad) : width_rad_(bin_width_rad) {
  const double bins = kTwoPi / bin_width_rad;
  const double whole = std::round(bins);
  if (!std::isfinite(bins) || !(whole >= 1.0 && whole <= kMaxBins) || std::abs(bins - whole) > kWholeBinsTol * whole) {
    throw std::invalid_argument("SkyMask: bin width " + std::to_string(rad2deg(bin_width_rad)) +
                                " deg must divide 360 deg into a whole number of bins (1 … 36000)");
  }
  width_rad_ = kTwoPi / whole;
  blocked_rad_.assign(static_cast<std::size_t>(whole), kOpenSky_rad);
}

int SkyMask::binOf(double azimuth_rad) const {
  if (!std::isfinite(azimuth_rad)) throw std::invalid_argument("SkyMask: azimuth is not finite");
  const int k = static_cast<int>(std::floor(wrapAzimuth(azimuth_rad) / width_rad_));
  return std::min(k, bins() - 1);
}

void SkyMask::raise(int k, double elevation_rad) {
  double& b = blocked_rad_.at(static_cast<std::size_t>(k));
  b = std::max(b, elevation_rad);
}

void SkyMask::raise(const SkyMask& other) {
  if (other.bins() != bins()) throw std::invalid_argument("SkyMask::raise: the masks have different bins");
  for (std::size_t k = 0; k < blocked_rad_.size(); ++k) blocked_rad_[k] = std::max(blocked_rad_[k], other.blocked_rad_[k]);
}

double dropRadius_m(double lat_rad, double refraction_k) {
  const double e2 = kWgs84F * (2.0 - kWgs84F);
  const double s = std::sin(lat_rad);
  return refraction_k * kWgs84A_m / std::sqrt(1.0 - e2 * s * s);  // prime vertical N(φ)
}

// --- BuildingIndex ---------------------------------------------------------------------------

namespace {

Geodetic centreOf(const std::vector<Building>& buildings) {
  if (buildings.empty()) return {};
  // Mean of unit vectors on the sphere: fine across the antimeridian.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double h = 0.0;
  for (const Building& b : buildings) {
    const auto& [lat, lon] = b.ring_lat_lon_rad.front();
    sum += Eigen::Vector3d(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
    h += b.base_h_ell_m;
  }
  return {std::atan2(sum.z(), std::hypot(sum.x(), sum.y())), std::atan2(sum.y(), sum.x()),
          h / static_cast<double>(buildings.size())};
}

}  // namespace

BuildingIndex::BuildingIndex(const std::vector<Building>& buildings) : BuildingIndex(buildings, centreOf(buildings)) {}

BuildingIndex::BuildingIndex(const std::vector<Building>& buildings, const Geodetic& origin, double cell_m)
    : frame_(origin), cell_m_(cell_m) {
  if (!(cell_m > 0.0) || !std::isfinite(cell_m)) throw std::invalid_argument("BuildingIndex: cell size must be positive");
  const Eigen::Matrix3d R_o_ecef = rotationEcefToEnu(origin.lat_rad, origin.lon_rad);
  items_.reserve(buildings.size());
  Eigen::Vector2d lo(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const Building& b : buildings) {
    if (b.ring_lat_lon_rad.size() < 3) throw std::logic_error("BuildingIndex: " + b.feature + " has fewer than 3 vertices");
    Item it;
    it.base_h_ell_m = b.base_h_ell_m;
    it.top_h_ell_m = b.top_h_ell_m;
    Eigen::Vector2d blo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), bhi = -blo;
    for (const auto& [lat, lon] : b.ring_lat_lon_rad) {
      const Eigen::Vector3d up_ecef(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
      it.p_foot_o.push_back(frame_.toEnu({lat, lon, 0.0}));
      it.up_o.push_back(R_o_ecef * up_ecef);
      blo = blo.cwiseMin(it.p_foot_o.back().head<2>());
      bhi = bhi.cwiseMax(it.p_foot_o.back().head<2>());
    }
    it.centre_en = 0.5 * (blo + bhi);
    for (const Eigen::Vector3d& p : it.p_foot_o) it.radius_m = std::max(it.radius_m, (p.head<2>() - it.centre_en).norm());
    lo = lo.cwiseMin(it.centre_en - Eigen::Vector2d::Constant(it.radius_m));
    hi = hi.cwiseMax(it.centre_en + Eigen::Vector2d::Constant(it.radius_m));
    max_top_h_ell_m_ = std::max(max_top_h_ell_m_, it.top_h_ell_m);
    items_.push_back(std::move(it));
  }
  if (items_.empty()) return;
  const Eigen::Vector2d span = hi - lo;
  const double max_cells = std::clamp(kGridCellsPerBuilding * static_cast<double>(items_.size()), kMinGridCells, kMaxGridCells);
  if ((span.x() / cell_m_ + 1.0) * (span.y() / cell_m_ + 1.0) > max_cells) {
    // Then (x/c + 1)(y/c + 1) = xy/c² + (x + y)/c + 1 ≤ M + 2M + 1 for M = max_cells.
    cell_m_ = std::sqrt(span.x() * span.y() / max_cells) + std::max(span.x(), span.y()) / max_cells + cell_m_;
  }
  grid_min_en_ = lo;
  cols_ = static_cast<int>(span.x() / cell_m_) + 1;
  rows_ = static_cast<int>(span.y() / cell_m_) + 1;
  cells_.resize(static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_));
  for (std::size_t i = 0; i < items_.size(); ++i) {
    const Item& it = items_[i];
    const auto cellIndex = [&](double v, double v0, int count) {
      return std::clamp(static_cast<int>(std::floor((v - v0) / cell_m_)), 0, count - 1);
    };
    const int c0 = cellIndex(it.centre_en.x() - it.radius_m, lo.x(), cols_), c1 = cellIndex(it.centre_en.x() + it.radius_m, lo.x(), cols_);
    const int r0 = cellIndex(it.centre_en.y() - it.radius_m, lo.y(), rows_), r1 = cellIndex(it.centre_en.y() + it.radius_m, lo.y(), rows_);
    for (int r = r0; r <= r1; ++r) {
      for (int c = c0; c <= c1; ++c) {
        Cell& cell = cells_[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols_) + static_cast<std::size_t>(c)];
        cell.items.push_back(static_cast<std::uint32_t>(i));
        cell.top_h_ell_m = std::max(cell.top_h_ell_m, it.top_h_ell_m);
      }
    }
  }
}

namespace {

/// \brief The observer's horizontal plane seen from the index origin, with the mask's bins:
/// what every building of one query is projected into.
struct ObserverPlane {
  double R = 0.0;      ///< drop radius (refraction included) [m]
  double h_obs = 0.0;  ///< observer's ellipsoidal height [m]
  int n_bins = 0;
  double w = 0.0;                        ///< bin width [rad]
  std::vector<Eigen::Vector2d> edge_dir;  ///< unit vectors (east, north) along the bins' lower edges
  Eigen::Vector3d p_OP_o;                 ///< the observer in the origin's ENU frame
  Eigen::Matrix<double, 2, 3> A;          ///< rows 0, 1 of R_PO = R_P,ecef · R_O,ecefᵀ

  /// \brief A point of the origin's EN plane at the observer's height, in the observer's plane.
  [[nodiscard]] Eigen::Vector2d toObserverPlane(const Eigen::Vector2d& q_en) const {
    return A * (Eigen::Vector3d(q_en.x(), q_en.y(), p_OP_o.z()) - p_OP_o);
  }
};

ObserverPlane observerPlane(const SkyMask& mask, const Geodetic& observer, double refraction_k,
                            const LocalFrame& frame) {
  ObserverPlane o;
  o.R = dropRadius_m(observer.lat_rad, refraction_k);
  o.h_obs = observer.h_ell_m;
  o.n_bins = mask.bins();
  o.w = mask.binWidth_rad();
  o.edge_dir.resize(static_cast<std::size_t>(o.n_bins));
  for (int k = 0; k < o.n_bins; ++k) o.edge_dir[static_cast<std::size_t>(k)] = {std::sin(k * o.w), std::cos(k * o.w)};
  o.p_OP_o = frame.toEnu(observer);
  const Eigen::Matrix3d R_po = rotationEcefToEnu(observer.lat_rad, observer.lon_rad) *
                               rotationEcefToEnu(frame.origin().lat_rad, frame.origin().lon_rad).transpose();
  o.A = R_po.topRows<2>();
  return o;
}

/// \brief Is the observer (the origin of the plane) inside or on the footprint `xy`? Crossing
/// number of a ray towards +east, plus the boundary.
bool observerInside(const std::vector<Eigen::Vector2d>& xy) {
  const std::size_t n = xy.size();
  bool inside = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = xy[i];
    const Eigen::Vector2d& b = xy[(i + 1) % n];
    const Eigen::Vector2d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp(-a.dot(ab) / len2, 0.0, 1.0) : 0.0;
    if ((a + t * ab).norm() <= kOnBoundary_m) return true;
    if ((a.y() > 0.0) != (b.y() > 0.0) && a.x() - a.y() * ab.x() / ab.y() > 0.0) inside = !inside;
  }
  return inside;
}

/// \brief Raises the bins one footprint edge s → e spans: each bin to the elevation of the
/// clipped piece's closest point, the top dh above the observer.
void raiseByEdge(SkyMask& mask, const ObserverPlane& o, Eigen::Vector2d s, Eigen::Vector2d e, double dh) {
  double az_s = wrapAzimuth(std::atan2(s.x(), s.y()));
  double span = std::remainder(std::atan2(e.x(), e.y()) - az_s, kTwoPi);
  if (span < 0.0) {  // walk the edge clockwise (increasing azimuth)
    std::swap(s, e);
    az_s = wrapAzimuth(std::atan2(s.x(), s.y()));
    span = -span;
  }
  const Eigen::Vector2d se = e - s;
  const double len2 = se.squaredNorm();
  const auto k0 = static_cast<long>(std::floor(az_s / o.w));
  const auto k1 = static_cast<long>(std::floor((az_s + span) / o.w));
  for (long k = k0; k <= k1; ++k) {
    const auto bin = static_cast<int>(k % o.n_bins);
    // The part of the edge inside the wedge [k·w, (k+1)·w): t where the bin's edge rays
    // cross the segment (cross(u, s + t·se) = 0), or the segment's own ends.
    const auto tAt = [&](long edge) {
      const Eigen::Vector2d& u = o.edge_dir[static_cast<std::size_t>(edge % o.n_bins)];
      const double den = cross2(u, se);
      return den != 0.0 ? std::clamp(-cross2(u, s) / den, 0.0, 1.0) : 0.0;
    };
    double t0 = k == k0 ? 0.0 : tAt(k);
    double t1 = k == k1 ? 1.0 : tAt(k + 1);
    if (t0 > t1) std::swap(t0, t1);
    const double t_close = len2 > 0.0 ? std::clamp(-s.dot(se) / len2, t0, t1) : t0;
    const double d_near = (s + t_close * se).norm();
    const double d_far = std::max((s + t0 * se).norm(), (s + t1 * se).norm());
    mask.raise(bin, maxElevation_rad(dh, d_near, d_far, o.R));
  }
}

/// \brief Raises `mask` by one building (corners p_foot_o on the ellipsoid, verticals up_o);
/// true when the observer stands inside it below its top, which blocks every bin. `xy` is
/// scratch for the corners in the observer's plane.
bool raiseByBuilding(SkyMask& mask, const ObserverPlane& o, const std::vector<Eigen::Vector3d>& p_foot_o,
                     const std::vector<Eigen::Vector3d>& up_o, double top_h_ell_m, std::vector<Eigen::Vector2d>& xy) {
  const std::size_t n = p_foot_o.size();
  xy.resize(n);
  for (std::size_t i = 0; i < n; ++i) xy[i] = o.A * (p_foot_o[i] + o.h_obs * up_o[i] - o.p_OP_o);
  const double dh = top_h_ell_m - o.h_obs;
  if (observerInside(xy) && dh > 0.0) {
    for (int k = 0; k < o.n_bins; ++k) mask.raise(k, M_PI / 2.0);
    return true;
  }
  for (std::size_t i = 0; i < n; ++i) raiseByEdge(mask, o, xy[i], xy[(i + 1) % n], dh);
  return false;
}

/// \brief Can nothing at least d_ring away, at most dh_max above the observer, rise above
/// `lowest_rad`, the lowest bin of the mask?
bool ringBelowMask(double lowest_rad, double d_ring, double dh_max, double earth_radius_m) {
  if (!(d_ring > 0.0)) return false;
  return maxElevation_rad(dh_max, d_ring, std::numeric_limits<double>::infinity(), earth_radius_m) <= lowest_rad;
}

}  // namespace

void BuildingIndex::raiseMask(SkyMask& mask, const Geodetic& observer, double refraction_k, bool cull) const {
  if (!std::isfinite(observer.lat_rad) || !std::isfinite(observer.lon_rad) || !std::isfinite(observer.h_ell_m) ||
      !(refraction_k > 0.0) || !std::isfinite(refraction_k)) {
    throw std::invalid_argument("BuildingIndex::raiseMask: observer and refraction factor must be finite (k > 0)");
  }
  if (items_.empty()) return;
  const ObserverPlane o = observerPlane(mask, observer, refraction_k, frame_);
  std::vector<Eigen::Vector2d> xy;  // corners at the observer's height, observer's plane
  bool all_blocked = false;
  bool mask_raised = true;  // since its lowest bin was last taken (it may come raised by terrain)
  const auto process = [&](const Item& it) {
    mask_raised = true;
    if (raiseByBuilding(mask, o, it.p_foot_o, it.up_o, it.top_h_ell_m, xy)) all_blocked = true;
  };
  if (!cull) {
    for (const Item& it : items_) {
      process(it);
      if (all_blocked) return;
    }
    return;
  }

  // Rings of cells around the observer's cell, nearest first.
  const double slack = kCullSlack_m + std::abs(o.h_obs) * (o.p_OP_o.head<2>().norm() + cell_m_ * (cols_ + rows_)) / o.R;
  const Eigen::Vector2d g = (o.p_OP_o.head<2>() - grid_min_en_) / cell_m_;
  const int ci = static_cast<int>(std::floor(std::clamp(g.x(), -1e6, 1e6)));
  const int cj = static_cast<int>(std::floor(std::clamp(g.y(), -1e6, 1e6)));
  std::vector<char> seen(items_.size(), 0);
  const double cell_radius = cell_m_ * M_SQRT1_2 + slack;
  const auto visit = [&](int c, int r) {
    const Cell& cell = cells_[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols_) + static_cast<std::size_t>(c)];
    if (cell.items.empty()) return;
    const Eigen::Vector2d centre = grid_min_en_ + cell_m_ * Eigen::Vector2d(c + 0.5, r + 0.5);
    if (circleHidden(mask, o.toObserverPlane(centre), cell_radius, cell.top_h_ell_m - o.h_obs, o.R)) return;
    for (const std::uint32_t i : cell.items) {
      if (seen[i] != 0 || all_blocked) continue;
      seen[i] = 1;
      const Item& it = items_[i];
      if (circleHidden(mask, o.toObserverPlane(it.centre_en), it.radius_m + slack, it.top_h_ell_m - o.h_obs, o.R)) continue;
      process(it);
    }
  };
  // Every cell of a ring is at least (ring − 1) cells away: stop when even the tallest
  // building there stays below the lowest bin. That bin is taken again only after a building
  // was processed, so a long walk over empty cells costs O(1) per ring, not O(bins).
  double lowest_rad = kOpenSky_rad;
  const auto out_of_sight = [&](int ring) {
    if (all_blocked) return true;
    if (mask_raised) lowest_rad = *std::min_element(mask.blocked_rad().begin(), mask.blocked_rad().end());
    mask_raised = false;
    return ringBelowMask(lowest_rad, (ring - 1) * cell_m_ - slack, max_top_h_ell_m_ - o.h_obs, o.R);
  };
  walkGridRings(ci, cj, cols_, rows_, out_of_sight, visit);
}

// --- terrain ---------------------------------------------------------------------------------

void raiseMaskByTerrain(SkyMask& mask, const Geodetic& observer, const Terrain& terrain, const SkyMaskOptions& options) {
  if (!std::isfinite(observer.lat_rad) || !std::isfinite(observer.lon_rad) || !std::isfinite(observer.h_ell_m) ||
      std::abs(observer.lat_rad) > M_PI / 2.0) {
    throw std::invalid_argument("raiseMaskByTerrain: the observer must be finite with |lat| <= 90 deg");
  }
  if (!(options.terrain_max_range_m > 0.0) || !std::isfinite(options.terrain_max_range_m) ||
      !(options.terrain_step_m >= 0.0) || !std::isfinite(options.terrain_step_m) || options.terrain_rays_per_bin < 2 ||
      !(options.refraction_k > 0.0) || !std::isfinite(options.refraction_k)) {
    throw std::invalid_argument("raiseMaskByTerrain: positive range, step >= 0, at least 2 rays per bin, k > 0");
  }
  const double R = dropRadius_m(observer.lat_rad, options.refraction_k);
  const double range = options.terrain_max_range_m;
  if (terrain.isFlat()) {
    const auto ground = terrain.heightEllipsoid_m(observer.lat_rad, observer.lon_rad);
    const double dh = *ground - observer.h_ell_m;  // the geoid's slope over the range is left out (≤ ~1 m in 10 km)
    double e = 0.0;
    if (dh > kOnGround_m) {
      e = M_PI / 2.0;  // below the ground
    } else if (dh < 0.0) {
      e = maxElevation_rad(dh, 0.0, range, R);
    }
    for (int k = 0; k < mask.bins(); ++k) mask.raise(k, e);
    return;
  }
  double step = options.terrain_step_m;
  if (step == 0.0) step = terrain.cellSize_m().value_or(30.0);
  step = std::max(step, range / 1e5);  // at most 1e5 samples per ray
  const LocalFrame at_observer(observer);
  const int per_bin = options.terrain_rays_per_bin - 1;  // distinct rays per bin (the upper edge is the next bin's)
  const int n_rays = mask.bins() * per_bin;
  const double dtheta = mask.binWidth_rad() / per_bin;
  std::vector<double> ray_max(static_cast<std::size_t>(n_rays), kOpenSky_rad);
  for (int a = 0; a < n_rays; ++a) {
    const double theta = a * dtheta;
    const double se = std::sin(theta), ce = std::cos(theta);
    double best = kOpenSky_rad;
    for (double d = step; d <= range + 1e-9; d += step) {
      // The point on the ellipsoid-parallel surface below the ray's foot: down by the drop.
      const Geodetic p = at_observer.fromEnu({d * se, d * ce, -d * d / (2.0 * R)});
      const auto h = terrain.heightEllipsoid_m(p.lat_rad, p.lon_rad);
      if (!h) continue;
      best = std::max(best, curvedElevation_rad(*h - observer.h_ell_m, d, R));
    }
    ray_max[static_cast<std::size_t>(a)] = best;
  }
  for (int k = 0; k < mask.bins(); ++k) {
    for (int j = 0; j <= per_bin; ++j) mask.raise(k, ray_max[static_cast<std::size_t>((k * per_bin + j) % n_rays)]);
  }
}

SkyMask computeSkyMask(const Geodetic& observer, const BuildingIndex* buildings, const Terrain* terrain,
                       const SkyMaskOptions& options) {
  SkyMask mask(options.bin_width_rad);
  if (options.floor_rad > kOpenSky_rad) {
    for (int k = 0; k < mask.bins(); ++k) mask.raise(k, options.floor_rad);
  }
  if (terrain != nullptr) raiseMaskByTerrain(mask, observer, *terrain, options);
  if (buildings != nullptr) buildings->raiseMask(mask, observer, options.refraction_k, options.cull);
  return mask;
}

}  // namespace skylane::maps
