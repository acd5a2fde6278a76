#include "airspace/vertical.hpp"

#include <limits>

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

}  // namespace skylane::airspace
