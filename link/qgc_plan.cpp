#include "link/qgc_plan.hpp"

#include "airspace/applicability.hpp"
#include "geofence/fence.hpp"
#include "maps/json_numbers.hpp"
#include "planner/report_formats.hpp"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/multi_polygon.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

namespace skylane::link {
namespace {

using nlohmann::json;
using maps::roundToDeg8;
using maps::roundToMm;

namespace bg = boost::geometry;
using BgPoint = bg::model::d2::point_xy<double>;
using BgPolygon = bg::model::polygon<BgPoint, false>;  // counter-clockwise, closed
using BgMulti = bg::model::multi_polygon<BgPolygon>;

// MAVLink MAV_CMD and MAV_FRAME values (common.xml), QGroundControl's AltitudeMode.
constexpr int kNavWaypoint = 16;
constexpr int kNavLand = 21;
constexpr int kNavTakeoff = 22;
constexpr int kDoChangeSpeed = 178;
constexpr int kFrameGlobalAmsl = 0;      ///< MAV_FRAME_GLOBAL: altitude above mean sea level
constexpr int kFrameMission = 2;         ///< MAV_FRAME_MISSION: an item without a position
constexpr int kQgcAltitudeAbsolute = 2;  ///< QGroundControl AltMode "Absolute" (frame 0)

/// A SimpleItem: one MISSION_ITEM with its seven parameters (null where NaN).
json simpleItem(int command, int jump_id, const std::array<double, 4>& p1to4, double lat_rad, double lon_rad, double alt_amsl_m) {
  json params = json::array();
  for (double p : p1to4) params.push_back(std::isfinite(p) ? json(p) : json(nullptr));
  params.push_back(roundToDeg8(lat_rad));
  params.push_back(roundToDeg8(lon_rad));
  params.push_back(roundToMm(alt_amsl_m));
  return {{"AMSLAltAboveTerrain", nullptr}, {"Altitude", roundToMm(alt_amsl_m)}, {"AltitudeMode", kQgcAltitudeAbsolute},
          {"autoContinue", true}, {"command", command}, {"doJumpId", jump_id}, {"frame", kFrameGlobalAmsl},
          {"params", params}, {"type", "SimpleItem"}};
}

/// The ground's AMSL height under a mission stop (the approver's terrain, ellipsoidal); the geoid
/// undulation is the route point's own h_ell − alt_amsl.
double groundAmsl(const planner::Approver& a, const Eigen::Vector3d& stop, const planner::RoutePoint& near) {
  const std::optional<double> ground_m = a.groundHeight(stop.head<2>());
  if (!ground_m) throw std::logic_error("qgcPlan: a mission stop outside the terrain model");  // placed on it
  return *ground_m - (near.h_ell_m - near.alt_amsl_m);
}

/// A speed to the cm/s: a report's positions (1e-8°, ≈ 1 mm) and ETAs (1 ms) give a short leg's
/// speed to a few mm/s only, and a finer figure would write changes that are rounding.
double roundToCmPerS(double v) { return std::round(v * 100.0) / 100.0; }

/// A DO_CHANGE_SPEED item (no position: frame 2, MAV_FRAME_MISSION): ground speed (param 1 = 1)
/// of `speed_mps` for the legs after it, the throttle unchanged (param 3 = −1).
json changeSpeedItem(int jump_id, double speed_mps) {
  return {{"autoContinue", true}, {"command", kDoChangeSpeed}, {"doJumpId", jump_id}, {"frame", kFrameMission},
          {"params", {1, speed_mps, -1, 0, 0, 0, 0}}, {"type", "SimpleItem"}};
}

/// The ground speed that flies leg i (to route point i) in its approved time: its horizontal
/// length over the time from leaving point i − 1 (its ETA and hover) to point i's ETA. Where the
/// approval timed the leg by its climb instead (height change at climb speed took longer), this
/// is slower than the cruise speed and arrives at the same time. None for a leg without
/// horizontal length or time.
std::optional<double> legSpeed(const std::vector<planner::RoutePoint>& route, std::size_t i) {
  const double length_m = (route[i].xyz - route[i - 1].xyz).head<2>().norm();
  const double time_s = route[i].eta_s - (route[i - 1].eta_s + route[i - 1].hover_s);
  if (!(length_m > 0.0) || !(time_s > 0.0)) return std::nullopt;
  return length_m / time_s;
}

json missionItems(const planner::ApprovedFlight& r, const planner::Approver& a) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<planner::RoutePoint>& route = r.route;
  json items = json::array();
  int id = 0;
  items.push_back(simpleItem(kNavTakeoff, ++id, {0.0, 0.0, 0.0, nan}, route.front().lat_rad, route.front().lon_rad,
                             route.front().alt_amsl_m));
  double speed_mps = std::numeric_limits<double>::quiet_NaN();  // the vehicle's own until the first change
  for (std::size_t i = 1; i < route.size(); ++i) {
    // The approved timing: a speed change before each leg whose speed differs (to the cm/s).
    if (const std::optional<double> v = legSpeed(route, i); v && roundToCmPerS(*v) != speed_mps) {
      speed_mps = roundToCmPerS(*v);
      items.push_back(changeSpeedItem(++id, speed_mps));
    }
    // params[0]: the hold time, the route point's hover (a multirotor stays that long).
    items.push_back(simpleItem(kNavWaypoint, ++id, {route[i].hover_s, r.level1.hal_m, 0.0, nan}, route[i].lat_rad,
                               route[i].lon_rad, route[i].alt_amsl_m));
  }
  const double land_m = groundAmsl(a, a.missionStops().back(), route.back());
  items.push_back(simpleItem(kNavLand, ++id, {0.0, 0.0, 0.0, nan}, route.back().lat_rad, route.back().lon_rad, land_m));
  return items;
}

/// [[lat, lon], …] of a ring given counter-clockwise, written clockwise.
json clockwiseLatLon(std::vector<json> ccw) {
  std::reverse(ccw.begin(), ccw.end());
  return json(std::move(ccw));
}

/// A closed counter-clockwise polygon of a ring given counter-clockwise.
BgPolygon bgPolygon(const std::vector<Eigen::Vector2d>& ring) {
  BgPolygon out;
  for (const Eigen::Vector2d& p : ring) bg::append(out.outer(), BgPoint(p.x(), p.y()));
  bg::correct(out);
  return out;
}

/// The union of the keep-in volumes whose zone is active at some instant of [t0, t1], in the map
/// frame (their rings as the fence checks them); empty when none is.
BgMulti activeKeepIn(const planner::Approver& a, const maps::GpsTime& t0, const maps::GpsTime& t1) {
  BgMulti merged;
  for (const geofence::KeepInVolume& k : a.obstructions().keepInVolumes()) {
    if (!airspace::isActiveDuring(a.obstructions().zones()[k.zone], t0, t1)) continue;
    BgMulti out;
    bg::union_(merged, bgPolygon(k.ring), out);
    merged = std::move(out);
  }
  return merged;
}

/// The level-2 airspace the vehicle may fly in: its outline, cut to the active keep-in zones when
/// there are any — the piece that holds the route's start (the route lies in both, so in one
/// piece; else the largest), with the keep-in zones' holes inside it.
BgPolygon fencedAirspace(const planner::ApprovedFlight& r, const planner::Approver& a) {
  BgPolygon outline = bgPolygon(airspaceOutline(r.route, r.level2.hal_m));
  const BgMulti keep_in = activeKeepIn(a, r.departure, r.departure.plus(r.route.back().eta_s));
  if (keep_in.empty()) return outline;
  BgMulti pieces;
  bg::intersection(outline, keep_in, pieces);
  if (pieces.empty()) return outline;  // not for an approved route (it lies in both); the airspace as it is
  const BgPoint start(r.route.front().xyz.x(), r.route.front().xyz.y());
  for (const BgPolygon& piece : pieces) {
    if (bg::covered_by(start, piece)) return piece;
  }
  return *std::max_element(pieces.begin(), pieces.end(),
                           [](const BgPolygon& x, const BgPolygon& y) { return bg::area(x) < bg::area(y); });
}

/// [[lat, lon], …] of a closed Boost.Geometry ring in the map frame, written clockwise.
template <class Ring>
json clockwiseLatLonOf(const Ring& ring, const maps::PlaneFrame& frame) {
  std::vector<json> ccw;
  for (const BgPoint& p : ring) {
    const Eigen::Vector2d ll = frame.toLatLon(Eigen::Vector2d(p.x(), p.y()));
    ccw.push_back({roundToDeg8(ll.x()), roundToDeg8(ll.y())});
  }
  if (ccw.size() > 1 && ccw.front() == ccw.back()) ccw.pop_back();
  if (bg::area(ring) < 0) std::reverse(ccw.begin(), ccw.end());  // a hole's ring runs clockwise already
  return clockwiseLatLon(std::move(ccw));
}

/// The inclusion polygon (fencedAirspace's outer ring) and, after it, an exclusion polygon for
/// each hole the keep-in zones leave in it.
void addAirspace(const planner::ApprovedFlight& r, const planner::Approver& a, json& polygons) {
  const BgPolygon fenced = fencedAirspace(r, a);
  polygons.push_back({{"inclusion", true}, {"polygon", clockwiseLatLonOf(fenced.outer(), a.frame())}, {"version", 1}});
  for (const auto& hole : fenced.inners()) {
    polygons.push_back({{"inclusion", false}, {"polygon", clockwiseLatLonOf(hole, a.frame())}, {"version", 1}});
  }
}

/// The counted zones active at some instant of the flight, one fence per volume.
void addExclusions(const planner::ApprovedFlight& r, const planner::Approver& a, json& polygons, json& circles) {
  const maps::GpsTime t0 = r.departure, t1 = r.departure.plus(r.route.back().eta_s);
  const geofence::ZonePolicy& policy = a.obstructions().policy();
  for (const airspace::Zone& z : a.obstructions().zones()) {
    if (!geofence::counts(z, policy) || !airspace::isActiveDuring(z, t0, t1)) continue;
    for (const airspace::Volume& v : z.volumes) {
      const airspace::Outline& o = v.outline;
      if (o.kind == airspace::Outline::Kind::kCircle) {
        circles.push_back({{"circle", {{"center", {roundToDeg8(o.centre.lat_rad), roundToDeg8(o.centre.lon_rad)}},
                                       {"radius", roundToMm(o.radius_m)}}},
                           {"inclusion", false},
                           {"version", 1}});
        continue;
      }
      std::vector<json> ring;
      for (const airspace::LatLon& p : o.ring) ring.push_back({roundToDeg8(p.lat_rad), roundToDeg8(p.lon_rad)});
      polygons.push_back({{"inclusion", false}, {"polygon", clockwiseLatLon(std::move(ring))}, {"version", 1}});
    }
  }
}

}  // namespace

std::vector<Eigen::Vector2d> airspaceOutline(const std::vector<planner::RoutePoint>& route, double hal_m) {
  BgMulti merged;
  for (std::size_t i = 1; i < route.size(); ++i) {
    const BgPolygon box = bgPolygon(planner::segmentOutline(route[i - 1].xyz, route[i].xyz, hal_m));
    BgMulti out;
    bg::union_(merged, box, out);
    merged = std::move(out);
  }
  if (merged.empty()) return {};
  // Consecutive boxes overlap around their shared point: the union is one polygon. (A route that
  // loops back on itself encloses a hole, which the outer ring does not exclude.)
  const auto largest = std::max_element(merged.begin(), merged.end(),
                                        [](const BgPolygon& x, const BgPolygon& y) { return bg::area(x) < bg::area(y); });
  std::vector<Eigen::Vector2d> ring;
  for (const BgPoint& p : largest->outer()) ring.emplace_back(p.x(), p.y());
  if (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
  return ring;
}

nlohmann::json qgcPlan(const planner::ApprovalReport& report, const planner::Approver& approver, const PlanVehicle& vehicle) {
  planner::ApprovedFlight flight;
  flight.approved = report.approved;
  flight.departure = report.departure;
  flight.route = report.route;
  flight.level1 = report.limits.level1;
  flight.level2 = report.limits.level2;
  return qgcPlan(flight, approver, vehicle);
}

nlohmann::json qgcPlan(planner::ApprovedFlight report, const planner::Approver& approver, const PlanVehicle& vehicle) {
  if (report.route.size() < 2) throw std::invalid_argument("qgcPlan: the report has no route of two points or more");
  for (planner::RoutePoint& p : report.route) {  // the map frame of the mission (a report file has none)
    const Eigen::Vector2d xy = approver.frame().toPlane(p.lat_rad, p.lon_rad);
    p.xyz = Eigen::Vector3d(xy.x(), xy.y(), p.h_ell_m);
  }
  const planner::Mission& m = approver.mission();
  const double home_m = groundAmsl(approver, approver.missionStops().front(), report.route.front());
  const planner::MissionPoint& start = m.points.front();
  json mission = {{"cruiseSpeed", m.cruise_speed_mps},
                  {"firmwareType", vehicle.firmware_type},
                  {"globalPlanAltitudeMode", kQgcAltitudeAbsolute},
                  {"hoverSpeed", m.cruise_speed_mps},
                  {"items", missionItems(report, approver)},
                  {"plannedHomePosition", {roundToDeg8(start.lat_rad), roundToDeg8(start.lon_rad), roundToMm(home_m)}},
                  {"vehicleType", vehicle.vehicle_type},
                  {"version", 2}};
  json polygons = json::array();
  addAirspace(report, approver, polygons);
  json circles = json::array();
  addExclusions(report, approver, polygons, circles);
  return {{"fileType", "Plan"},
          {"geoFence", {{"circles", circles}, {"polygons", polygons}, {"version", 2}}},
          {"groundStation", "skylane"},
          {"mission", mission},
          {"rallyPoints", {{"points", json::array()}, {"version", 2}}},
          {"version", 1}};
}

}  // namespace skylane::link
