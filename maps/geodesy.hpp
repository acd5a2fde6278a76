#pragma once
/// \file
/// \brief WGS-84 geodetic ⇄ ECEF ⇄ local ENU conversions and look angles.
///
/// Thin, typed wrappers over GeographicLib (C. F. F. Karney, "Transverse Mercator with an
/// accuracy of a few nanometers", J. Geodesy 85, 2011; Geocentric / LocalCartesian classes).
/// Angles are radians inside skylane; heights are ellipsoidal (WGS-84) here.

#include <Eigen/Core>

#include <cmath>

namespace skylane::maps {

/// \brief WGS-84 semi-major axis [m] (NIMA TR8350.2).
inline constexpr double kWgs84A_m = 6378137.0;
/// \brief WGS-84 flattening.
inline constexpr double kWgs84F = 1.0 / 298.257223563;

/// \brief A geodetic position: latitude and longitude in radians, ellipsoidal height in metres.
struct Geodetic {
  double lat_rad = 0.0;
  double lon_rad = 0.0;
  double h_ell_m = 0.0;
};

/// \brief Azimuth (clockwise from north) and elevation of a line of sight, radians.
struct LookAngles {
  double azimuth_rad = 0.0;
  double elevation_rad = 0.0;
};

/// \brief Geodetic → ECEF (WGS-84).
/// \throws std::invalid_argument when a coordinate is not finite or latitude is outside ±π/2.
[[nodiscard]] Eigen::Vector3d geodeticToEcef(const Geodetic& p);

/// \brief ECEF → geodetic (WGS-84), exact to GeographicLib's precision (nanometres).
[[nodiscard]] Geodetic ecefToGeodetic(const Eigen::Vector3d& p_ecef);

/// \brief Rotation R_EnuEcef: maps an ECEF vector to east, north, up at the given place.
[[nodiscard]] Eigen::Matrix3d rotationEcefToEnu(double lat_rad, double lon_rad);

/// \brief Azimuth and elevation of the target seen from the observer (both ECEF).
[[nodiscard]] LookAngles lookAngles(const Eigen::Vector3d& p_observer_ecef,
                                    const Eigen::Vector3d& p_target_ecef);
/// \brief The same, with the observer's rotation R_EnuEcef (rotationEcefToEnu of its geodetic
/// position) computed once for many targets: no geodetic conversion per target, the same result.
[[nodiscard]] LookAngles lookAngles(const Eigen::Vector3d& p_observer_ecef, const Eigen::Matrix3d& r_enu_ecef,
                                    const Eigen::Vector3d& p_target_ecef);

/// \brief Unit line-of-sight vector (east, north, up) for azimuth/elevation.
[[nodiscard]] Eigen::Vector3d losEnu(const LookAngles& look);

/// \brief A local east-north-up frame anchored at an origin (the mission origin).
class LocalFrame {
 public:
  /// \brief Anchors the frame at the given origin.
  explicit LocalFrame(const Geodetic& origin);

  /// \brief The frame's origin.
  [[nodiscard]] const Geodetic& origin() const { return origin_; }
  /// \brief Geodetic → ENU coordinates [m] of the point in this frame.
  [[nodiscard]] Eigen::Vector3d toEnu(const Geodetic& p) const;
  /// \brief ENU [m] → geodetic.
  [[nodiscard]] Geodetic fromEnu(const Eigen::Vector3d& p_enu) const;
  /// \brief ECEF → ENU [m].
  [[nodiscard]] Eigen::Vector3d ecefToEnu(const Eigen::Vector3d& p_ecef) const;
  /// \brief ENU [m] → ECEF.
  [[nodiscard]] Eigen::Vector3d enuToEcef(const Eigen::Vector3d& p_enu) const;

 private:
  Geodetic origin_;
  Eigen::Vector3d p_origin_ecef_;
  Eigen::Matrix3d R_enu_ecef_;
};

/// \brief A longitude difference wrapped into [−π, π] [rad].
[[nodiscard]] inline double wrapLongitudeDelta_rad(double d_rad) { return std::remainder(d_rad, 2.0 * M_PI); }

/// \brief `lon_rad` moved by whole turns to lie within π of `ref_rad`: rings and circles across
/// the antimeridian keep continuous longitudes.
[[nodiscard]] inline double continuousLongitude_rad(double lon_rad, double ref_rad) {
  return ref_rad + wrapLongitudeDelta_rad(lon_rad - ref_rad);
}

/// \brief Degrees → radians.
[[nodiscard]] constexpr double deg2rad(double deg) { return deg * 0.017453292519943295; }
/// \brief Radians → degrees.
[[nodiscard]] constexpr double rad2deg(double rad) { return rad * 57.29577951308232; }

}  // namespace skylane::maps
