#pragma once
/// \file
/// \brief Geometry services on zone outlines (CGAL exact predicates inside the .cpp).

#include "airspace/zone.hpp"

namespace skylane::airspace {

/// \brief Where a point lies with respect to an outline.
enum class Side { kInside, kBoundary, kOutside };

/// \brief Horizontal position of `p` relative to the outline. Polygons: the ring is projected
/// into the azimuthal equidistant plane centred at `p` (maps/plane_frame.hpp) and tested with
/// CGAL's exact bounded-side predicate; circles: the WGS-84 geodesic distance to the centre
/// against the radius.
[[nodiscard]] Side horizontalSide(const Outline& o, const LatLon& p);

}  // namespace skylane::airspace
