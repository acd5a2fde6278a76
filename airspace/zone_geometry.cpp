#include "airspace/zone_geometry.hpp"

#include "maps/geodesy.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Partition_traits_2.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/minkowski_sum_2.h>
#include <CGAL/partition_2.h>

#include <cmath>
#include <iterator>
#include <list>
#include <sstream>
#include <stdexcept>
#include <string>

namespace skylane::airspace {
namespace {

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
using Epeck = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = Epick::Point_2;
using ExactPoint = Epeck::Point_2;
using ExactSegment = Epeck::Segment_2;
using ExactFt = Epeck::FT;

constexpr double kPi = 3.141592653589793;
/// Mean Earth radius [m] for the azimuthal equidistant scale bound (IUGG R1).
constexpr double kEarthRadius_m = 6371008.8;

/// Throws std::invalid_argument when `v` is not finite and positive.
void requirePositive(double v, const char* what) {
  if (!(std::isfinite(v) && v > 0.0)) {
    std::ostringstream s;
    s << what << " must be a positive finite number of metres, got " << v;
    throw std::invalid_argument(s.str());
  }
}

void requireBufferArguments(double distance_m, double max_error_m) {
  if (!(std::isfinite(distance_m) && distance_m >= 0.0)) {
    throw std::invalid_argument("buffer distance must be a finite number of metres ≥ 0, got " +
                                std::to_string(distance_m));
  }
  requirePositive(max_error_m, "buffer error");
}

/// A regular N-gon round the origin with its vertices at `r_vertex_m`, vertex k at azimuth
/// −2πk/N (x east, y north): decreasing azimuth, so counter-clockwise.
std::vector<Eigen::Vector2d> regularPolygon(int n, double r_vertex_m) {
  std::vector<Eigen::Vector2d> v;
  v.reserve(n);
  for (int k = 0; k < n; ++k) {
    const double az = -2.0 * kPi * k / n;
    v.emplace_back(r_vertex_m * std::sin(az), r_vertex_m * std::cos(az));
  }
  return v;
}

/// A regular polygon whose inscribed circle has radius `inner_m` and whose vertices lie at
/// most `budget_m` beyond it (distance inner/cos(π/N)), counter-clockwise.
std::vector<Eigen::Vector2d> circumscribedPolygon(double inner_m, double budget_m) {
  const int n = circleVertexCount(inner_m, budget_m, SafeSide::kContain);
  return regularPolygon(n, inner_m / std::cos(kPi / n));
}

CGAL::Polygon_2<Epeck> exactPolygon(const PlanarRing& ring) {
  CGAL::Polygon_2<Epeck> p;
  for (const Eigen::Vector2d& v : ring) p.push_back(ExactPoint(v.x(), v.y()));
  return p;
}

PlanarRing toRing(const CGAL::Polygon_2<Epeck>& p) {
  PlanarRing ring;
  ring.reserve(p.size());
  for (auto it = p.vertices_begin(); it != p.vertices_end(); ++it) {
    ring.emplace_back(CGAL::to_double(it->x()), CGAL::to_double(it->y()));
  }
  return ring;
}

/// Simple and counter-clockwise, or std::invalid_argument naming the problem.
void requireSimpleCcw(const PlanarRing& ring, const char* what) {
  if (ring.size() < 3) {
    throw std::invalid_argument(std::string(what) + ": a ring needs at least 3 vertices, got " +
                                std::to_string(ring.size()));
  }
  std::vector<Point> pts;
  pts.reserve(ring.size());
  for (const Eigen::Vector2d& v : ring) pts.emplace_back(v.x(), v.y());
  if (!CGAL::is_simple_2(pts.begin(), pts.end(), Epick())) {
    throw std::invalid_argument(std::string(what) + ": the ring is not simple (validate zones first)");
  }
  if (CGAL::orientation_2(pts.begin(), pts.end(), Epick()) != CGAL::COUNTERCLOCKWISE) {
    throw std::invalid_argument(std::string(what) + ": the ring must be counter-clockwise");
  }
}

bool exactSegmentMeetsRing(const ExactPoint& a, const ExactPoint& b, const std::vector<ExactPoint>& ring) {
  if (ring.empty()) return false;
  if (CGAL::bounded_side_2(ring.begin(), ring.end(), a, Epeck()) != CGAL::ON_UNBOUNDED_SIDE) return true;
  if (a == b) return false;
  const ExactSegment ab(a, b);
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const ExactPoint& p = ring[i];
    const ExactPoint& q = ring[(i + 1) % n];
    if (p == q ? ab.has_on(p) : CGAL::do_intersect(ab, ExactSegment(p, q))) return true;
  }
  return false;  // a is outside and no edge is met: the whole segment is outside
}

bool exactSegmentMeetsDisk(const ExactPoint& a, const ExactPoint& b, const ExactPoint& c, double radius_m) {
  const ExactFt r2 = ExactFt(radius_m) * ExactFt(radius_m);
  const ExactFt d2 = a == b ? CGAL::squared_distance(a, c) : CGAL::squared_distance(ExactSegment(a, b), c);
  return d2 <= r2;
}

std::vector<ExactPoint> exactRing(const PlanarRing& ring) {
  std::vector<ExactPoint> pts;
  pts.reserve(ring.size());
  for (const Eigen::Vector2d& v : ring) pts.emplace_back(v.x(), v.y());
  return pts;
}

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

SafeSide safeSideOf(const Zone& z) { return z.keep_in ? SafeSide::kContained : SafeSide::kContain; }

int circleVertexCount(double radius_m, double max_error_m, SafeSide side) {
  requirePositive(radius_m, "circle radius");
  requirePositive(max_error_m, "circle approximation error");
  double half_angle_rad = 0.0;  // π/N at the bound
  if (side == SafeSide::kContain) {
    half_angle_rad = std::acos(radius_m / (radius_m + max_error_m));  // r / cos(π/N) ≤ r + e
  } else {
    if (max_error_m >= radius_m) {
      std::ostringstream s;
      s << "an inscribed polygon needs an error below the radius (" << radius_m << " m), got " << max_error_m << " m";
      throw std::invalid_argument(s.str());
    }
    half_angle_rad = std::acos(1.0 - max_error_m / radius_m);  // r (1 − cos(π/N)) ≤ e
  }
  const double n = std::ceil(kPi / half_angle_rad);
  if (!(n <= 1e6)) {
    std::ostringstream s;
    s << "a " << radius_m << " m circle within " << max_error_m << " m needs more than a million vertices";
    throw std::invalid_argument(s.str());
  }
  return std::max(3, static_cast<int>(n));
}

Outline circleToPolygon(const Outline& o, double max_error_m, SafeSide side) {
  if (o.kind != Outline::Kind::kCircle) return o;
  requirePositive(max_error_m, "circle approximation error");
  const double r = o.radius_m, e = max_error_m;
  // Between r + e/4 and r + e (contain) or r − e and r − e/4 (contained): see the header.
  std::vector<Eigen::Vector2d> vertices;
  if (side == SafeSide::kContain) {
    vertices = circumscribedPolygon(r + e / 4.0, 0.75 * e);
  } else {
    if (e >= r) (void)circleVertexCount(r, e, side);  // throws with the message
    vertices = regularPolygon(circleVertexCount(r - e / 4.0, 0.75 * e, SafeSide::kContained), r - e / 4.0);
  }
  const maps::PlaneFrame frame(o.centre.lat_rad, o.centre.lon_rad);
  Outline poly;
  poly.kind = Outline::Kind::kPolygon;
  poly.ring.reserve(vertices.size());
  for (const Eigen::Vector2d& v : vertices) {
    const Eigen::Vector2d ll = frame.toLatLon(v);
    poly.ring.push_back({ll.x(), ll.y()});
  }
  // Keep longitudes continuous with the centre's (a circle on the antimeridian).
  for (LatLon& v : poly.ring) v.lon_rad = maps::continuousLongitude_rad(v.lon_rad, o.centre.lon_rad);
  return poly;
}

PlanarRing projectOutline(const Outline& o, const maps::PlaneFrame& frame, double max_error_m, SafeSide side) {
  const Outline poly = circleToPolygon(o, max_error_m, side);
  PlanarRing ring;
  ring.reserve(poly.ring.size());
  for (const LatLon& v : poly.ring) ring.push_back(frame.toPlane(v.lat_rad, v.lon_rad));
  return ring;
}

double twiceSignedArea_m2(const PlanarRing& ring) {
  double a = 0.0;
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = ring[i];
    const Eigen::Vector2d& q = ring[(i + 1) % n];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return a;
}

namespace {

/// Minkowski sum of a simple CCW ring with a regular polygon of inscribed radius `inner_m`
/// whose vertices lie within `budget_m` beyond it; the sum's outer boundary.
PlanarRing minkowskiBuffer(const PlanarRing& ring, double inner_m, double budget_m) {
  CGAL::Polygon_2<Epeck> disk;
  for (const Eigen::Vector2d& v : circumscribedPolygon(inner_m, budget_m)) disk.push_back(ExactPoint(v.x(), v.y()));
  const CGAL::Polygon_with_holes_2<Epeck> sum = CGAL::minkowski_sum_2(exactPolygon(ring), disk);
  return toRing(sum.outer_boundary());
}

}  // namespace

PlanarRing bufferRing(const PlanarRing& ring, double distance_m, double max_error_m) {
  requireBufferArguments(distance_m, max_error_m);
  requireSimpleCcw(ring, "buffer");
  if (distance_m == 0.0) return ring;
  // Inscribed radius d + e/4, vertices at most d + e: a margin of e/4 beyond the exact buffer.
  return minkowskiBuffer(ring, distance_m + max_error_m / 4.0, 0.75 * max_error_m);
}

Outline bufferOutline(const Outline& o, double distance_m, double max_error_m) {
  if (o.kind == Outline::Kind::kCircle) {
    requireBufferArguments(distance_m, max_error_m);
    Outline c = o;
    c.radius_m += distance_m;
    return c;
  }
  requireBufferArguments(distance_m, max_error_m);
  if (o.ring.size() < 3) throw std::invalid_argument("buffer: a ring needs at least 3 vertices");
  double lat_sum = 0.0, lon_sum = 0.0;
  for (const LatLon& v : o.ring) {
    lat_sum += v.lat_rad;
    lon_sum += v.lon_rad;
  }
  const double n = static_cast<double>(o.ring.size());
  const maps::PlaneFrame frame(lat_sum / n, lon_sum / n);
  PlanarRing ring;
  double rho_max_m = 0.0;
  for (const LatLon& v : o.ring) {
    ring.push_back(frame.toPlane(v.lat_rad, v.lon_rad));
    rho_max_m = std::max(rho_max_m, ring.back().norm());
  }
  requireSimpleCcw(ring, "buffer");
  if (distance_m == 0.0) return o;
  // Distances in the plane are true to a factor 1 + (ρ/R)²/6 (tangential scale of the
  // azimuthal equidistant projection on a sphere); the buffer is grown by twice that.
  const double kappa = 2.0 * (rho_max_m / kEarthRadius_m) * (rho_max_m / kEarthRadius_m) / 6.0;
  const double inner_m = distance_m * (1.0 + kappa) + max_error_m / 4.0;
  const double budget_m = distance_m + max_error_m - inner_m;
  if (!(budget_m > 0.0)) {
    std::ostringstream s;
    s << "buffer error " << max_error_m << " m is below the projection margin for a " << distance_m
      << " m buffer of a zone " << 2 * rho_max_m << " m across";
    throw std::invalid_argument(s.str());
  }
  Outline out;
  out.kind = Outline::Kind::kPolygon;
  for (const Eigen::Vector2d& p : minkowskiBuffer(ring, inner_m, budget_m)) {
    const Eigen::Vector2d ll = frame.toLatLon(p);
    out.ring.push_back({ll.x(), maps::continuousLongitude_rad(ll.y(), lon_sum / n)});
  }
  return out;
}

std::vector<PlanarRing> convexPieces(const PlanarRing& ring) {
  requireSimpleCcw(ring, "convex decomposition");
  using Traits = CGAL::Partition_traits_2<Epick>;
  Traits::Polygon_2 polygon;
  for (const Eigen::Vector2d& v : ring) polygon.push_back(Traits::Point_2(v.x(), v.y()));
  std::list<Traits::Polygon_2> parts;
  CGAL::approx_convex_partition_2(polygon.vertices_begin(), polygon.vertices_end(), std::back_inserter(parts));
  std::vector<PlanarRing> pieces;
  pieces.reserve(parts.size());
  for (const Traits::Polygon_2& part : parts) {
    PlanarRing piece;
    piece.reserve(part.size());
    for (auto it = part.vertices_begin(); it != part.vertices_end(); ++it) piece.emplace_back(it->x(), it->y());
    pieces.push_back(std::move(piece));
  }
  return pieces;
}

bool segmentMeetsRing(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const PlanarRing& ring) {
  return exactSegmentMeetsRing(ExactPoint(a.x(), a.y()), ExactPoint(b.x(), b.y()), exactRing(ring));
}

bool segmentMeetsDisk(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& centre,
                      double radius_m) {
  return exactSegmentMeetsDisk(ExactPoint(a.x(), a.y()), ExactPoint(b.x(), b.y()), ExactPoint(centre.x(), centre.y()),
                               radius_m);
}

bool segmentMeetsPrism(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const PlanarPrism& prism) {
  if (!a.allFinite() || !b.allFinite()) throw std::invalid_argument("segmentMeetsPrism: non-finite endpoint");
  // Clip t ∈ [0, 1] to floor ≤ h(t) ≤ ceiling with h(t) = h_a + t (h_b − h_a), exactly.
  ExactFt t_lo(0), t_hi(1);
  const ExactFt ha(a.z()), dh = ExactFt(b.z()) - ExactFt(a.z());
  const auto clip = [&](double limit_m, bool is_floor) {
    if (!std::isfinite(limit_m)) {
      // −∞ floor or +∞ ceiling: no constraint; +∞ floor or −∞ ceiling: nothing is inside.
      if ((is_floor && limit_m > 0) || (!is_floor && limit_m < 0)) t_hi = ExactFt(-1);
      return;
    }
    const ExactFt lim(limit_m);
    if (dh == 0) {
      if (is_floor ? ha < lim : ha > lim) t_hi = ExactFt(-1);
      return;
    }
    const ExactFt t = (lim - ha) / dh;
    // floor: h(t) ≥ lim ⇔ t ≥ t* when rising, t ≤ t* when falling; the ceiling the other way.
    if (is_floor == (dh > 0)) {
      if (t > t_lo) t_lo = t;
    } else if (t < t_hi) {
      t_hi = t;
    }
  };
  clip(prism.floor_h_ell_m, true);
  clip(prism.ceiling_h_ell_m, false);
  if (t_lo > t_hi) return false;
  const ExactPoint pa(a.x(), a.y()), pb(b.x(), b.y());
  const auto at = [&](const ExactFt& t) { return pa + (pb - pa) * t; };
  const ExactPoint p = at(t_lo), q = at(t_hi);
  if (prism.ring.empty()) return exactSegmentMeetsDisk(p, q, ExactPoint(prism.centre.x(), prism.centre.y()), prism.radius_m);
  return exactSegmentMeetsRing(p, q, exactRing(prism.ring));
}

bool cylinderMeetsPrism(const Eigen::Vector3d& centre, double radius_m, double half_height_m,
                        const PlanarPrism& prism) {
  if (!centre.allFinite()) throw std::invalid_argument("cylinderMeetsPrism: non-finite centre");
  if (!(std::isfinite(radius_m) && radius_m >= 0 && std::isfinite(half_height_m) && half_height_m >= 0)) {
    std::ostringstream s;
    s << "cylinderMeetsPrism: radius and half-height must be finite and ≥ 0, got " << radius_m << " m, "
      << half_height_m << " m";
    throw std::invalid_argument(s.str());
  }
  // Heights: [z − hh, z + hh] meets [floor, ceiling] ⇔ z − hh ≤ ceiling and z + hh ≥ floor
  // (an infinite limit constrains nothing on its own side, everything on the other).
  const ExactFt z(centre.z()), hh(half_height_m);
  const auto above = [&](double ceiling_m) {
    return std::isfinite(ceiling_m) ? z - hh > ExactFt(ceiling_m) : ceiling_m < 0;
  };
  const auto below = [&](double floor_m) { return std::isfinite(floor_m) ? z + hh < ExactFt(floor_m) : floor_m > 0; };
  if (above(prism.ceiling_h_ell_m) || below(prism.floor_h_ell_m)) return false;
  const ExactPoint c(centre.x(), centre.y());
  const ExactFt r(radius_m);
  if (prism.ring.empty()) {
    const ExactFt reach = r + ExactFt(prism.radius_m);
    return CGAL::squared_distance(c, ExactPoint(prism.centre.x(), prism.centre.y())) <= reach * reach;
  }
  const std::vector<ExactPoint> ring = exactRing(prism.ring);
  if (CGAL::bounded_side_2(ring.begin(), ring.end(), c, Epeck()) != CGAL::ON_UNBOUNDED_SIDE) return true;
  const ExactFt r2 = r * r;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const ExactPoint& p = ring[i];
    const ExactPoint& q = ring[(i + 1) % ring.size()];
    const ExactFt d2 = p == q ? CGAL::squared_distance(p, c) : CGAL::squared_distance(ExactSegment(p, q), c);
    if (d2 <= r2) return true;
  }
  return false;
}

}  // namespace skylane::airspace
