#include "geofence/keep_in.hpp"

#include "geofence/zone_heights.hpp"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/multi_polygon.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace skylane::geofence {

namespace {

namespace bg = boost::geometry;
using BgPoint = bg::model::d2::point_xy<double>;
using BgPolygon = bg::model::polygon<BgPoint, false>;  // counter-clockwise, closed
using BgMulti = bg::model::multi_polygon<BgPolygon>;

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Distance from p to the closed segment ab.
double segmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

/// Distance from p to the ring's boundary.
double boundaryDistance(const Eigen::Vector2d& p, const airspace::PlanarRing& ring) {
  double d = kInf;
  for (std::size_t i = 0; i < ring.size(); ++i) d = std::min(d, segmentDistance(p, ring[i], ring[(i + 1) % ring.size()]));
  return d;
}

/// Crossing-number test (a point on the boundary is at distance 0, so its side does not matter).
bool insideRing(const Eigen::Vector2d& p, const airspace::PlanarRing& ring) {
  bool inside = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

BgPolygon toBoost(const airspace::PlanarRing& ring) {
  BgPolygon poly;
  for (const Eigen::Vector2d& v : ring) poly.outer().emplace_back(v.x(), v.y());
  poly.outer().emplace_back(ring.front().x(), ring.front().y());
  bg::correct(poly);
  return poly;
}

airspace::PlanarRing fromBoost(const bg::model::ring<BgPoint, false>& r) {
  airspace::PlanarRing ring;
  for (std::size_t i = 0; i + 1 < r.size(); ++i) ring.emplace_back(r[i].x(), r[i].y());
  return ring;
}

/// Signed distance from p to the boundary of the union of the rings (Boost.Geometry's union for
/// two or more; the union's holes are boundary too).
double signedDistanceToUnion(const Eigen::Vector2d& p, const std::vector<const airspace::PlanarRing*>& rings) {
  if (rings.size() == 1) return signedDistanceToRing(p, *rings.front());
  BgMulti merged;
  for (const airspace::PlanarRing* r : rings) {
    BgMulti next;
    bg::union_(merged, toBoost(*r), next);
    merged = std::move(next);
  }
  double d = kInf;
  bool inside = false;
  for (const BgPolygon& poly : merged) {
    const airspace::PlanarRing outer = fromBoost(poly.outer());
    bool in_this = insideRing(p, outer);
    d = std::min(d, boundaryDistance(p, outer));
    for (const auto& hole : poly.inners()) {
      const airspace::PlanarRing h = fromBoost(hole);
      d = std::min(d, boundaryDistance(p, h));
      if (insideRing(p, h)) in_this = false;
    }
    inside = inside || in_this;
  }
  return inside ? d : -d;
}

/// Room left between [lo, hi] and the volume's band (negative: how far it sticks out).
double bandRoom(const KeepInVolume& k, double lo, double hi) {
  return std::min(k.ceiling_h_ell_m - hi, lo - k.floor_h_ell_m);
}

}  // namespace

double signedDistanceToRing(const Eigen::Vector2d& p, const airspace::PlanarRing& ring) {
  const double d = boundaryDistance(p, ring);
  return insideRing(p, ring) ? d : -d;
}

std::vector<KeepInVolume> keepInVolumes(const std::vector<airspace::Zone>& zones, const maps::PlaneFrame& frame,
                                        const airspace::VerticalModel& model) {
  std::vector<KeepInVolume> out;
  for (std::size_t zi = 0; zi < zones.size(); ++zi) {
    const airspace::Zone& z = zones[zi];
    if (!z.keep_in) continue;
    for (std::size_t vi = 0; vi < z.volumes.size(); ++vi) {
      const airspace::Volume& v = z.volumes[vi];
      const VolumeHeights heights = volumeHeights(z, vi, model);
      KeepInVolume k;
      k.zone = zi;
      k.floor_h_ell_m = heights.floor.h_ell_max_m;  // the zone only shrinks: its floor at its highest
      k.ceiling_h_ell_m = heights.ceiling.h_ell_min_m;
      k.ring = airspace::projectOutline(v.outline, frame, kKeepInCircleError_m, airspace::SafeSide::kContained);
      if (airspace::twiceSignedArea_m2(k.ring) < 0) std::reverse(k.ring.begin(), k.ring.end());
      if (k.ring.size() < 3 || !bg::is_simple(toBoost(k.ring))) {
        throw std::invalid_argument(airspace::describe(z) + ": volume " + std::to_string(vi) +
                                    ": a keep-in outline must be a simple polygon of at least 3 vertices");
      }
      out.push_back(std::move(k));
    }
  }
  return out;
}

KeepInMargins keepInMargins(const ProtectionVolume& volume, const std::vector<const KeepInVolume*>& active) {
  if (active.empty()) throw std::invalid_argument("keep-in margins need at least one active keep-in volume");
  const Eigen::Vector2d p = volume.p_map.head<2>();
  const double lo = volume.p_map.z() - volume.vpl_m;
  const double hi = volume.p_map.z() + volume.vpl_m;
  thread_local std::vector<const KeepInVolume*> holding;  // this thread's scratch
  thread_local std::vector<const airspace::PlanarRing*> rings;
  holding.clear();
  rings.clear();
  for (const KeepInVolume* k : active) {
    if (bandRoom(*k, lo, hi) >= 0) holding.push_back(k);
  }
  const std::vector<const KeepInVolume*>& used = holding.empty() ? active : holding;
  for (const KeepInVolume* k : used) rings.push_back(&k->ring);

  KeepInMargins m;
  m.margin_h_m = signedDistanceToUnion(p, rings) - volume.hpl_m;
  double deepest = -kInf;
  double reached_room = kInf, best_room = -kInf;
  for (std::size_t i = 0; i < used.size(); ++i) {
    const double d = signedDistanceToRing(p, used[i]->ring);
    const double room = bandRoom(*used[i], lo, hi);
    if (d > deepest) {
      deepest = d;
      m.nearest = static_cast<std::size_t>(std::find(active.begin(), active.end(), used[i]) - active.begin());
    }
    if (d > -volume.hpl_m) reached_room = std::min(reached_room, room);
    best_room = std::max(best_room, room);
  }
  // Held: the least room among the bands the disk reaches; not held: the nearest band's shortfall.
  m.margin_v_m = holding.empty() || reached_room == kInf ? best_room : reached_room;
  return m;
}

}  // namespace skylane::geofence
