#pragma once
/// \file
/// \brief Zones and obstacles as convex pieces in the mission map frame, one FCL collision object
/// per piece indexed by a flat grid over their FCL AABBs, and the separation of a protection
/// volume from them: FCL narrow phase (GJK distance between the volume's cylinder and the
/// piece), with the exact predicates of airspace/ deciding near contact and whenever FCL fails.
///
/// FCL stays inside geofence/fcl_module.cpp (libskylane_fcl.so, loaded with the first Scene).
/// The map frame is the one of geofence/corridor.hpp: x east and y north [m] in the mission's
/// azimuthal equidistant plane, z the ellipsoidal height [m].
///
/// **Touching** (the decision): zones and obstacles are closed sets, so a volume that touches a
/// piece meets it (airspace::cylinderMeetsPrism is exact about it). Its deciding margin is 0,
/// so the checks above report such a contact as indeterminate, never as clear.

#include "airspace/zone_geometry.hpp"
#include "geofence/corridor.hpp"

#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

namespace skylane::geofence {

/// \brief What a piece belongs to.
enum class PieceOwner { kZone, kObstacle };

/// \brief Heights FCL works within [m, ellipsoidal]: an unlimited floor is cut at the bottom of
/// this band (or 1 km below a ceiling that lies under it) and an unlimited ceiling at its top
/// (or 1 km above a floor over it) — FCL needs finite shapes; finite limits stay as they are.
/// The band holds every surface on Earth (the Dead Sea shore is at about −400 m ellipsoidal)
/// and every flight a U-space serves, so the cut changes no answer for a volume inside it; a
/// volume reaching out of it is refused.
inline constexpr double kSceneFloor_h_ell_m = -2000.0;
inline constexpr double kSceneCeiling_h_ell_m = 20000.0;

/// \brief FCL's GJK distance decides "clear" only above this [m] and only when it agrees with
/// the closed form of Separation to within it; otherwise (contact, penetration, a near miss, a
/// disagreement) the exact predicate decides. FCL's GJK stops at 1e-6 m when it converges; a
/// centimetre leaves a wide berth (the volume's FCL cylinder is at least 1 mm in each size).
inline constexpr double kExactBand_m = 0.01;

/// \brief One convex piece of a zone or an obstacle: a convex counter-clockwise ring, or a
/// disk (empty ring), between a floor and a ceiling (−∞ / +∞ allowed), in the map frame.
struct ScenePiece {
  airspace::PlanarPrism prism;
  PieceOwner owner = PieceOwner::kZone;
  std::size_t owner_index = 0;  ///< which zone or obstacle
};

/// \brief How far a protection volume is from a piece.
///
/// The volume and the piece are both a horizontal shape times a height interval, so with
///   margin_h = (signed horizontal distance from the volume's centre to the piece) − HPL and
///   margin_v = (signed vertical distance from the centre to the piece's height band) − VPL
/// (signed: negative inside) the volume meets the piece iff max(margin_h, margin_v) ≤ 0, and
/// their 3-D distance is hypot(max(margin_h, 0), max(margin_v, 0)). margin_h is how much HPL
/// could grow, margin_v how much VPL could, before the volume meets the piece.
struct Separation {
  double margin_h_m = 0.0;
  double margin_v_m = 0.0;
  double clearance_m = 0.0;  ///< 3-D distance (the closed form above), 0 when meeting
  bool meets = false;        ///< the volume meets the piece (closed sets)
  bool exact = false;        ///< decided by the exact predicate (near contact, disagreement, FCL failed)
  bool fcl_failed = false;   ///< FCL threw; the exact predicate stood in
  /// FCL's GJK distance from the last solver the narrow phase ran (≤ 0 in contact), else NaN.
  double fcl_distance_m = std::numeric_limits<double>::quiet_NaN();
};

/// \brief The margins of the volume from the piece, computed directly in the piece's frame
/// (the formulas of Separation; meets and clearance follow from them, in floating point).
[[nodiscard]] Separation separationMargins(const ProtectionVolume& volume, const airspace::PlanarPrism& piece);

/// \brief A zone or obstacle the query reached: the piece that decides it and its separation.
struct SceneHit {
  PieceOwner owner = PieceOwner::kZone;
  std::size_t owner_index = 0;
  std::size_t piece = 0;  ///< a piece the volume meets, else the piece nearest to it
  Separation separation;
};

/// \brief Convex pieces behind a grid over their FCL AABBs.
class Scene {
 public:
  /// \brief Builds one FCL object per piece (a convex mesh for a ring, a cylinder for a disk;
  /// vertices relative to the piece's centre for conditioning) and the broad phase over them.
  /// \throws std::invalid_argument for a ring that is not convex and counter-clockwise, a
  /// non-finite coordinate, a non-positive radius or a floor not below its ceiling (the
  /// message names the piece).
  explicit Scene(std::vector<ScenePiece> pieces);
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;

  /// \brief The pieces, in the order given.
  [[nodiscard]] const std::vector<ScenePiece>& pieces() const;

  /// \brief Every zone and obstacle (owner) that `accept(owner, owner_index)` takes with a piece
  /// that meets the volume or lies within `horizon_m` of it; one hit per owner, sorted by owner.
  ///
  /// Broad phase: the volume's cylinder grown by the horizon against the AABB grid. Then, per
  /// owner, the direct margins (separationMargins) rank its pieces; the narrow phase — FCL's
  /// GJK distance, with the exact predicate at or below kExactBand_m, when FCL and the closed
  /// form disagree, or when FCL throws — runs on every piece the margins put within kExactBand_m of
  /// meeting (until one meets), else on the nearest piece. Pieces the margins put farther than
  /// the band cannot meet the volume (the margins' rounding is far below it) and are not
  /// nearer than the one evaluated. Thread-safe (const, no shared scratch).
  /// \throws std::invalid_argument for a non-finite position, a negative or non-finite PL or
  /// horizon, or a volume reaching outside [kSceneFloor_h_ell_m, kSceneCeiling_h_ell_m].
  [[nodiscard]] std::vector<SceneHit> query(const ProtectionVolume& volume, double horizon_m,
                                            const std::function<bool(PieceOwner, std::size_t)>& accept) const;
  /// \brief The same into `hits`, cleared first: its storage is reused, so a caller that keeps
  /// one vector makes no allocation per query once it has grown.
  void query(const ProtectionVolume& volume, double horizon_m,
             const std::function<bool(PieceOwner, std::size_t)>& accept, std::vector<SceneHit>& hits) const;

  /// \brief Whether query(volume, 0, accept) reports any owner, found without FCL: a piece is
  /// reported at horizon 0 exactly when its margins put the volume in contact (deciding margin
  /// ≤ 0, clearance 0) or, within kExactBand_m outside, when the exact predicate has them meet.
  /// The narrow phase's FCL distances change the separation query() reports, never whether it
  /// reports a piece at horizon 0 (settle(): FCL decides only where it agrees with the margins).
  /// For yes/no questions such as a planner's state validity. Thread-safe.
  /// \throws std::invalid_argument as query() does.
  [[nodiscard]] bool reachesAny(const ProtectionVolume& volume, const std::function<bool(PieceOwner, std::size_t)>& accept) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace skylane::geofence
