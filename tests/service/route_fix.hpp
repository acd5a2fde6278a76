#pragma once
/// \file
/// \brief What the service and NATS tests send along an approved route: fixes interpolated on
/// the report's route by its ETAs, and a zone set with a closure put on the route.

#include "maps/time.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace skylane::test {

/// A fix `k` seconds after departure on the report's route (between its points by their ETAs),
/// `off_m` metres north of it, with HPL = VPL = `pl_m`.
inline nlohmann::json fixAlongRoute(const nlohmann::json& report, int k, double off_m = 0.0, double pl_m = 0.5) {
  const nlohmann::json& pts = report.at("route");
  std::size_t i = 1;
  while (i + 1 < pts.size() && k > pts[i].at("eta_s").get<double>()) ++i;
  const nlohmann::json &a = pts[i - 1], &b = pts[i];
  const double f = std::clamp((k - a.at("eta_s").get<double>()) / (b.at("eta_s").get<double>() - a.at("eta_s").get<double>()), 0.0, 1.0);
  auto mix = [&](const char* key) { return a.at(key).get<double>() + f * (b.at(key).get<double>() - a.at(key).get<double>()); };
  const std::string time = maps::formatRfc3339(maps::parseRfc3339(report.at("departure").get<std::string>())->plus(k));
  return {{"time", time}, {"lat", mix("lat") + off_m / 111'195.0}, {"lon", mix("lon")}, {"h_ell_m", mix("h_ell_m")},
          {"hpl_m", pl_m}, {"vpl_m", pl_m}};
}

/// An ED-269 zone list with one more zone, EX-NEW-CLOSURE: a copy of its first zone made a square
/// 120 m wide around `at` (a fix on the route).
inline nlohmann::json withClosureAt(nlohmann::json zones, const nlohmann::json& at) {
  nlohmann::json closure = zones["UASZoneList"][0];
  const double lat = at["lat"], lon = at["lon"], dlat = 60.0 / 111'195.0, dlon = dlat / std::cos(lat * M_PI / 180.0);
  closure["identifier"] = "EX-NEW-CLOSURE";
  closure["name"] = "Closure put while flying (test)";
  closure["geometry"][0]["horizontalProjection"]["coordinates"] = nlohmann::json::array(
      {nlohmann::json::array({{lon - dlon, lat - dlat}, {lon + dlon, lat - dlat}, {lon + dlon, lat + dlat}, {lon - dlon, lat + dlat}, {lon - dlon, lat - dlat}})});
  zones["UASZoneList"].push_back(closure);
  return zones;
}

}  // namespace skylane::test
