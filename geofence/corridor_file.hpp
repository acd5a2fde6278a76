#pragma once
/// \file
/// \brief The corridor file: a mission's path, vehicle and box factors as JSON (README,
/// "Corridor file"), and the two box levels built from it in the mission map frame.

#include "geofence/corridor.hpp"
#include "maps/geodesy.hpp"
#include "maps/plane_frame.hpp"

#include <nlohmann/json.hpp>

#include <set>
#include <string>
#include <vector>

namespace skylane::geofence {

/// \brief What a corridor file says.
struct CorridorSpec {
  std::string source;                 ///< the file
  std::vector<maps::Geodetic> path;   ///< waypoints (lat, lon [rad], h_ell [m])
  maps::Geodetic origin;              ///< the map frame's origin (default: the first waypoint)
  Vehicle vehicle;
  BoxLevels levels;
  OperatingLimits operating;
  std::set<std::string> authorisations;  ///< zone identifiers the mission may enter
};

/// \brief Parses a corridor document; `source` names it in errors.
/// \throws maps::ParseError naming the source, the field (e.g. "path[2].lat"), the value and
/// what was expected; unknown fields are errors too.
[[nodiscard]] CorridorSpec parseCorridorSpec(const nlohmann::json& doc, const std::string& source);

/// \brief Reads and parses a corridor file.
[[nodiscard]] CorridorSpec loadCorridorSpec(const std::string& path);

/// \brief The boxes of a corridor file in its map frame.
struct CorridorBoxes {
  maps::PlaneFrame frame;
  LevelLimits limits;
  Corridor level1;
  Corridor level2;
};

/// \brief Builds the frame, the alert limits (alertLimits) and both levels' corridors.
/// \throws maps::ParseError naming the source when the factors or the vehicle are refused.
[[nodiscard]] CorridorBoxes buildBoxes(const CorridorSpec& spec);

}  // namespace skylane::geofence
