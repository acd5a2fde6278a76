#include "geofence/obstruction_files.hpp"

#include "airspace/validation.hpp"
#include "maps/geoid.hpp"

#include <iterator>
#include <utility>

namespace skylane::geofence {

Obstructions loadObstructions(const ObstructionFiles& files, const maps::PlaneFrame& frame, const maps::Terrain& terrain,
                              ZonePolicy policy, FenceOptions options) {
  const airspace::VerticalModel model{terrain, maps::Geoid::egm96()};
  std::vector<airspace::Zone> zones;
  for (const std::string& path : files.zones) {
    std::vector<airspace::Zone> z = airspace::loadZones(path, files.format);
    zones.insert(zones.end(), std::make_move_iterator(z.begin()), std::make_move_iterator(z.end()));
  }
  std::vector<maps::Building> buildings;
  if (!files.buildings.empty()) buildings = maps::loadBuildings(files.buildings, terrain);
  std::vector<ScenePiece> pieces = zonePieces(zones, frame, model);
  std::vector<KeepInVolume> keep_in = keepInVolumes(zones, frame, model);
  std::vector<ScenePiece> obstacles = obstaclePieces(buildings, frame);
  pieces.insert(pieces.end(), obstacles.begin(), obstacles.end());
  return Obstructions(std::move(zones), std::move(buildings), Scene(std::move(pieces)), std::move(policy), options,
                      std::move(keep_in));
}

}  // namespace skylane::geofence
