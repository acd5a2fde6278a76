#pragma once
/// \file
/// \brief Geometry services on zone outlines (CGAL inside the .cpp): exact point-in-zone,
/// circles as polygons with a stated one-sided error, outward buffering, convex decomposition
/// and exact segment-meets-zone predicates.
///
/// Two coordinate settings:
/// - **Outlines** (airspace/zone.hpp): latitude/longitude [rad] on WGS-84, as loaded.
/// - **Planar** rings and prisms: (x east, y north) [m] in a local plane the caller chooses
///   (maps::PlaneFrame at the mission origin, or any other map frame), with z the ellipsoidal
///   height [m] for prisms. Polygon edges are straight in that plane. These are the oracle the
///   FCL-based checks are tested against, so they work on exactly the numbers FCL gets.
///
/// "Safe side": a zone to stay out of may only grow when approximated (the approximation
/// contains the exact shape); a keep-in zone may only shrink.

#include "airspace/zone.hpp"
#include "maps/plane_frame.hpp"

#include <Eigen/Core>

#include <vector>

namespace skylane::airspace {

/// \brief Where a point lies with respect to an outline.
enum class Side { kInside, kBoundary, kOutside };

/// \brief Horizontal position of `p` relative to the outline. Polygons: the ring is projected
/// into the azimuthal equidistant plane centred at `p` (maps/plane_frame.hpp) and tested with
/// CGAL's exact bounded-side predicate; circles: the WGS-84 geodesic distance to the centre
/// against the radius.
[[nodiscard]] Side horizontalSide(const Outline& o, const LatLon& p);

/// \brief Which way an approximation may err.
enum class SafeSide {
  kContain,    ///< the approximation contains the exact shape (zones to stay out of)
  kContained,  ///< the approximation lies inside the exact shape (keep-in zones)
};

/// \brief The safe side for a zone: kContained for keep-in zones, kContain otherwise.
[[nodiscard]] SafeSide safeSideOf(const Zone& z);

/// \brief Vertex count N of a regular polygon that approximates a circle of radius r to within
/// e on the given side. Circumscribed (kContain): the vertices lie at r/cos(π/N), the largest
/// distance from the circle, so N = ⌈π / acos(r/(r+e))⌉. Inscribed (kContained): the sagitta
/// r(1 − cos(π/N)) is the largest gap, so N = ⌈π / acos(1 − e/r)⌉. At least 3.
/// \throws std::invalid_argument when r or e is not positive and finite, or when an inscribed
/// polygon is asked for with e ≥ r.
[[nodiscard]] int circleVertexCount(double radius_m, double max_error_m, SafeSide side);

/// \brief A circle outline as a polygon outline (counter-clockwise) within `max_error_m` of
/// the circle and on the given side of it, with a margin: kContain puts the polygon between
/// r + e/4 and r + e from the centre, kContained between r − e and r − e/4, so it stays on its
/// side when its edges are later taken as straight in another local plane. The vertices are
/// geodesic destinations from the centre (azimuthal equidistant plane at the centre, where
/// the circle is exact). A polygon outline is returned unchanged.
[[nodiscard]] Outline circleToPolygon(const Outline& o, double max_error_m, SafeSide side);

/// \brief A ring in a local plane [m], counter-clockwise, no repeated closing vertex.
using PlanarRing = std::vector<Eigen::Vector2d>;

/// \brief The outline in `frame`: polygon vertices projected; a circle approximated first
/// (circleToPolygon with max_error_m and side).
[[nodiscard]] PlanarRing projectOutline(const Outline& o, const maps::PlaneFrame& frame, double max_error_m,
                                        SafeSide side);

/// \brief Twice the signed area of a planar ring [m²] (shoelace formula; > 0 counter-clockwise).
[[nodiscard]] double twiceSignedArea_m2(const PlanarRing& ring);

/// \brief Outward buffer of a simple counter-clockwise ring by `distance_m`: the Minkowski sum
/// of the ring with a regular polygon circumscribed about the disk of that radius (CGAL
/// minkowski_sum_2, exact kernel). It contains every point within `distance_m` of the ring and
/// no point farther than `distance_m + max_error_m`; holes in the sum are filled (more
/// room taken, never less).
/// \throws std::invalid_argument for a negative or non-finite distance, a non-positive error,
/// or a ring with fewer than 3 vertices.
[[nodiscard]] PlanarRing bufferRing(const PlanarRing& ring, double distance_m, double max_error_m);

/// \brief Outward buffer of an outline by `distance_m` (the same contract as bufferRing). A
/// circle grows its radius (exact). A polygon is buffered in the azimuthal equidistant plane
/// centred at its vertex mean and taken back to latitude/longitude; the plane's scale error
/// away from its centre, (ρ/R)²/6 at distance ρ, is covered by enlarging the buffer by that
/// factor for the farthest vertex.
[[nodiscard]] Outline bufferOutline(const Outline& o, double distance_m, double max_error_m);

/// \brief Convex pieces of a simple counter-clockwise ring: the interiors are disjoint and the
/// union is the ring's region (Hertel–Mehlhorn approximate optimal partition, at most four
/// times the optimal number of pieces: CGAL approx_convex_partition_2). Each piece is
/// counter-clockwise.
/// \throws std::invalid_argument when the ring is not simple or has fewer than 3 vertices.
[[nodiscard]] std::vector<PlanarRing> convexPieces(const PlanarRing& ring);

/// \brief Whether the closed segment ab meets the closed region of the ring (crosses or touches
/// its boundary, or lies inside). Exact predicates.
[[nodiscard]] bool segmentMeetsRing(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const PlanarRing& ring);

/// \brief Whether the closed segment ab meets the closed disk (exact arithmetic on the given
/// doubles: squared distance against r²).
[[nodiscard]] bool segmentMeetsDisk(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& centre,
                                    double radius_m);

/// \brief A zone volume in a local plane: a ring or a disk extruded between a floor and a
/// ceiling in ellipsoidal height (−∞ / +∞ for none).
struct PlanarPrism {
  PlanarRing ring;             ///< empty for a disk
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< disk
  double radius_m = 0.0;       ///< disk
  double floor_h_ell_m = 0.0;
  double ceiling_h_ell_m = 0.0;
};

/// \brief Whether the closed 3D segment ab, (x, y, h_ell), meets the closed prism. The segment
/// is clipped to floor ≤ h ≤ ceiling with exact rational arithmetic, and the clipped piece is
/// tested with segmentMeetsRing / segmentMeetsDisk exactly.
[[nodiscard]] bool segmentMeetsPrism(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const PlanarPrism& prism);

/// \brief Whether the closed vertical cylinder round `centre` (x, y, h_ell) with the given
/// radius and half-height meets the closed prism: the height intervals overlap and the disk
/// meets the ring (the centre lies in it or an edge comes within the radius) or the prism's
/// disk. Exact rational arithmetic on the given doubles, so touching counts as meeting.
/// \throws std::invalid_argument for a non-finite centre or a negative/non-finite size.
[[nodiscard]] bool cylinderMeetsPrism(const Eigen::Vector3d& centre, double radius_m, double half_height_m,
                                      const PlanarPrism& prism);

}  // namespace skylane::airspace
