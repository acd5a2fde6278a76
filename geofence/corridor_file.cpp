#include "geofence/corridor_file.hpp"

#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <cmath>
#include <stdexcept>

namespace skylane::geofence {
namespace {

using maps::JsonNode;
using maps::ParseError;

double latitude(const JsonNode& n) {
  const double v = n.number();
  if (std::abs(v) > 90.0) n.fail("a latitude in [-90, 90] degrees");
  return maps::deg2rad(v);
}

double longitude(const JsonNode& n) {
  const double v = n.number();
  if (std::abs(v) > 180.0) n.fail("a longitude in [-180, 180] degrees");
  return maps::deg2rad(v);
}

/// Vehicle sizes: any UAS is smaller than this (the largest span about 80 m); a size of 1e308
/// made the alert limits k × size infinite.
constexpr double kMaxVehicleSize_m = 1000.0;
/// k1, k2 with override_ranges (their ranges are 1.1–1.3 and 100–1000).
constexpr double kMaxBoxFactor = 1e4;
/// Heights of the path and the operating limits: below the Dead Sea shore to 100 km.
constexpr double kMinHeight_m = -1000.0, kMaxHeight_m = 100e3;

double positive(const JsonNode& n) { return n.positiveUpTo(kMaxVehicleSize_m, "m"); }

Dimension dimension(const JsonNode& n) {
  const std::string s = n.str();
  if (s == "lateral") return Dimension::kLateral;
  if (s == "longitudinal") return Dimension::kLongitudinal;
  if (s == "height") return Dimension::kHeight;
  n.fail("\"lateral\", \"longitudinal\" or \"height\"");
}

}  // namespace

CorridorSpec parseCorridorSpec(const nlohmann::json& doc, const std::string& source) {
  const JsonNode root{doc, "$", source};
  root.requireKnownFields({"path", "origin", "vehicle", "k1", "k2", "override_ranges", "alert_mapping",
                            "operating_limits", "authorisations"});
  CorridorSpec spec;
  spec.source = source;
  const JsonNode path = root.at("path");
  if (path.array().size() < 2) path.fail("an array of at least 2 waypoints");
  for (std::size_t i = 0; i < path.j.size(); ++i) {
    const JsonNode w = path.item(i);
    w.requireKnownFields({"lat", "lon", "h_ell_m"});
    spec.path.push_back({latitude(w.at("lat")), longitude(w.at("lon")), w.at("h_ell_m").numberIn(kMinHeight_m, kMaxHeight_m, "m")});
  }
  spec.origin = spec.path.front();
  if (root.has("origin")) {
    const JsonNode o = root.at("origin");
    o.requireKnownFields({"lat", "lon"});
    spec.origin = {latitude(o.at("lat")), longitude(o.at("lon")), 0.0};
  }
  const JsonNode v = root.at("vehicle");
  v.requireKnownFields({"lateral_m", "longitudinal_m", "height_m"});
  spec.vehicle.lateral_m = positive(v.at("lateral_m"));
  spec.vehicle.longitudinal_m = positive(v.at("longitudinal_m"));
  if (v.has("height_m")) spec.vehicle.height_m = positive(v.at("height_m"));
  if (root.has("k1")) spec.levels.k1 = root.at("k1").positiveUpTo(kMaxBoxFactor, "(a factor)");
  if (root.has("k2")) spec.levels.k2 = root.at("k2").positiveUpTo(kMaxBoxFactor, "(a factor)");
  if (root.has("override_ranges")) spec.levels.override_ranges = root.at("override_ranges").boolean();
  if (root.has("alert_mapping")) {
    const JsonNode m = root.at("alert_mapping");
    m.requireKnownFields({"horizontal", "vertical"});
    if (m.has("horizontal")) spec.levels.mapping.horizontal = dimension(m.at("horizontal"));
    if (m.has("vertical")) spec.levels.mapping.vertical = dimension(m.at("vertical"));
  }
  if (root.has("operating_limits")) {
    const JsonNode o = root.at("operating_limits");
    o.requireKnownFields({"floor_h_ell_m", "ceiling_h_ell_m"});
    if (o.has("floor_h_ell_m")) spec.operating.floor_h_ell_m = o.at("floor_h_ell_m").numberIn(kMinHeight_m, kMaxHeight_m, "m");
    if (o.has("ceiling_h_ell_m")) spec.operating.ceiling_h_ell_m = o.at("ceiling_h_ell_m").numberIn(kMinHeight_m, kMaxHeight_m, "m");
    if (!(spec.operating.floor_h_ell_m < spec.operating.ceiling_h_ell_m)) {
      o.fail("floor_h_ell_m below ceiling_h_ell_m");
    }
  }
  if (root.has("authorisations")) {
    const JsonNode a = root.at("authorisations");
    for (std::size_t i = 0; i < a.array().size(); ++i) spec.authorisations.insert(a.item(i).str());
  }
  return spec;
}

CorridorSpec loadCorridorSpec(const std::string& path) { return parseCorridorSpec(maps::readJsonFile(path), path); }

CorridorBoxes buildBoxes(const CorridorSpec& spec) {
  const maps::PlaneFrame frame(spec.origin.lat_rad, spec.origin.lon_rad);
  LevelLimits limits;
  try {
    limits = alertLimits(spec.vehicle, spec.levels);
  } catch (const std::invalid_argument& e) {
    throw ParseError(spec.source, 0, "k1/k2/vehicle", "", std::string(e.what()));
  }
  std::vector<Eigen::Vector3d> path_map;
  path_map.reserve(spec.path.size());
  for (const maps::Geodetic& g : spec.path) {
    const Eigen::Vector2d p = frame.toPlane(g.lat_rad, g.lon_rad);
    path_map.emplace_back(p.x(), p.y(), g.h_ell_m);
  }
  return {frame, limits, Corridor(path_map, limits.level1, spec.operating),
          Corridor(path_map, limits.level2, spec.operating)};
}

}  // namespace skylane::geofence
