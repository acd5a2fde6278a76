#include "airspace/vertical.hpp"

#include "maps/geodesy.hpp"
#include "maps/plane_frame.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace skylane::airspace {

std::optional<double> limitHeightEllipsoid_m(const VerticalLimit& l, bool ceiling, const LatLon& p,
                                             const VerticalModel& model) {
  const double inf = std::numeric_limits<double>::infinity();
  if (l.unlimited) return ceiling ? inf : -inf;
  switch (l.reference) {
    case VerticalReference::kWgs84: return l.value_m;
    case VerticalReference::kAmsl: return model.geoid.ellipsoidalFromAmsl_m(p.lat_rad, p.lon_rad, l.value_m);
    case VerticalReference::kAgl: {
      const auto ground = model.terrain.heightEllipsoid_m(p.lat_rad, p.lon_rad);
      if (!ground) return std::nullopt;
      return *ground + l.value_m;
    }
  }
  return std::nullopt;
}

std::optional<HeightRange> limitRange(const VerticalLimit& l, bool ceiling, const Outline& o,
                                      const VerticalModel& model) {
  const double inf = std::numeric_limits<double>::infinity();
  if (l.unlimited) {
    const double h = ceiling ? inf : -inf;
    return HeightRange{h, h, h, h};
  }
  std::vector<std::pair<double, double>> ring;  // (lat, lon) [rad], longitudes continuous
  if (o.kind == Outline::Kind::kCircle) {
    const maps::PlaneFrame frame(o.centre.lat_rad, o.centre.lon_rad);
    for (const auto& [x, y] : {std::pair{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}}) {
      const Eigen::Vector2d p = frame.toLatLon({x * o.radius_m, y * o.radius_m});
      // Keep the square's longitudes next to the centre's (continuous across the antimeridian).
      ring.emplace_back(p.x(), maps::continuousLongitude_rad(p.y(), o.centre.lon_rad));
    }
  } else {
    for (const LatLon& v : o.ring) ring.emplace_back(v.lat_rad, v.lon_rad);
  }
  double lat_min = inf, lat_max = -inf, lon_west = inf, lon_east = -inf;
  for (const auto& [lat, lon] : ring) {
    lat_min = std::min(lat_min, lat);
    lat_max = std::max(lat_max, lat);
    lon_west = std::min(lon_west, lon);
    lon_east = std::max(lon_east, lon);
  }
  const auto [n_min, n_max] = model.geoid.undulationRange_m(lat_min, lat_max, lon_west, lon_east);
  const double v = l.value_m;
  switch (l.reference) {
    case VerticalReference::kWgs84: return HeightRange{v, v, v - n_max, v - n_min};
    case VerticalReference::kAmsl: return HeightRange{v + n_min, v + n_max, v, v};
    case VerticalReference::kAgl: {
      const auto ground = model.terrain.rangeAmsl_m(ring);
      if (!ground) return std::nullopt;
      return HeightRange{v + ground->first + n_min, v + ground->second + n_max, v + ground->first, v + ground->second};
    }
  }
  return std::nullopt;
}

}  // namespace skylane::airspace
