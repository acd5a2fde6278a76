#include "airspace/zone_geometry.hpp"

#include "maps/plane_frame.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>

#include <vector>

namespace skylane::airspace {
namespace {

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Epick::Point_2;

}  // namespace

Side horizontalSide(const Outline& o, const LatLon& p) {
  if (o.kind == Outline::Kind::kCircle) {
    const double d = maps::geodesicDistance_m(p.lat_rad, p.lon_rad, o.centre.lat_rad, o.centre.lon_rad);
    return d < o.radius_m ? Side::kInside : (d == o.radius_m ? Side::kBoundary : Side::kOutside);
  }
  const maps::PlaneFrame frame(p.lat_rad, p.lon_rad);
  std::vector<Point> pts;
  pts.reserve(o.ring.size());
  for (const LatLon& v : o.ring) {
    const Eigen::Vector2d q = frame.toPlane(v.lat_rad, v.lon_rad);
    pts.emplace_back(q.x(), q.y());
  }
  switch (CGAL::bounded_side_2(pts.begin(), pts.end(), Point(0.0, 0.0), Epick())) {
    case CGAL::ON_BOUNDED_SIDE: return Side::kInside;
    case CGAL::ON_BOUNDARY: return Side::kBoundary;
    case CGAL::ON_UNBOUNDED_SIDE: return Side::kOutside;
  }
  return Side::kOutside;
}

}  // namespace skylane::airspace
