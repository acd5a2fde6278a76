#include "airspace/validation.hpp"

#include "maps/geodesy.hpp"
#include "maps/parse_error.hpp"

#include <CGAL/Arr_segment_traits_2.h>
#include <CGAL/Arrangement_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace skylane::airspace {
namespace {

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
using Epeck = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = Epick::Point_2;
using Segment = Epick::Segment_2;

constexpr double kPi = 3.141592653589793;
/// Two vertices closer than this are the same vertex (1e-11 rad ≈ 0.06 mm on the ground):
/// files repeat closing vertices exactly, or after a decimal round trip.
constexpr double kSameVertex_rad = 1e-11;
/// A ring whose longitudes turn by more than this in total goes round a pole (the sum is 0
/// for a ring that does not, ±2π for one that does).
constexpr double kPoleWinding_rad = kPi;

bool same(const LatLon& a, const LatLon& b) {
  return std::abs(a.lat_rad - b.lat_rad) <= kSameVertex_rad && std::abs(maps::wrapLongitudeDelta_rad(a.lon_rad - b.lon_rad)) <= kSameVertex_rad;
}

std::string degrees(const LatLon& p) {
  std::ostringstream s;
  s.precision(7);
  s << "(lat " << maps::rad2deg(p.lat_rad) << ", lon " << maps::rad2deg(p.lon_rad) << ")";
  return s.str();
}

/// Plane coordinates for the predicates: (longitude, latitude) in radians, longitudes already
/// continuous. Simplicity and orientation are invariant under the map to any local plane
/// whose edges stay straight, so the exact predicates can run on these numbers.
std::vector<Point> planePoints(const std::vector<LatLon>& ring) {
  std::vector<Point> pts;
  pts.reserve(ring.size());
  for (const LatLon& p : ring) pts.emplace_back(p.lon_rad, p.lat_rad);
  return pts;
}

/// The first pair of edges that touch or cross other than at their shared vertex:
/// {i, j} with edge k = (k, k+1 mod n); {-1, -1} when the ring is simple.
std::pair<int, int> firstCrossing(const std::vector<Point>& pts) {
  const int n = static_cast<int>(pts.size());
  for (int i = 0; i < n; ++i) {
    const Segment si(pts[i], pts[(i + 1) % n]);
    for (int j = i + 1; j < n; ++j) {
      const Segment sj(pts[j], pts[(j + 1) % n]);
      const bool adjacent_next = j == i + 1;
      const bool adjacent_prev = i == 0 && j == n - 1;
      if (!adjacent_next && !adjacent_prev) {
        if (CGAL::do_intersect(si, sj)) return {i, j};
        continue;
      }
      // Adjacent edges share one vertex; they are bad only when they fold back onto each other.
      const Point& shared = adjacent_next ? pts[j] : pts[i];
      const Point& a = adjacent_next ? pts[i] : pts[(i + 1) % n];
      const Point& b = adjacent_next ? pts[(j + 1) % n] : pts[j];
      if (CGAL::collinear(a, shared, b) && !CGAL::collinear_are_ordered_along_line(a, shared, b)) return {i, j};
    }
  }
  return {-1, -1};
}

/// The outer boundary of the area a self-intersecting ring encloses (every bounded face of its
/// arrangement filled), counter-clockwise; empty when the ring encloses no area.
std::vector<LatLon> outerBoundary(const std::vector<Point>& pts) {
  using Traits = CGAL::Arr_segment_traits_2<Epeck>;
  using Arrangement = CGAL::Arrangement_2<Traits>;
  std::vector<Traits::X_monotone_curve_2> segments;
  const std::size_t n = pts.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Epeck::Point_2 a(pts[i].x(), pts[i].y()), b(pts[(i + 1) % n].x(), pts[(i + 1) % n].y());
    if (a != b) segments.emplace_back(a, b);
  }
  Arrangement arr;
  CGAL::insert(arr, segments.begin(), segments.end());
  std::vector<LatLon> best;
  double best_area = 0.0;
  const auto unbounded = arr.unbounded_face();
  for (auto hole = unbounded->inner_ccbs_begin(); hole != unbounded->inner_ccbs_end(); ++hole) {
    // The unbounded face's inner boundary runs clockwise around the filled region.
    std::vector<LatLon> ring;
    auto e = *hole;
    do {
      const auto& p = e->source()->point();
      ring.push_back({CGAL::to_double(p.y()), CGAL::to_double(p.x())});
    } while (++e != *hole);
    std::reverse(ring.begin(), ring.end());
    std::vector<Point> q = planePoints(ring);
    const double area = CGAL::to_double(CGAL::polygon_area_2(q.begin(), q.end(), Epick()));
    if (area > best_area) {
      best_area = area;
      best = std::move(ring);
    }
  }
  return best;
}

struct Context {
  const Zone& zone;
  std::size_t index;
  int volume;
  ValidationReport& report;

  std::string where(int vertex) const {
    std::string s = describe(zone) + ", volume " + std::to_string(volume);
    if (vertex >= 0) s += ", vertex " + std::to_string(vertex);
    return s;
  }
  void note(const std::string& what, int vertex = -1) const {
    report.issues.push_back({index, volume, vertex, false, false, where(vertex) + ": " + what, what});
  }
  void error(const std::string& what, int vertex = -1, bool repaired = false) const {
    report.issues.push_back({index, volume, vertex, true, repaired, where(vertex) + ": " + what, what});
  }
};

/// Normalises and checks one polygon ring; false when it is unusable.
bool checkRing(Outline& o, const Context& ctx, bool repair, std::vector<std::string>& notes) {
  std::vector<LatLon>& r = o.ring;
  std::vector<int> original(r.size());  // file index of each kept vertex
  for (std::size_t i = 0; i < r.size(); ++i) original[i] = static_cast<int>(i);
  // Continuous longitudes (a ring across the antimeridian runs past ±π).
  bool unwrapped = false;
  for (std::size_t i = 1; i < r.size(); ++i) {
    const double lon = r[i - 1].lon_rad + maps::wrapLongitudeDelta_rad(r[i].lon_rad - r[i - 1].lon_rad);
    if (lon != r[i].lon_rad) unwrapped = true;
    r[i].lon_rad = lon;
  }
  if (unwrapped) notes.push_back(ctx.where(-1) + ": ring crosses the antimeridian (longitudes made continuous)");
  if (r.size() >= 2 && same(r.front(), r.back())) {
    r.pop_back();
    original.pop_back();
  } else if (r.size() >= 3) {
    notes.push_back(ctx.where(-1) + ": ring not closed in the file (closed implicitly)");
  }
  for (std::size_t i = 1; i < r.size();) {
    if (same(r[i], r[i - 1])) {
      notes.push_back(ctx.where(original[i]) + ": repeated vertex removed " + degrees(r[i]));
      r.erase(r.begin() + static_cast<long>(i));
      original.erase(original.begin() + static_cast<long>(i));
    } else {
      ++i;
    }
  }
  while (r.size() >= 2 && same(r.front(), r.back())) {
    r.pop_back();
    original.pop_back();
  }
  if (r.size() < 3) {
    ctx.error("fewer than 3 distinct vertices (" + std::to_string(r.size()) + ")");
    return false;
  }
  // Closing edge back across the antimeridian: a ring round a pole does not close in longitude.
  const double winding = r.back().lon_rad - r.front().lon_rad - maps::wrapLongitudeDelta_rad(r.back().lon_rad - r.front().lon_rad);
  if (std::abs(winding) > kPoleWinding_rad) {
    ctx.error("ring goes round a pole (longitudes wind by 360°): not supported, split the zone");
    return false;
  }
  std::vector<Point> pts = planePoints(r);
  if (!CGAL::is_simple_2(pts.begin(), pts.end(), Epick())) {
    const auto [i, j] = firstCrossing(pts);
    const int vi = i >= 0 ? original[static_cast<std::size_t>(i)] : -1;
    const int vj = j >= 0 ? original[static_cast<std::size_t>(j)] : -1;
    const std::string what = "self-intersecting ring: edge from vertex " + std::to_string(vi) + " " +
                             degrees(r[static_cast<std::size_t>(std::max(i, 0))]) + " crosses the edge from vertex " +
                             std::to_string(vj) + " " + degrees(r[static_cast<std::size_t>(std::max(j, 0))]);
    if (!repair || ctx.zone.keep_in) {
      ctx.error(what + (ctx.zone.keep_in && repair ? " (keep-in zones are not repaired: growing them is unsafe)" : ""), vi);
      return false;
    }
    std::vector<LatLon> fixed = outerBoundary(pts);
    if (fixed.size() < 3) {
      ctx.error(what + " (encloses no area: cannot be repaired)", vi);
      return false;
    }
    ctx.error(what + " — repaired: replaced by the outer boundary of the area it encloses (" +
                  std::to_string(fixed.size()) + " vertices; the zone can only grow)",
              vi, /*repaired=*/true);
    notes.push_back(ctx.where(vi) + ": self-intersecting ring replaced by its outer boundary");
    r = std::move(fixed);
    pts = planePoints(r);
  }
  if (CGAL::orientation_2(pts.begin(), pts.end(), Epick()) == CGAL::CLOCKWISE) {
    std::reverse(r.begin(), r.end());
    notes.push_back(ctx.where(-1) + ": clockwise ring reversed to counter-clockwise");
  }
  return true;
}

}  // namespace

bool ValidationReport::ok() const { return firstError() == nullptr; }

const ZoneIssue* ValidationReport::firstError() const {
  for (const ZoneIssue& i : issues) {
    if (i.error && !i.repaired) return &i;
  }
  return nullptr;
}

ValidationReport validateZones(std::vector<Zone>& zones, bool repair) {
  ValidationReport report;
  for (std::size_t zi = 0; zi < zones.size(); ++zi) {
    Zone& z = zones[zi];
    if (z.volumes.empty()) Context{z, zi, -1, report}.error("no volume");
    for (std::size_t vi = 0; vi < z.volumes.size(); ++vi) {
      Volume& v = z.volumes[vi];
      const Context ctx{z, zi, static_cast<int>(vi), report};
      std::vector<std::string> notes;
      if (v.outline.kind == Outline::Kind::kPolygon) checkRing(v.outline, ctx, repair, notes);
      if (v.outline.kind == Outline::Kind::kCircle && !(v.outline.radius_m > 0.0 && std::isfinite(v.outline.radius_m))) {
        ctx.error("circle radius must be positive");
      }
      if (!v.lower.unlimited && !v.upper.unlimited && v.lower.reference == v.upper.reference) {
        if (v.lower.value_m > v.upper.value_m) {
          ctx.error("floor " + v.lower.as_given + " is above the ceiling " + v.upper.as_given);
        } else if (v.lower.value_m == v.upper.value_m) {
          notes.push_back(ctx.where(-1) + ": floor equals ceiling (" + v.upper.as_given + "): the volume is empty");
        }
      }
      for (std::string& n : notes) {
        report.issues.push_back({zi, static_cast<int>(vi), -1, false, false, n, n.substr(n.rfind(": ") + 2)});
        z.notes.push_back(std::move(n));
      }
    }
  }
  for (const ZoneIssue& i : report.issues) {
    if (i.repaired) zones[i.zone].notes.push_back(i.message);
  }
  return report;
}

std::vector<Zone> loadZones(const std::string& path, ZoneFormat format, bool repair) {
  std::vector<Zone> zones = readZoneFile(path, format);
  const ValidationReport report = validateZones(zones, repair);
  if (const ZoneIssue* e = report.firstError()) {
    const Zone& z = zones[e->zone];
    std::string field = z.feature;
    if (e->volume >= 0) field += ".volume[" + std::to_string(e->volume) + "]";
    if (e->vertex >= 0) field += ".vertex[" + std::to_string(e->vertex) + "]";
    throw maps::ParseError(path, 0, field, e->what,
                           "a valid zone (run 'skylane zones validate --repair' to see what can be fixed)");
  }
  return zones;
}

}  // namespace skylane::airspace
