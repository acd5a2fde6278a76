#include "planner/operational_intent.hpp"

#include "maps/json_node.hpp"
#include "maps/json_numbers.hpp"
#include "planner/report_formats.hpp"

#include <algorithm>

namespace skylane::planner {
namespace {

using nlohmann::json;
const std::string kSource = "operational intent";

json heightJson(double h_m) { return {{"value", maps::roundToMm(h_m)}, {"reference", "W84"}, {"units", "M"}}; }
json timeJson(const maps::GpsTime& t) { return {{"value", maps::formatRfc3339(t, 0)}, {"format", "RFC3339"}}; }

double heightOf(const maps::JsonNode& n) {
  if (n.at("reference").str() != "W84") n.at("reference").fail("\"W84\" (WGS-84 ellipsoidal heights)");
  if (n.at("units").str() != "M") n.at("units").fail("\"M\" (metres)");
  return n.at("value").number();
}

maps::GpsTime timeOf(const maps::JsonNode& n) {
  if (n.at("format").str() != "RFC3339") n.at("format").fail("\"RFC3339\"");
  const auto t = maps::parseRfc3339(n.at("value").str());
  if (!t) n.at("value").fail("an RFC 3339 date-time");
  return *t;
}

Volume4D volumeOf(const maps::JsonNode& n) {
  Volume4D v;
  const maps::JsonNode vol = n.at("volume");
  const maps::JsonNode vertices = vol.at("outline_polygon").at("vertices");
  if (vertices.array().size() < 3) vertices.fail("a polygon of at least 3 vertices");
  for (std::size_t i = 0; i < vertices.j.size(); ++i) {
    const maps::JsonNode p = vertices.item(i);
    const double lat = p.at("lat").number(), lng = p.at("lng").number();
    if (std::abs(lat) > 90.0) p.at("lat").fail("a latitude in [-90, 90] degrees");
    if (std::abs(lng) > 180.0) p.at("lng").fail("a longitude in [-180, 180] degrees");
    v.outline_rad.emplace_back(maps::deg2rad(lat), maps::deg2rad(lng));
  }
  v.altitude_lower_m = heightOf(vol.at("altitude_lower"));
  v.altitude_upper_m = heightOf(vol.at("altitude_upper"));
  if (v.altitude_upper_m < v.altitude_lower_m) vol.at("altitude_upper").fail("an upper altitude not below the lower one");
  v.time_start = timeOf(n.at("time_start"));
  v.time_end = timeOf(n.at("time_end"));
  if (v.time_end - v.time_start < 0.0) n.at("time_end").fail("an end not before the start");
  return v;
}

std::vector<Volume4D> volumesOf(const maps::JsonNode& list) {
  std::vector<Volume4D> out;
  for (std::size_t i = 0; i < list.array().size(); ++i) out.push_back(volumeOf(list.item(i)));
  return out;
}

}  // namespace

void to_json(json& j, const Volume4D& v) {
  json vertices = json::array();
  for (const Eigen::Vector2d& p : v.outline_rad) vertices.push_back({{"lat", maps::roundToDeg8(p.x())}, {"lng", maps::roundToDeg8(p.y())}});
  j = {{"volume",
        {{"outline_polygon", {{"vertices", vertices}}},
         {"altitude_lower", heightJson(v.altitude_lower_m)},
         {"altitude_upper", heightJson(v.altitude_upper_m)}}},
       {"time_start", timeJson(v.time_start)},
       {"time_end", timeJson(v.time_end)}};
}

void from_json(const json& j, Volume4D& v) { v = volumeOf(maps::JsonNode{j, "$", kSource}); }

void to_json(json& j, const OperationalIntent& oi) {
  j = {{"operational_intent", {{"volumes", oi.volumes}, {"state", oi.state}, {"priority", oi.priority}}},
       {"corridor_volumes", oi.corridor_volumes}};
}

void from_json(const json& j, OperationalIntent& oi) {
  const maps::JsonNode root{j, "$", kSource};
  if (!j.is_object()) root.fail("an operational intent object");
  const maps::JsonNode intent = root.at("operational_intent");
  oi.volumes = volumesOf(intent.at("volumes"));
  oi.state = intent.at("state").str();
  oi.priority = static_cast<int>(intent.at("priority").number());
  oi.corridor_volumes = root.has("corridor_volumes") ? volumesOf(root.at("corridor_volumes")) : std::vector<Volume4D>{};
}

std::vector<Volume4D> routeVolumes(const ApprovalReport& report, const maps::PlaneFrame& frame, int level, double time_buffer_s) {
  const geofence::AlertLimits& lim = level == 1 ? report.limits.level1 : report.limits.level2;
  std::vector<Volume4D> out;
  for (std::size_t i = 1; i < report.route.size(); ++i) {
    const RoutePoint& a = report.route[i - 1];
    const RoutePoint& b = report.route[i];
    Volume4D v;
    for (const Eigen::Vector2d& p : segmentOutline(a.xyz, b.xyz, lim.hal_m)) v.outline_rad.push_back(frame.toLatLon(p));
    v.altitude_lower_m = std::min(a.h_ell_m, b.h_ell_m) - lim.val_m;
    v.altitude_upper_m = std::max(a.h_ell_m, b.h_ell_m) + lim.val_m;
    v.time_start = report.departure.plus(a.eta_s - time_buffer_s);
    v.time_end = report.departure.plus(b.eta_s + b.hover_s + time_buffer_s);  // a hover at b is in this volume
    out.push_back(std::move(v));
  }
  return out;
}

OperationalIntent operationalIntent(const ApprovalReport& report, const maps::PlaneFrame& frame) {
  OperationalIntent oi;
  oi.volumes = routeVolumes(report, frame, 2, kIntentTimeBuffer_s);
  oi.corridor_volumes = routeVolumes(report, frame, 1, kIntentTimeBuffer_s);
  return oi;
}

}  // namespace skylane::planner
