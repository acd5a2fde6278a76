#pragma once
/// \file
/// \brief The fence check (docs/method.md §6; US 10,466,362 claims 8–9): a
/// protection volume is trusted only when it lies inside its first-level corridor, inside its
/// second-level airspace box, and clear of every zone active at the time and every obstacle.
/// One verdict type serves every level; the same checker serves a predicted trajectory and a
/// live fix.

#include "airspace/vertical.hpp"
#include "airspace/zone.hpp"
#include "geofence/corridor.hpp"
#include "geofence/keep_in.hpp"
#include "geofence/scene.hpp"
#include "maps/buildings.hpp"
#include "maps/plane_frame.hpp"
#include "maps/time.hpp"

#include <optional>
#include <set>
#include <string>
#include <vector>

namespace skylane::geofence {

/// \brief The level a check belongs to. (kKeepIn comes last so that the per-level state stored by
/// earlier versions keeps its indices; checks are ordered 1, 2, keep-in, zones, obstacles.)
enum class Level { kCorridor, kAirspace, kZone, kObstacle, kKeepIn };

/// \brief "level1", "level2", "zone", "obstacle", "keep_in".
[[nodiscard]] const char* levelName(Level l);

/// \brief Whether the level is one the volume must lie inside (the two boxes, the keep-in zones)
/// rather than one it must stay clear of (zones and obstacles).
[[nodiscard]] inline bool isContainmentLevel(Level l) { return l != Level::kZone && l != Level::kObstacle; }

/// \brief The word a check of this level reports: "inside" / "outside" for the boxes and the
/// keep-in zones, "clear" / "met" for zones and obstacles; "indeterminate" for both.
[[nodiscard]] const char* verdictWord(Level l, Verdict v);

/// \brief One check of a protection volume.
///
/// `verdict` says whether the volume lies inside the space the check allows: the box for
/// levels 1 and 2, the union of the active keep-in zones, everything outside the zone or
/// obstacle otherwise (reported as verdictWord: inside / outside, clear / met). Margins in metres are how
/// much HPL (margin_h) and VPL (margin_v) could still grow and the verdict stay; negative: by
/// how much they are exceeded. A box is kept when both margins are positive, a zone when
/// either is (see Separation); within the tolerance of that the verdict is indeterminate.
struct Check {
  Level level = Level::kCorridor;
  Verdict verdict = Verdict::kInside;
  std::size_t index = 0;    ///< segment (levels 1, 2) or zone / obstacle index
  std::string subject;      ///< "segment 3", the zone's identifier, the obstacle's feature
  std::string name;         ///< zones and keep-in: the zone's name
  std::string restriction;  ///< zones and keep-in: airspace::restrictionLabel (KEEP_IN for keep-in)
  double margin_h_m = 0.0;
  double margin_v_m = 0.0;
  std::optional<double> clearance_m;  ///< zones and obstacles: 3-D distance (0 when met)
  bool across_joint = false;          ///< levels 1, 2: held only by the union at a joint
  bool exact = false;                 ///< zones and obstacles: decided by exact predicates
};

/// \brief The outcome for one protection volume.
struct FenceVerdict {
  /// inside only when every check is; outside when any check is; indeterminate otherwise.
  Verdict verdict = Verdict::kInside;
  /// The first level (in the order 1, 2, keep-in, zone, obstacle) with an outside check, or else
  /// with an indeterminate one; empty when inside.
  std::optional<Level> violated;
  /// That check's index in `checks`.
  std::optional<std::size_t> deciding;
  /// Level 1 and level 2 always (their deciding segment); the keep-in check when a keep-in zone
  /// is active; then every zone and obstacle within the clearance horizon, nearest first within
  /// each level.
  std::vector<Check> checks;
};

/// \brief Which zones count.
struct ZonePolicy {
  /// Identifiers of zones the mission is authorised for (REQ_AUTHORISATION) or whose conditions
  /// it meets (CONDITIONAL). A PROHIBITED zone counts whatever this says.
  std::set<std::string> authorisations;
  bool count_conditional = true;       ///< CONDITIONAL zones without an entry above count
  bool count_no_restriction = false;   ///< NO_RESTRICTION zones count (off: they restrict nothing)
};

/// \brief Whether the zone counts under the policy as one to stay clear of (its activity in time
/// aside); a keep-in zone never does (it is checked by Obstructions::keepIn, whatever the policy).
[[nodiscard]] bool counts(const airspace::Zone& zone, const ZonePolicy& policy);

/// \brief Tunables of the check.
struct FenceOptions {
  double tolerance_m = 1e-6;      ///< a deciding margin within this of 0 is indeterminate
  double horizon_m = 100.0;       ///< zones and obstacles within this are reported with their clearance
};

/// \brief Added to a circle's radius in the map frame for the rounding of the projection [m].
inline constexpr double kCircleRounding_m = 1e-3;

/// \brief Convex pieces of the zones in the map frame, each volume's floor at its lowest and
/// ceiling at its highest over the outline (airspace::limitRange), so the pieces contain the
/// zone. Polygons: vertices projected into the frame and cut into convex pieces. Circles: a
/// disk whose radius is the zone's times the largest scale of the frame along the circle,
/// k(ρ) = (ρ/R)/sin(ρ/R) at the circle's farthest point from the origin (the azimuthal
/// equidistant projection stretches azimuthally by k and not radially; R the least radius of
/// curvature of the ellipsoid, so the disk contains the circle), plus kCircleRounding_m.
/// Keep-in zones are left out (they are not "to stay clear of"; see the README).
/// \throws std::invalid_argument naming the zone when a limit cannot be resolved (an AGL limit
/// where the terrain is unknown).
[[nodiscard]] std::vector<ScenePiece> zonePieces(const std::vector<airspace::Zone>& zones,
                                                 const maps::PlaneFrame& frame,
                                                 const airspace::VerticalModel& model);

/// \brief Convex pieces of buildings and obstacles in the map frame, between their base and top.
[[nodiscard]] std::vector<ScenePiece> obstaclePieces(const std::vector<maps::Building>& buildings,
                                                     const maps::PlaneFrame& frame);

/// \brief A protection volume at a time (or over a time interval [t0, t1)).
struct TimedVolume {
  maps::GpsTime t0;
  maps::GpsTime t1;  ///< ≤ t0: the instant t0
  ProtectionVolume volume;
};

/// \brief A list of checks filled again in place: slot k is the k-th check the list held
/// before, every member reset but its strings' storage, so that a verdict filled fix after fix
/// allocates nothing once grown — not even for identifiers and names longer than a std::string
/// keeps inline. Checks the list held beyond the ones filled wait, strings and all, in this
/// thread's spare checks for a longer list.
class CheckSlots {
 public:
  /// \brief Fills `checks` again from slot `first` on (the checks before it stay).
  explicit CheckSlots(std::vector<Check>& checks, std::size_t first = 0) : checks_(checks), used_(first) {}
  CheckSlots(const CheckSlots&) = delete;
  CheckSlots& operator=(const CheckSlots&) = delete;
  /// \brief Without finish() (an exception on the way): the list ends at the checks filled.
  ~CheckSlots();
  /// \brief The next check, reset.
  [[nodiscard]] Check& next();
  /// \brief The list ends at the checks filled; the ones after them go to the spare checks.
  void finish();
  [[nodiscard]] std::size_t size() const { return used_; }
  [[nodiscard]] std::vector<Check>& checks() { return checks_; }

 private:
  std::vector<Check>& checks_;
  std::size_t used_;
  bool finished_ = false;
};

/// \brief What a volume must stay clear of — the zones (those the policy counts, when active)
/// and the obstacles of a scene — and inside of: the active keep-in zones. Shared by the fence
/// (a protection volume) and the route planner (the vehicle inflated to its first-level box).
class Obstructions {
 public:
  /// \brief `zones` and `buildings` give names and activity to the scene's pieces (a piece's
  /// owner_index indexes them).
  /// `keep_in` (keepInVolumes of the same zones) are the volumes of the keep-in zones.
  /// \throws std::invalid_argument for a bad tolerance or horizon, or a piece or keep-in volume
  /// naming a zone or obstacle that is not there.
  Obstructions(std::vector<airspace::Zone> zones, std::vector<maps::Building> buildings, Scene scene,
               ZonePolicy policy = {}, FenceOptions options = {}, std::vector<KeepInVolume> keep_in = {});
  /// \brief One check per zone or obstacle within the options' horizon (zones first, the worst
  /// verdict first, then the nearest); zones count when active at some instant of [t0, t1).
  [[nodiscard]] std::vector<Check> check(const TimedVolume& v) const;
  /// \brief The same within `horizon_m`.
  [[nodiscard]] std::vector<Check> check(const TimedVolume& v, double horizon_m) const;
  /// \brief The same appended to `out`.
  void appendChecks(const TimedVolume& v, double horizon_m, std::vector<Check>& out) const;
  /// \brief The same into the next slots (what checkVolume fills a verdict with): no allocation
  /// once the list has grown.
  void appendChecks(const TimedVolume& v, double horizon_m, CheckSlots& slots) const;
  /// \brief The keep-in check: the volume against the union of the keep-in zones active at some
  /// instant of [t0, t1); none when no keep-in zone is active then.
  [[nodiscard]] std::optional<Check> keepIn(const TimedVolume& v) const;
  /// \brief The same into the next slot when a keep-in zone is active.
  void appendKeepIn(const TimedVolume& v, CheckSlots& slots) const;
  /// \brief The first of: the keep-in check when it is not inside (unless `with_keep_in` is
  /// false); the worst zone or obstacle the volume meets or may meet (indeterminate). None when
  /// the volume is clear of everything.
  [[nodiscard]] std::optional<Check> firstConflict(const TimedVolume& v, bool with_keep_in = true) const;
  /// \brief Whether firstConflict() finds one, without building the check: no FCL distance,
  /// no names (Scene::reachesAny). For a planner's state validity.
  [[nodiscard]] bool conflicts(const TimedVolume& v, bool with_keep_in = true) const;

  [[nodiscard]] const std::vector<airspace::Zone>& zones() const { return zones_; }
  [[nodiscard]] const std::vector<maps::Building>& buildings() const { return buildings_; }
  [[nodiscard]] const std::vector<KeepInVolume>& keepInVolumes() const { return keep_in_; }
  [[nodiscard]] const ZonePolicy& policy() const { return policy_; }
  [[nodiscard]] const FenceOptions& options() const { return options_; }
  /// \brief Whether zone i counts under the policy (its activity aside).
  [[nodiscard]] bool zoneCounts(std::size_t i) const { return zone_counts_.at(i); }

 private:
  /// The check of one scene hit (its zone's or obstacle's names, the verdict of its separation)
  /// into `c`, whose members are reset.
  void fillHitCheck(const SceneHit& h, Check& c) const;
  /// The keep-in check of margins `m` over the active zones `active` into `c` (reset).
  void fillKeepInCheck(const KeepInMargins& m, const std::vector<const KeepInVolume*>& active, Check& c) const;
  /// Whether the zone or obstacle counts for a check over [v.t0, v.t1).
  [[nodiscard]] bool takes(PieceOwner owner, std::size_t i, const TimedVolume& v) const;
  /// The keep-in zones active in [v.t0, v.t1) (into `active`) and the volume's margins in their
  /// union; none when no keep-in zone is active.
  [[nodiscard]] std::optional<KeepInMargins> keepInMarginsAt(const TimedVolume& v, std::vector<const KeepInVolume*>& active) const;
  /// The keep-in verdict of those margins (the options' tolerance).
  [[nodiscard]] Verdict keepInVerdict(const KeepInMargins& m) const;
  /// The volume a scene query takes: cut to the scene's height band when taller (none when
  /// wholly above or below it).
  [[nodiscard]] std::optional<ProtectionVolume> sceneVolume(const ProtectionVolume& given) const;

  std::vector<airspace::Zone> zones_;
  std::vector<maps::Building> buildings_;
  std::vector<bool> zone_counts_;
  /// Per zone: it has no applicability periods (always active), so a check need not read the
  /// zone itself to know (the zones are large; reading one per candidate misses the cache).
  std::vector<bool> always_active_;
  std::vector<KeepInVolume> keep_in_;
  Scene scene_;
  bool pieces_in_band_ = true;  ///< every piece within the scene's height band (volumes may be cut to it)
  ZonePolicy policy_;
  FenceOptions options_;
};

/// \brief The fence check of one volume against two box levels and the obstructions (what
/// Fence::check does; for callers that own the pieces separately, such as route approval).
[[nodiscard]] FenceVerdict checkVolume(const Corridor& level1, const Corridor& level2, const Obstructions& obstructions,
                                       const TimedVolume& v);
/// \brief The same, reporting zones and obstacles within `horizon_m` (a met one always).
[[nodiscard]] FenceVerdict checkVolume(const Corridor& level1, const Corridor& level2, const Obstructions& obstructions,
                                       const TimedVolume& v, double horizon_m);
/// \brief The same into `out`, whose storage is reused: a caller that keeps one verdict makes no
/// allocation per check once it has grown: its checks are filled again in place (CheckSlots), so
/// identifiers and names longer than std::string keeps inline need no new storage once the
/// strings have grown.
void checkVolume(const Corridor& level1, const Corridor& level2, const Obstructions& obstructions, const TimedVolume& v,
                 double horizon_m, FenceVerdict& out);

/// \brief Both box levels, the zones and the obstacles, checked together.
class Fence {
 public:
  /// \brief `zones` and `buildings` give names and activity to the scene's pieces (a piece's
  /// owner_index indexes them).
  Fence(Corridor level1, Corridor level2, std::vector<airspace::Zone> zones, std::vector<maps::Building> buildings,
        Scene scene, ZonePolicy policy = {}, FenceOptions options = {});
  /// \brief The box levels around prepared obstructions.
  Fence(Corridor level1, Corridor level2, Obstructions obstructions);

  /// \brief Checks one volume against every level; zones count when active at some instant of
  /// [t0, t1) (at t0 when t1 ≤ t0) and counted by the policy.
  [[nodiscard]] FenceVerdict check(const TimedVolume& v) const;
  /// \brief The same into `out`, its storage reused (checkVolume): for a stream of fixes.
  void check(const TimedVolume& v, FenceVerdict& out) const;
  /// \brief Checks each sample of a trajectory (predicted or flown).
  [[nodiscard]] std::vector<FenceVerdict> check(const std::vector<TimedVolume>& samples) const;

  [[nodiscard]] const Corridor& level1() const { return level1_; }
  [[nodiscard]] const Corridor& level2() const { return level2_; }
  [[nodiscard]] const std::vector<airspace::Zone>& zones() const { return obstructions_.zones(); }
  [[nodiscard]] const Obstructions& obstructions() const { return obstructions_; }

 private:
  Corridor level1_, level2_;
  Obstructions obstructions_;
};

}  // namespace skylane::geofence
