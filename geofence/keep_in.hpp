#pragma once
/// \file
/// \brief Keep-in zones (docs/method.md §6.4): the space a protection volume must stay inside —
/// QGroundControl inclusion fences, GeoJSON zones with restriction KEEP_IN.
///
/// **The rule for several fences.** The volume must lie inside the **union** of the keep-in
/// zones active at the time (PX4's rule: inside any inclusion fence). ArduPilot asks for the
/// intersection instead; skylane's exported plan (link/qgc_plan.hpp) holds one inclusion polygon,
/// so either autopilot reads it the same. When no keep-in zone is active, nothing is required.
///
/// **Exact where it counts, safe elsewhere.** In the mission map frame (x east, y north [m], z the
/// ellipsoidal height) each keep-in volume is its outline as a ring — a circle as an inscribed
/// polygon, so the ring lies inside the zone — between its floor at its highest and its ceiling
/// at its lowest over the outline (the zone may only shrink). The volume is held when its height
/// interval [z − VPL, z + VPL] lies inside the height band of every zone used and its disk
/// (radius HPL) lies inside the horizontal union of the zones whose band holds that interval.
/// That is exact when the keep-in zones share one band (a QGroundControl fence is unlimited in
/// height) and errs on the safe side otherwise (a volume held only by one zone's lower half and
/// another's upper half counts as outside).

#include "airspace/vertical.hpp"
#include "airspace/zone.hpp"
#include "airspace/zone_geometry.hpp"
#include "geofence/corridor.hpp"
#include "maps/plane_frame.hpp"

#include <cstddef>
#include <vector>

namespace skylane::geofence {

/// \brief The largest gap between a keep-in circle and its inscribed polygon [m].
inline constexpr double kKeepInCircleError_m = 0.05;

/// \brief One volume of a keep-in zone in the map frame: a ring (counter-clockwise, simple) between a floor
/// and a ceiling (−∞ / +∞ allowed).
struct KeepInVolume {
  airspace::PlanarRing ring;
  double floor_h_ell_m = 0.0;
  double ceiling_h_ell_m = 0.0;
  std::size_t zone = 0;  ///< which zone of the list it came from
};

/// \brief The volumes of the keep-in zones of `zones` (those with keep_in), shrunk to the safe side.
/// \throws std::invalid_argument naming the zone when a limit cannot be resolved (an AGL limit
/// where the terrain is unknown) or its ring is not simple.
[[nodiscard]] std::vector<KeepInVolume> keepInVolumes(const std::vector<airspace::Zone>& zones,
                                                      const maps::PlaneFrame& frame,
                                                      const airspace::VerticalModel& model);

/// \brief How far a protection volume is inside the union of keep-in volumes.
///
/// margin_h = (distance from the volume's centre to the outside of the horizontal union of the
/// volumes whose band holds the volume's height interval; negative: the distance to that union
/// from outside) − HPL; margin_v = the least room left between the volume's height interval and
/// the bands of those volumes whose ring the disk reaches (negative: how far the interval sticks
/// out of the nearest band when no band holds it). The volume is inside iff both are ≥ 0.
struct KeepInMargins {
  double margin_h_m = 0.0;
  double margin_v_m = 0.0;
  /// The keep-in volume that holds the centre deepest, else the nearest (an index into the list given).
  std::size_t nearest = 0;
};

/// \brief The margins of `volume` against the union of `active` (not empty).
/// \throws std::invalid_argument for an empty list.
[[nodiscard]] KeepInMargins keepInMargins(const ProtectionVolume& volume, const std::vector<const KeepInVolume*>& active);

/// \brief Signed distance from `p` to the boundary of a simple ring [m]: positive inside,
/// negative outside, 0 on it.
[[nodiscard]] double signedDistanceToRing(const Eigen::Vector2d& p, const airspace::PlanarRing& ring);

}  // namespace skylane::geofence
