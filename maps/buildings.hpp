#pragma once
/// \file
/// \brief Buildings and obstacles: GeoJSON footprints with a height, extruded to prisms and
/// closed triangle meshes in a local ENU frame (docs/method.md §1.1).
///
/// **Input** (README "Buildings and obstacles"): an RFC 7946 FeatureCollection (or a single
/// Feature) whose geometries are Polygon, MultiPolygon or Point (a mast, a chimney: a vertical
/// cylinder of `radius` metres, default kDefaultObstacleRadius_m). Heights come from the
/// properties, in this order of precedence:
///  - `top_amsl_m`: absolute top above mean sea level (EGM96), metres;
///  - `height`: metres above ground (the OpenStreetMap key) — a number or a string "12",
///    "12 m", "12.5m", "40 ft", "40'";
///  - `building:levels` / `levels` × metres-per-level (BuildingOptions, default 3.0 m — an
///    assumption: real storeys run 2.6–4 m; roofs above the last storey are not counted);
///  - else BuildingOptions::default_height_m when set, else the feature is an error.
/// `min_height` (same forms as `height`) or `building:min_level` / `min_level` lift the base
/// (a bridge, an overhang).
///
/// **Ground and heights (the safe convention)**: the ground under a footprint is the terrain's
/// range over the footprint's bounding box (Terrain::rangeAmsl_m, conservative). The *base*
/// stands on the lowest ground, the *top* on the highest:
///   base_h_ell = (lowest ground AMSL + lowest N) + min_height,
///   top_h_ell  = (highest ground AMSL + highest N) + height   (or top_amsl_m + highest N),
/// with N the EGM96 undulation range over the box. Both the sky mask (a taller building blocks
/// more sky) and collision checks (a taller and deeper prism is hit sooner) err on the safe side.
///
/// **Holes** (interior rings of a Polygon) are ignored: the footprint is filled — a courtyard
/// counts as building, which blocks more sky and more airspace than the real one (safe side).
/// A bad feature makes the whole file load fail (as the zone loaders do: airspace/loaders.hpp).

#include "maps/geodesy.hpp"
#include "maps/terrain.hpp"

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace skylane::maps {

/// \brief Metres per storey when a height comes from a number of levels (an assumption; README).
inline constexpr double kMetresPerLevel = 3.0;
/// \brief Radius of a Point obstacle that gives none [m]: a lattice mast or a lamp post.
inline constexpr double kDefaultObstacleRadius_m = 1.0;
/// \brief Sides of the regular polygon that stands in for a Point obstacle's circle. The polygon
/// is circumscribed (its edges touch the circle), so it contains the whole circle.
inline constexpr int kObstacleSides = 8;

/// \brief How to read heights that a file leaves implicit.
struct BuildingOptions {
  double metres_per_level = kMetresPerLevel;      ///< `levels` × this = height [m]
  std::optional<double> default_height_m;         ///< for features with no height at all; nullopt: an error
  double default_obstacle_radius_m = kDefaultObstacleRadius_m;  ///< Point obstacles without `radius`
};

/// \brief One extruded footprint (a MultiPolygon gives one per polygon).
struct Building {
  std::string source;   ///< the file
  std::string feature;  ///< e.g. "features[3](way/1234)" or "features[3](way/1234).geometry.coordinates[1]"
  /// Outer ring, (lat, lon) [rad], open (no repeated closing vertex), ≥ 3 distinct vertices,
  /// simple (no two edges cross), in the file's winding.
  std::vector<std::pair<double, double>> ring_lat_lon_rad;
  double base_h_ell_m = 0.0;  ///< bottom of the prism, WGS-84 ellipsoidal
  double top_h_ell_m = 0.0;   ///< top of the prism, WGS-84 ellipsoidal (> base)
  bool holes_filled = false;  ///< the Polygon had interior rings, filled in
  bool from_point = false;    ///< a Point obstacle (the ring is its circumscribed polygon)
};

/// \brief Parses a GeoJSON FeatureCollection (or Feature) of buildings; `source` names it in errors.
/// \throws ParseError naming the source, the feature (index and id), the field, the value and
/// what was expected; also when a footprint lies outside `terrain` or on a void in it.
[[nodiscard]] std::vector<Building> parseBuildings(const nlohmann::json& doc, const std::string& source,
                                                   const Terrain& terrain, const BuildingOptions& options = {});

/// \brief readJsonFile + parseBuildings.
[[nodiscard]] std::vector<Building> loadBuildings(const std::string& path, const Terrain& terrain,
                                                  const BuildingOptions& options = {});

/// \brief A building as a right prism in a local ENU frame: the footprint polygon in the EN
/// plane, walls vertical along the frame's U axis, between two planes U = bottom and U = top.
///
/// The footprint's vertices are the corners at the building's base height. U bounds are
/// conservative over the footprint: bottom_u_m is the lowest, top_u_m the highest U any corner
/// has at the base / top ellipsoidal height (so the Earth's curvature between the frame's
/// origin and the building — d²/2R, 8 cm at 1 km — widens the prism, never shrinks it). The real
/// walls stand along the local plumb line, which leans from the frame's U axis by d/R (a
/// 60 m wall 2 km from the origin: 2 cm at its top); frames are meant for a mission area of a
/// few kilometres.
struct Prism {
  std::vector<Eigen::Vector2d> footprint_en;  ///< counter-clockwise seen from above (+U), open ring [m]
  double bottom_u_m = 0.0;
  double top_u_m = 0.0;
};

/// \brief Extrudes a building in `frame`.
[[nodiscard]] Prism extrude(const Building& building, const LocalFrame& frame);

/// \brief A closed triangle mesh.
///
/// **Winding rule**: every triangle (a, b, c) is counter-clockwise seen from outside the solid,
/// so its normal (b − a) × (c − a) points outward (the convention FCL's BVHModel and most mesh
/// tools take). Vertices [0, n) are the bottom corners, [n, 2n) the top corners, in footprint
/// order.
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices_enu;  ///< [m]
  std::vector<std::array<int, 3>> triangles;  ///< indices into vertices_enu
};

/// \brief The prism's surface: two caps triangulated by ear clipping (so non-convex
/// footprints work) and two triangles per wall. For n footprint vertices: 2n vertices, 4n − 4
/// triangles, 6n − 6 edges (Euler characteristic V − E + F = 2).
/// \throws std::logic_error when the footprint has fewer than 3 vertices.
[[nodiscard]] TriangleMesh prismMesh(const Prism& prism);

/// \brief Ear clipping of a simple polygon (counter-clockwise, open ring): n − 2 triangles,
/// each counter-clockwise, as index triples into `ring`. Collinear and repeated vertices are
/// tolerated; a ring that is not simple still yields n − 2 triangles (not a valid cover).
/// D. H. Eberly, "Triangulation by Ear Clipping", Geometric Tools, 2002 (rev. 2015).
[[nodiscard]] std::vector<std::array<int, 3>> earClip(const std::vector<Eigen::Vector2d>& ring);

/// \brief Twice the signed area of a ring (shoelace formula; > 0 counter-clockwise).
[[nodiscard]] double signedArea2(const std::vector<Eigen::Vector2d>& ring);

/// \brief A height given as a number (metres) or a string "12", "12 m", "12m", "40 ft", "40'".
/// Returns metres, nullopt when the text is none of these.
[[nodiscard]] std::optional<double> parseHeightText_m(const std::string& text);

}  // namespace skylane::maps
