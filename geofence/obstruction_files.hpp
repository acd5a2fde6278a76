#pragma once
/// \file
/// \brief Obstructions from files: zone files (ED-269, ED-318, GeoJSON, QGroundControl) and a
/// buildings GeoJSON, cut into the scene of a map frame. Shared by `fence check` and route
/// approval.

#include "airspace/loaders.hpp"
#include "geofence/fence.hpp"
#include "maps/terrain.hpp"

#include <set>
#include <string>
#include <vector>

namespace skylane::geofence {

/// \brief Which files hold the obstructions.
struct ObstructionFiles {
  std::vector<std::string> zones;
  airspace::ZoneFormat format = airspace::ZoneFormat::kAuto;
  std::string buildings;  ///< empty: none
};

/// \brief Loads the zones and buildings, resolves their heights with `terrain` and the EGM96
/// geoid, and builds the scene in `frame`. The zone files named in `qgc_plans` are read as
/// QGroundControl plans whatever `files.format` says (a mission's .plan, whose geoFence joins
/// zones of another format).
/// \throws maps::ParseError naming the file and field of a bad input; std::invalid_argument
/// naming a zone whose limits cannot be resolved.
[[nodiscard]] Obstructions loadObstructions(const ObstructionFiles& files, const maps::PlaneFrame& frame,
                                            const maps::Terrain& terrain, ZonePolicy policy, FenceOptions options,
                                            const std::set<std::string>& qgc_plans = {});

}  // namespace skylane::geofence
