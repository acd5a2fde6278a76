#pragma once
/// \file
/// \brief Map-frame points as the GeoJSON and mission coordinates the planner's tests write.

#include "maps/geodesy.hpp"
#include "maps/plane_frame.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace skylane::test {

/// \brief A mission's map frame (azimuthal equidistant round lat0, lon0 degrees) and its points
/// as [lon, lat] degrees.
class MapFrameJson {
 public:
  MapFrameJson(double lat0_deg, double lon0_deg) : frame_(maps::deg2rad(lat0_deg), maps::deg2rad(lon0_deg)) {}
  [[nodiscard]] const maps::PlaneFrame& frame() const { return frame_; }
  /// \brief The map point (x east, y north [m]) as a GeoJSON position, [lon, lat] in degrees.
  [[nodiscard]] nlohmann::json lonLat(const Eigen::Vector2d& xy) const {
    const Eigen::Vector2d ll = frame_.toLatLon(xy);
    return {maps::rad2deg(ll.y()), maps::rad2deg(ll.x())};
  }

 private:
  maps::PlaneFrame frame_;
};

}  // namespace skylane::test
