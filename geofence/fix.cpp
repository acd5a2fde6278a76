#include "geofence/fix.hpp"

#include "maps/geodesy.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"

#include <cmath>

namespace skylane::geofence {

using maps::ParseError;
using nlohmann::json;

Fix parseFix(const json& doc, const std::string& source) {
  const maps::JsonNode root{doc, "$", source};
  if (!doc.is_object()) root.fail("a JSON object {\"time\", \"lat\", \"lon\", \"h_ell_m\", \"hpl_m\", \"vpl_m\"}");
  root.requireKnownFields({"id", "time", "until", "lat", "lon", "h_ell_m", "hpl_m", "vpl_m"});
  const auto time = [&](const char* key) {
    const maps::JsonNode n = root.at(key);
    const auto t = maps::parseRfc3339(n.str());
    if (!t) n.fail("an RFC 3339 date-time such as 2026-11-23T14:00:00Z");
    return *t;
  };
  const auto nonNegative = [&](const char* key) {
    const maps::JsonNode n = root.at(key);
    const double v = n.number();
    if (v < 0) n.fail("a protection level ≥ 0 m");
    return v;
  };
  Fix f;
  if (doc.contains("id")) f.id = doc.at("id");
  f.t0 = time("time");
  f.t1 = root.has("until") ? time("until") : f.t0;
  if (f.t1 - f.t0 < 0) root.at("until").fail("a time not before \"time\"");
  const maps::JsonNode lat = root.at("lat"), lon = root.at("lon");
  if (std::abs(lat.number()) > 90) lat.fail("a latitude in [-90, 90] degrees");
  if (std::abs(lon.number()) > 180) lon.fail("a longitude in [-180, 180] degrees");
  f.lat_rad = maps::deg2rad(lat.number());
  f.lon_rad = maps::deg2rad(lon.number());
  f.h_ell_m = root.at("h_ell_m").number();
  f.hpl_m = nonNegative("hpl_m");
  f.vpl_m = nonNegative("vpl_m");
  return f;
}

}  // namespace skylane::geofence
