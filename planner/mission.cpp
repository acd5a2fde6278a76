#include "planner/mission.hpp"

#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>

namespace skylane::planner {

using maps::JsonNode;

namespace {

double positive(const JsonNode& n) {
  const double v = n.number();
  if (!(v > 0.0)) n.fail("a number > 0");
  return v;
}

MissionPoint point(const JsonNode& n) {
  n.requireKnownFields({"lat", "lon"});
  const double lat = n.at("lat").number(), lon = n.at("lon").number();
  if (std::abs(lat) > 89.0) n.at("lat").fail("a latitude within ±89°");
  if (std::abs(lon) > 180.0) n.at("lon").fail("a longitude within ±180°");
  return {maps::deg2rad(lat), maps::deg2rad(lon)};
}

maps::GpsTime time(const JsonNode& n) {
  const auto t = maps::parseRfc3339(n.str());
  if (!t) n.fail("an RFC 3339 UTC time such as \"2026-11-24T14:00:00Z\"");
  return *t;
}

std::string resolve(const std::string& base_dir, const std::string& name) {
  std::filesystem::path p(name);
  if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
  return p.lexically_normal().string();
}

std::vector<std::string> files(const JsonNode& n, const std::string& base_dir) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n.array().size(); ++i) out.push_back(resolve(base_dir, n.item(i).str()));
  return out;
}

}  // namespace

Mission parseMission(const nlohmann::json& doc, const std::string& source, const std::string& base_dir) {
  const JsonNode root{doc, "$", source};
  root.requireKnownFields({"name", "vehicle", "k1", "k2", "start", "goal", "waypoints", "altitude", "departure",
                           "departure_window", "zones", "zone_format", "terrain", "ground_amsl_m", "buildings",
                           "authorisations", "orbits", "integrity", "planner"});
  Mission m;
  m.source = source;
  if (root.has("name")) m.name = root.at("name").str();
  {
    const JsonNode v = root.at("vehicle");
    v.requireKnownFields({"lateral_m", "longitudinal_m", "height_m", "cruise_speed_mps", "climb_speed_mps"});
    m.vehicle.lateral_m = positive(v.at("lateral_m"));
    m.vehicle.longitudinal_m = positive(v.at("longitudinal_m"));
    if (v.has("height_m")) m.vehicle.height_m = positive(v.at("height_m"));
    m.cruise_speed_mps = positive(v.at("cruise_speed_mps"));
    if (v.has("climb_speed_mps")) m.climb_speed_mps = positive(v.at("climb_speed_mps"));
  }
  if (root.has("k1")) m.levels.k1 = root.at("k1").number();
  if (root.has("k2")) m.levels.k2 = root.at("k2").number();
  m.points.push_back(point(root.at("start")));
  if (root.has("waypoints")) {
    const JsonNode w = root.at("waypoints");
    for (std::size_t i = 0; i < w.array().size(); ++i) m.points.push_back(point(w.item(i)));
  }
  m.points.push_back(point(root.at("goal")));
  if (root.has("altitude")) {
    const JsonNode a = root.at("altitude");
    a.requireKnownFields({"cruise_agl_m", "min_agl_m", "max_agl_m", "max_amsl_m"});
    if (a.has("cruise_agl_m")) m.cruise_agl_m = positive(a.at("cruise_agl_m"));
    if (a.has("min_agl_m")) m.min_agl_m = a.at("min_agl_m").number();
    if (a.has("max_agl_m")) m.max_agl_m = positive(a.at("max_agl_m"));
    if (a.has("max_amsl_m")) m.max_amsl_m = a.at("max_amsl_m").number();
    if (!(m.min_agl_m <= m.cruise_agl_m && m.cruise_agl_m <= m.max_agl_m)) {
      a.fail("min_agl_m ≤ cruise_agl_m ≤ max_agl_m");
    }
  }
  m.departure_earliest = m.departure_latest = time(root.at("departure"));
  if (root.has("departure_window")) {
    const JsonNode w = root.at("departure_window");
    w.requireKnownFields({"latest", "step_s"});
    m.departure_latest = time(w.at("latest"));
    if (m.departure_latest - m.departure_earliest < 0) w.at("latest").fail("a time not before departure");
    if (w.has("step_s")) m.departure_step_s = positive(w.at("step_s"));
  }
  if (root.has("zones")) m.zone_files = files(root.at("zones"), base_dir);
  if (root.has("zone_format")) m.zone_format = root.at("zone_format").str();
  if (root.has("terrain") && root.has("ground_amsl_m")) root.fail("an object with at most one of terrain and ground_amsl_m");
  if (root.has("terrain")) m.terrain_file = resolve(base_dir, root.at("terrain").str());
  if (root.has("ground_amsl_m")) m.ground_amsl_m = root.at("ground_amsl_m").number();
  if (root.has("buildings")) m.buildings_file = resolve(base_dir, root.at("buildings").str());
  if (root.has("authorisations")) {
    const JsonNode a = root.at("authorisations");
    for (std::size_t i = 0; i < a.array().size(); ++i) m.authorisations.insert(a.item(i).str());
  }
  {
    const JsonNode o = root.at("orbits");
    if (o.array().empty()) o.fail("a non-empty array of almanac or RINEX navigation file names");
    m.orbit_files = files(o, base_dir);
  }
  if (root.has("integrity")) {
    const JsonNode n = root.at("integrity");
    n.requireKnownFields({"method", "mask_deg", "user_model", "sample_s", "cost_weight", "cost_cell_m"});
    if (n.has("method")) {
      const std::string meth = n.at("method").str();
      if (meth == "raim") m.method = integrity::IntegrityMethod::kRaim;
      else if (meth == "araim") m.method = integrity::IntegrityMethod::kAraim;
      else n.at("method").fail("\"raim\" or \"araim\"");
    }
    if (n.has("mask_deg")) m.mask_deg = n.at("mask_deg").number();
    if (n.has("user_model")) {
      const std::string u = n.at("user_model").str();
      if (u == "dual_frequency") m.model.setUserModel(integrity::UserErrorModel::kDualFrequency);
      else if (u == "single_frequency") m.model.setUserModel(integrity::UserErrorModel::kSingleFrequency);
      else n.at("user_model").fail("\"dual_frequency\" or \"single_frequency\"");
    }
    if (n.has("sample_s")) m.sample_s = positive(n.at("sample_s"));
    if (n.has("cost_weight")) {
      m.cost_weight = n.at("cost_weight").number();
      if (!(m.cost_weight >= 0.0)) n.at("cost_weight").fail("a weight ≥ 0");
    }
    if (n.has("cost_cell_m")) m.cost_cell_m = positive(n.at("cost_cell_m"));
  }
  if (root.has("planner")) {
    const JsonNode p = root.at("planner");
    p.requireKnownFields({"algorithm", "time_limit_s", "seed", "resolution_m", "simplify", "margin_m", "max_replans"});
    if (p.has("algorithm")) {
      const auto k = parsePlannerKind(p.at("algorithm").str());
      if (!k) p.at("algorithm").fail("\"rrtstar\", \"informed_rrtstar\", \"bitstar\" or \"prmstar\"");
      m.planner = *k;
    }
    if (p.has("time_limit_s")) m.time_limit_s = positive(p.at("time_limit_s"));
    if (p.has("seed")) {
      const double s = p.at("seed").number();
      if (!(s >= 0 && s < 4294967296.0 && s == std::floor(s))) p.at("seed").fail("a whole number 0…2³²−1");
      m.seed = static_cast<std::uint64_t>(s);
    }
    if (p.has("resolution_m")) m.resolution_m = positive(p.at("resolution_m"));
    if (p.has("simplify")) m.simplify = p.at("simplify").boolean();
    if (p.has("margin_m")) m.margin_m = positive(p.at("margin_m"));
    if (p.has("max_replans")) {
      const double r = p.at("max_replans").number();
      if (!(r >= 0 && r <= 20 && r == std::floor(r))) p.at("max_replans").fail("a whole number 0…20");
      m.max_replans = static_cast<int>(r);
    }
  }
  return m;
}

Mission loadMission(const std::string& path) {
  return parseMission(maps::readJsonFile(path), path, std::filesystem::path(path).parent_path().string());
}

}  // namespace skylane::planner
