#include "maps/plane_frame.hpp"

#include "maps/geodesy.hpp"

#include <GeographicLib/AzimuthalEquidistant.hpp>
#include <GeographicLib/Geodesic.hpp>

#include <cmath>
#include <stdexcept>

namespace skylane::maps {

PlaneFrame::PlaneFrame(double lat_rad, double lon_rad) : lat0_deg_(rad2deg(lat_rad)), lon0_deg_(rad2deg(lon_rad)) {
  if (!std::isfinite(lat_rad) || !std::isfinite(lon_rad) || std::abs(lat0_deg_) > 90.0) {
    throw std::invalid_argument("PlaneFrame: origin must be finite with |lat| <= 90 deg");
  }
}

namespace {

const GeographicLib::AzimuthalEquidistant& projection() {
  static const GeographicLib::AzimuthalEquidistant p(GeographicLib::Geodesic::WGS84());
  return p;
}

}  // namespace

Eigen::Vector2d PlaneFrame::toPlane(double lat_rad, double lon_rad) const {
  return toPlaneDeg(rad2deg(lat_rad), rad2deg(lon_rad));
}

Eigen::Vector2d PlaneFrame::toPlaneDeg(double lat_deg, double lon_deg) const {
  double x = 0, y = 0, azi = 0, rk = 0;
  projection().Forward(lat0_deg_, lon0_deg_, lat_deg, lon_deg, x, y, azi, rk);
  return {x, y};
}

Eigen::Vector2d PlaneFrame::toLatLon(const Eigen::Vector2d& p_xy) const {
  double lat = 0, lon = 0, azi = 0, rk = 0;
  projection().Reverse(lat0_deg_, lon0_deg_, p_xy.x(), p_xy.y(), lat, lon, azi, rk);
  return {deg2rad(lat), deg2rad(lon)};
}

double geodesicDistance_m(double lat1_rad, double lon1_rad, double lat2_rad, double lon2_rad) {
  double s12 = 0;
  GeographicLib::Geodesic::WGS84().Inverse(rad2deg(lat1_rad), rad2deg(lon1_rad), rad2deg(lat2_rad), rad2deg(lon2_rad), s12);
  return s12;
}

}  // namespace skylane::maps
