#include "maps/geodesy.hpp"

#include <GeographicLib/Geocentric.hpp>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace skylane::maps {
namespace {

const GeographicLib::Geocentric& wgs84() { return GeographicLib::Geocentric::WGS84(); }

void requireValid(const Geodetic& p) {
  if (!std::isfinite(p.lat_rad) || !std::isfinite(p.lon_rad) || !std::isfinite(p.h_ell_m) ||
      std::abs(p.lat_rad) > M_PI / 2 + 1e-12) {
    std::ostringstream msg;
    msg << "geodetic position (lat " << rad2deg(p.lat_rad) << " deg, lon " << rad2deg(p.lon_rad)
        << " deg, h " << p.h_ell_m << " m) is not finite or latitude is outside [-90, 90] deg";
    throw std::invalid_argument(msg.str());
  }
}

}  // namespace

Eigen::Vector3d geodeticToEcef(const Geodetic& p) {
  requireValid(p);
  Eigen::Vector3d out;
  wgs84().Forward(rad2deg(p.lat_rad), rad2deg(p.lon_rad), p.h_ell_m, out.x(), out.y(), out.z());
  return out;
}

Geodetic ecefToGeodetic(const Eigen::Vector3d& p_ecef) {
  if (!p_ecef.allFinite()) throw std::invalid_argument("ECEF position is not finite");
  double lat_deg = 0, lon_deg = 0, h = 0;
  wgs84().Reverse(p_ecef.x(), p_ecef.y(), p_ecef.z(), lat_deg, lon_deg, h);
  return {deg2rad(lat_deg), deg2rad(lon_deg), h};
}

Eigen::Matrix3d rotationEcefToEnu(double lat_rad, double lon_rad) {
  const double sl = std::sin(lat_rad), cl = std::cos(lat_rad);
  const double so = std::sin(lon_rad), co = std::cos(lon_rad);
  Eigen::Matrix3d R;
  R << -so, co, 0.0,              // east
      -sl * co, -sl * so, cl,      // north
      cl * co, cl * so, sl;        // up
  return R;
}

LookAngles lookAngles(const Eigen::Vector3d& p_observer_ecef, const Eigen::Vector3d& p_target_ecef) {
  const Geodetic obs = ecefToGeodetic(p_observer_ecef);
  return lookAngles(p_observer_ecef, rotationEcefToEnu(obs.lat_rad, obs.lon_rad), p_target_ecef);
}

LookAngles lookAngles(const Eigen::Vector3d& p_observer_ecef, const Eigen::Matrix3d& r_enu_ecef, const Eigen::Vector3d& p_target_ecef) {
  const Eigen::Vector3d d_enu = r_enu_ecef * (p_target_ecef - p_observer_ecef);
  const double horiz = std::hypot(d_enu.x(), d_enu.y());
  LookAngles out;
  out.azimuth_rad = std::atan2(d_enu.x(), d_enu.y());
  if (out.azimuth_rad < 0) out.azimuth_rad += 2 * M_PI;
  out.elevation_rad = std::atan2(d_enu.z(), horiz);
  return out;
}

Eigen::Vector3d losEnu(const LookAngles& look) {
  const double ce = std::cos(look.elevation_rad);
  return {ce * std::sin(look.azimuth_rad), ce * std::cos(look.azimuth_rad),
          std::sin(look.elevation_rad)};
}

LocalFrame::LocalFrame(const Geodetic& origin)
    : origin_(origin),
      p_origin_ecef_(geodeticToEcef(origin)),
      R_enu_ecef_(rotationEcefToEnu(origin.lat_rad, origin.lon_rad)) {}

Eigen::Vector3d LocalFrame::toEnu(const Geodetic& p) const { return ecefToEnu(geodeticToEcef(p)); }

Geodetic LocalFrame::fromEnu(const Eigen::Vector3d& p_enu) const {
  return ecefToGeodetic(enuToEcef(p_enu));
}

Eigen::Vector3d LocalFrame::ecefToEnu(const Eigen::Vector3d& p_ecef) const {
  return R_enu_ecef_ * (p_ecef - p_origin_ecef_);
}

Eigen::Vector3d LocalFrame::enuToEcef(const Eigen::Vector3d& p_enu) const {
  return p_origin_ecef_ + R_enu_ecef_.transpose() * p_enu;
}

}  // namespace skylane::maps
