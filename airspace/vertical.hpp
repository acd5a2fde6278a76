#pragma once
/// \file
/// \brief Vertical limits resolved to WGS-84 ellipsoidal height at a place: AMSL through the
/// EGM96 geoid (h = H + N), AGL through the terrain model (h = terrain h_ell + value), WGS84 as
/// given; unlimited ceilings at +∞ and missing floors at −∞.

#include "airspace/zone.hpp"
#include "maps/geoid.hpp"
#include "maps/terrain.hpp"

#include <optional>

namespace skylane::airspace {

/// \brief What vertical references are resolved with.
struct VerticalModel {
  const maps::Terrain& terrain;
  const maps::Geoid& geoid;
};

/// \brief Ellipsoidal height [m] of the limit at `p`; ±∞ when unlimited (−∞ for a floor);
/// nullopt when the limit is AGL and the terrain is unknown at `p`.
[[nodiscard]] std::optional<double> limitHeightEllipsoid_m(const VerticalLimit& l, bool ceiling, const LatLon& p,
                                                           const VerticalModel& model);

/// \brief A limit's extent over an outline, in both height references.
struct HeightRange {
  double h_ell_min_m = 0, h_ell_max_m = 0;
  double alt_amsl_min_m = 0, alt_amsl_max_m = 0;
};

/// \brief Conservative range of the limit over the outline's bounding box (a circle's
/// circumscribed square): the geoid's range there (Geoid::undulationRange_m) and, for AGL, the
/// terrain's (Terrain::rangeAmsl_m); ±∞ when unlimited; nullopt when the terrain is unknown
/// somewhere in the box.
[[nodiscard]] std::optional<HeightRange> limitRange(const VerticalLimit& l, bool ceiling, const Outline& o,
                                                    const VerticalModel& model);

}  // namespace skylane::airspace
