#include "planner/report_formats.hpp"

#include <cmath>

namespace skylane::planner {

namespace {

double round7(double deg) { return std::round(deg * 1e7) / 1e7; }
double roundMm(double m) { return std::round(m * 1e3) / 1e3; }

nlohmann::json lonLat(const maps::PlaneFrame& frame, const Eigen::Vector2d& xy) {
  const Eigen::Vector2d ll = frame.toLatLon(xy);
  return {round7(maps::rad2deg(ll.y())), round7(maps::rad2deg(ll.x()))};
}

}  // namespace

std::vector<Eigen::Vector2d> segmentOutline(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double hal_m) {
  Eigen::Vector2d d = (b - a).head<2>();
  const double len = d.norm();
  d = len > 1e-9 ? Eigen::Vector2d(d / len) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d n(-d.y(), d.x());
  const Eigen::Vector2d p0 = a.head<2>() - d * hal_m, p1 = b.head<2>() + d * hal_m;
  return {p0 - n * hal_m, p1 - n * hal_m, p1 + n * hal_m, p0 + n * hal_m};
}

nlohmann::json routeGeoJson(const ApprovalReport& report, const Mission& mission, const maps::PlaneFrame& frame) {
  using nlohmann::json;
  json features = json::array();
  json line = json::array();
  for (const RoutePoint& p : report.route) {
    line.push_back({round7(maps::rad2deg(p.lon_rad)), round7(maps::rad2deg(p.lat_rad)), roundMm(p.alt_amsl_m)});
  }
  features.push_back({{"type", "Feature"},
                      {"geometry", {{"type", "LineString"}, {"coordinates", line}}},
                      {"properties",
                       {{"kind", "route"},
                        {"mission", mission.name},
                        {"decision", report.approved ? "approved" : "rejected"},
                        {"departure", maps::formatRfc3339(report.departure)},
                        {"heights", "AMSL (EGM96) metres"}}}});
  for (std::size_t i = 0; i < report.route.size(); ++i) {
    const RoutePoint& p = report.route[i];
    features.push_back(
        {{"type", "Feature"},
         {"geometry", {{"type", "Point"}, {"coordinates", {round7(maps::rad2deg(p.lon_rad)), round7(maps::rad2deg(p.lat_rad)), roundMm(p.alt_amsl_m)}}}},
         {"properties",
          {{"kind", "route_point"}, {"index", i}, {"eta", maps::formatRfc3339(report.departure.plus(p.eta_s), 1)},
           {"h_ell_m", roundMm(p.h_ell_m)}, {"alt_amsl_m", roundMm(p.alt_amsl_m)}}}});
  }
  for (int level : {2, 1}) {
    const geofence::AlertLimits& lim = level == 1 ? report.limits.level1 : report.limits.level2;
    for (std::size_t i = 1; i < report.route.size(); ++i) {
      json ring = json::array();
      for (const Eigen::Vector2d& v : segmentOutline(report.route[i - 1].xyz, report.route[i].xyz, lim.hal_m)) {
        ring.push_back(lonLat(frame, v));
      }
      ring.push_back(ring.front());
      features.push_back({{"type", "Feature"},
                          {"geometry", {{"type", "Polygon"}, {"coordinates", {ring}}}},
                          {"properties",
                           {{"kind", level == 1 ? "corridor" : "airspace"},
                            {"level", level},
                            {"segment", i - 1},
                            {"hal_m", roundMm(lim.hal_m)},
                            {"val_m", roundMm(lim.val_m)},
                            {"h_ell_lower_m", roundMm(std::min(report.route[i - 1].h_ell_m, report.route[i].h_ell_m) - lim.val_m)},
                            {"h_ell_upper_m", roundMm(std::max(report.route[i - 1].h_ell_m, report.route[i].h_ell_m) + lim.val_m)}}}});
    }
  }
  for (const Reason& r : report.reasons) {
    if (!r.lat_rad || !r.lon_rad) continue;
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "Point"}, {"coordinates", {round7(maps::rad2deg(*r.lon_rad)), round7(maps::rad2deg(*r.lat_rad))}}}},
                        {"properties", {{"kind", "reason"}, {"reason", r.kind}, {"subject", r.subject}, {"message", r.message}}}});
  }
  return {{"type", "FeatureCollection"}, {"features", features}};
}

nlohmann::json operationalIntentVolumes(const ApprovalReport& report, const maps::PlaneFrame& frame, int level,
                                        double time_buffer_s) {
  using nlohmann::json;
  const geofence::AlertLimits& lim = level == 1 ? report.limits.level1 : report.limits.level2;
  json volumes = json::array();
  for (std::size_t i = 1; i < report.route.size(); ++i) {
    const RoutePoint& a = report.route[i - 1];
    const RoutePoint& b = report.route[i];
    json vertices = json::array();
    for (const Eigen::Vector2d& v : segmentOutline(a.xyz, b.xyz, lim.hal_m)) {
      const Eigen::Vector2d ll = frame.toLatLon(v);
      vertices.push_back({{"lat", round7(maps::rad2deg(ll.x()))}, {"lng", round7(maps::rad2deg(ll.y()))}});
    }
    const double lower = std::min(a.h_ell_m, b.h_ell_m) - lim.val_m;
    const double upper = std::max(a.h_ell_m, b.h_ell_m) + lim.val_m;
    volumes.push_back(
        {{"volume",
          {{"outline_polygon", {{"vertices", vertices}}},
           {"altitude_lower", {{"value", roundMm(lower)}, {"reference", "W84"}, {"units", "M"}}},
           {"altitude_upper", {{"value", roundMm(upper)}, {"reference", "W84"}, {"units", "M"}}}}},
         {"time_start", {{"value", maps::formatRfc3339(report.departure.plus(a.eta_s - time_buffer_s), 0)}, {"format", "RFC3339"}}},
         {"time_end", {{"value", maps::formatRfc3339(report.departure.plus(b.eta_s + time_buffer_s), 0)}, {"format", "RFC3339"}}}});
  }
  return volumes;
}

}  // namespace skylane::planner
