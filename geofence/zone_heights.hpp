#pragma once
/// \file
/// \brief A zone volume's floor and ceiling over its outline (airspace::limitRange of both),
/// shared by the zones to stay clear of (geofence/fence.cpp) and the keep-in zones
/// (geofence/keep_in.cpp), which take opposite ends of the ranges.

#include "airspace/vertical.hpp"

#include <cstddef>
#include <stdexcept>
#include <string>

namespace skylane::geofence {

/// \brief Both limits' ranges over the outline.
struct VolumeHeights {
  airspace::HeightRange floor;
  airspace::HeightRange ceiling;
};

/// \brief The ranges of volume `vi` of `z`.
/// \throws std::invalid_argument naming the zone and the volume when an AGL limit lies where
/// the terrain model has no data.
[[nodiscard]] inline VolumeHeights volumeHeights(const airspace::Zone& z, std::size_t vi,
                                                 const airspace::VerticalModel& model) {
  const airspace::Volume& v = z.volumes[vi];
  const auto floor = airspace::limitRange(v.lower, false, v.outline, model);
  const auto ceiling = airspace::limitRange(v.upper, true, v.outline, model);
  if (!floor || !ceiling) {
    throw std::invalid_argument(airspace::describe(z) + ": volume " + std::to_string(vi) +
                                ": an AGL limit lies where the terrain model has no data");
  }
  return {*floor, *ceiling};
}

}  // namespace skylane::geofence
