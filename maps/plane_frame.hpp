#pragma once
/// \file
/// \brief A local horizontal plane: the azimuthal equidistant projection centred at an origin
/// (GeographicLib::AzimuthalEquidistant, exact geodesic distance and azimuth from the origin).
/// Zones are tested against a point in the plane centred at that point, where the point's
/// distance to every vertex is exact and edges are straight to well under a millimetre for
/// zone-sized polygons.

#include <Eigen/Core>

namespace skylane::maps {

/// \brief Azimuthal equidistant plane (x east, y north, metres) centred at an origin.
class PlaneFrame {
 public:
  /// \brief Centres the plane at (lat, lon) [rad].
  PlaneFrame(double lat_rad, double lon_rad);
  /// \brief (lat, lon) [rad] → plane (x east, y north) [m].
  [[nodiscard]] Eigen::Vector2d toPlane(double lat_rad, double lon_rad) const;
  /// \brief The same from (lat, lon) [deg].
  [[nodiscard]] Eigen::Vector2d toPlaneDeg(double lat_deg, double lon_deg) const;
  /// \brief Plane [m] → (lat, lon) [rad].
  [[nodiscard]] Eigen::Vector2d toLatLon(const Eigen::Vector2d& p_xy) const;
  /// \brief The origin (lat, lon) [deg].
  [[nodiscard]] Eigen::Vector2d origin_deg() const { return {lat0_deg_, lon0_deg_}; }

 private:
  double lat0_deg_, lon0_deg_;
};

/// \brief Geodesic distance on the WGS-84 ellipsoid [m] (Karney 2013).
[[nodiscard]] double geodesicDistance_m(double lat1_rad, double lon1_rad, double lat2_rad, double lon2_rad);

}  // namespace skylane::maps
