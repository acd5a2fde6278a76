#pragma once
/// \file
/// \brief Preflight route approval (`skylane approve`): plan a route around the zones active
/// when the vehicle gets there, wrap it in the corridor (level 1) and airspace (level 2) boxes,
/// predict HPL/VPL along it at each point's arrival time, check every sample with the fence,
/// and approve it or reject it with reasons.
///
/// Steps, per departure time (the fixed one, or each step of the window in turn):
/// 1. Plan in the mission's map frame (x, y of the azimuthal-equidistant plane at the start,
///    z = ellipsoidal height) with OMPL. A state is valid when its height above the terrain is
///    within [min_agl, max_agl] (and below max_amsl) and the vehicle, inflated to its level-1
///    box (a cylinder of radius HAL₁ and half-height VAL₁) or, where larger, to 1.2 × the
///    protection levels predicted there (a grid at cruise height, mid-flight; the margin allows
///    for their change over the flight), is clear of the buildings and of
///    every counted zone active at some instant the vehicle could be there: from the earliest
///    departure plus the straight-line flight time to the state, to the latest departure plus
///    twice the direct route's flight time plus 2 min (so zones that expire before the vehicle
///    can arrive, or start after it must have landed, are ignored). The integrity cost is
///    w·φ(r), r = max(HPL/HAL₂, VPL/VAL₂) predicted on a grid at cruise height (sky mask from
///    buildings and terrain at each cell), φ(r) = (r/(1 − r))² for r < 0.99 and 10⁴ beyond
///    (an unavailable PL counts as r = ∞).
/// 2. Time the route (ETA per point: horizontal distance at the leg's speed — cruise, or a
///    plan's DO_CHANGE_SPEED — height change at climb speed, whichever takes longer; a stop's
///    hover delays every later ETA) and build both box levels along it. The stops are at their
///    own heights (a plan's items), else at cruise height; legs climb or descend between them.
/// 3. Every `sample_s` seconds of flight, and where each hover starts and ends: the position
///    (held at a stop while it hovers), its sky mask, the predicted PLs with the mission's
///    method, and the fence check of the protection volume at that time.
///    The PLs are those of the mission's navigation (Mission::navigation): GNSS alone (RAIM or
///    ARAIM per sample), GNSS/INS (the tracker's filter run along the route, see
///    planner/ins_pl_prediction.hpp) or a receiver's declared constants.
/// 4. Approved when every sample has a PL and its protection volume is inside level 2 and clear
///    of the zones and the obstacles, and the level-1 availability (the fraction of samples with
///    HPL ≤ HAL₁ and VPL ≤ VAL₁) meets the policy's minimum when it sets one. Otherwise level-1
///    exceedances are reported, with each level's availability and worst stretch: in flight they
///    trigger a monitoring rerun, not a rejection.
/// 5. Otherwise the violating places are penalised (no state within a protection level of a
///    violation, plus the level-1 box, is valid) and the route replanned, up to `max_replans`
///    times; then the next departure of the window. A rejection names where, when and why, and
///    (for a fixed departure) the earliest departure within 24 h at which the same route passes.

#include "planner/mission.hpp"

#include "geofence/corridor.hpp"
#include "geofence/fence.hpp"
#include "integrity/gnss/orbit_source.hpp"
#include "maps/plane_frame.hpp"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace skylane::maps {
class PlaneGrid;
}  // namespace skylane::maps

namespace skylane::planner {

/// \brief One route point.
struct RoutePoint {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  ///< map frame x, y [m] and ellipsoidal height [m]
  double lat_rad = 0.0, lon_rad = 0.0, h_ell_m = 0.0, alt_amsl_m = 0.0;
  double eta_s = 0.0;    ///< arrival, seconds after departure
  double hover_s = 0.0;  ///< the vehicle stays here this long after arriving, then leaves
};

/// \brief Where a timed route is t seconds after departure (map frame): held at a point from its
/// ETA until its hover ends, linear from there to the next point's ETA, held at the ends.
[[nodiscard]] Eigen::Vector3d positionAlong(const std::vector<RoutePoint>& route, double t_s);

/// \brief One prediction sample along the route.
struct PredictedSample {
  double t_s = 0.0;  ///< after departure
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  double lat_rad = 0.0, lon_rad = 0.0, h_ell_m = 0.0;
  bool pl_available = false;
  double hpl_m = 0.0, vpl_m = 0.0;
  int satellites = 0;
  int blocked = 0;  ///< satellites above the mask hidden by buildings or terrain
  /// GNSS/INS: the three-hypothesis INS PL of the same filter beside the fault-mode PL above
  /// (which is the one the tracker flies with and the one checked); none for the other kinds.
  std::optional<double> three_hypothesis_hpl_m, three_hypothesis_vpl_m;
  geofence::FenceVerdict fence;
};

/// \brief The longest run of consecutive route samples whose PLs exceed a level's limits.
struct FailingStretch {
  double t_start_s = 0.0, t_end_s = 0.0;  ///< its first and last failing sample, after departure
  double lat_start_rad = 0.0, lon_start_rad = 0.0;
  double lat_end_rad = 0.0, lon_end_rad = 0.0;
  int samples = 0;
  /// \brief From its first to its last failing sample [s] (0 for a single sample).
  [[nodiscard]] double duration_s() const { return t_end_s - t_start_s; }
};

/// \brief How much of the route one box level holds: a sample holds it when it has PLs and
/// HPL ≤ HAL and VPL ≤ VAL (a sample without PLs does not).
struct LevelAvailability {
  geofence::AlertLimits limits;
  int samples = 0;
  int held = 0;
  double fraction = 0.0;  ///< held / samples; 0 without samples
  std::optional<FailingStretch> worst_stretch;  ///< none when every sample holds
};

/// \brief The availability of `limits` over `samples` (in time order).
[[nodiscard]] LevelAvailability levelAvailability(const std::vector<PredictedSample>& samples,
                                                  const geofence::AlertLimits& limits);

/// \brief Why a route was refused.
struct Reason {
  std::string kind;     ///< "zone", "obstacle", "airspace", "integrity", "planning"
  std::string subject;  ///< zone identifier, building, "HPL"/"VPL", planner status
  std::string message;  ///< one sentence a person can act on
  std::optional<double> t_s;  ///< after departure
  std::optional<double> lat_rad, lon_rad, h_ell_m;
  std::optional<double> value_m, limit_m;  ///< e.g. HPL and HAL₂, or the overlap with a zone
};

/// \brief The nearest approach to a zone over the flight.
struct ZoneApproach {
  std::string identifier;
  std::string restriction;
  bool counted = false;       ///< the policy counts it (PROHIBITED, or not authorised)
  double min_clearance_m = 0.0;  ///< of the protection volume; 0 when met
};

/// \brief Planner statistics of the accepted (or last) attempt.
struct PlannerStats {
  std::string algorithm;
  std::string status;
  bool straight_line = false;
  double planning_time_s = 0.0;
  double length_m = 0.0;
  int attempts = 0;          ///< plans made in all
  std::uint64_t iterations = 0;  ///< planner iterations in all
  bool stopped_by_time = false;  ///< some search ended at the time limit (then not reproducible)
  int departures_tried = 0;
  /// Legs whose OMPL search found no exact path and that searched the lattice seed (or all legs,
  /// with the "lattice" algorithm); legs whose route is the refined seed.
  int lattice_legs_searched = 0, lattice_legs_seeded = 0;
  std::uint64_t lattice_state_checks = 0;  ///< in all
  double lattice_step_m = 0.0;             ///< of the last leg that searched the lattice
};

/// \brief One input file of an approval and its SHA-256 when the approver read it.
struct InputDigest {
  std::string role;  ///< "mission", "zones", "buildings", "terrain", "orbits"
  std::string file;
  std::string sha256;
};

/// \brief What a report says of its mission, so that the report stands alone: the approval can
/// be audited and replayed against exactly these files.
struct MissionRecord {
  std::string name;
  std::string source;           ///< the mission file as given
  std::string source_absolute;  ///< its absolute path (for a tracker started elsewhere)
  double k1 = 0.0, k2 = 0.0;    ///< the box levels' factors
  NavigationModel navigation;   ///< how the PLs were predicted
  MissionPolicy policy;
  std::uint64_t seed = 0;       ///< the planner's seed
  std::vector<InputDigest> inputs;
};

/// \brief The record of a mission: its names, factors, seed and every input file's digest.
[[nodiscard]] MissionRecord missionRecord(const Mission& m);

/// \brief The outcome of an approval.
struct ApprovalReport {
  MissionRecord mission;
  bool approved = false;
  std::vector<Reason> reasons;
  maps::GpsTime departure;
  std::vector<RoutePoint> route;
  geofence::LevelLimits limits;
  std::vector<PredictedSample> predicted;
  std::vector<ZoneApproach> zones;
  PlannerStats planner;
  int level1_exceedances = 0;  ///< samples whose level-1 fence check was not inside (kept for compatibility)
  LevelAvailability level1_availability;  ///< of the report's route (HAL₁, VAL₁)
  LevelAvailability level2_availability;  ///< (HAL₂, VAL₂)
  std::optional<maps::GpsTime> earliest_passing_departure;
  double elapsed_s = 0.0;
  /// Findings that do not decide the approval but that its reader must see: an orbit file
  /// older than its warning limit at the departure (integrity/gnss/orbit_age.hpp).
  std::vector<std::string> warnings;
};

/// \brief Loads the mission's files once and approves (or rejects) it.
class Approver {
 public:
  /// \throws maps::ParseError naming the file and field of a bad input, or a route point the
  /// terrain does not cover, or a plan item whose height breaks the altitude limits.
  explicit Approver(Mission mission);
  ~Approver();
  Approver(const Approver&) = delete;
  Approver& operator=(const Approver&) = delete;

  /// \brief Runs the whole approval; `progress(message)` is called at each step. First checks
  /// the orbit files' ages at the departure (each end of a window): past the warning limit the
  /// report carries a warning; past the error limit nothing is planned.
  /// \throws maps::ParseError naming the orbit file, its epoch, the departure, the age and the
  /// limit when a file is older than its error limit (integrity/gnss/orbit_age.hpp).
  [[nodiscard]] ApprovalReport approve(const std::function<void(const std::string&)>& progress = {});

  /// \brief A new route from where the vehicle is (map frame: x, y, ellipsoidal height) through
  /// the mission's remaining points from `next_stop` (index into Mission::points, ≥ 1) to the goal,
  /// departing `now`: the same steps as approve() for one departure. Within max(10 m, 2 × the
  /// planning volume) of the vehicle only its own point must be clear of zones and obstacles, and
  /// samples there give no zone or obstacle reason (the route leads the vehicle out). Reuses the
  /// cost field of an earlier approve() or replan.
  /// \throws std::invalid_argument for a non-finite position or a next_stop out of range.
  [[nodiscard]] ApprovalReport replanFrom(const Eigen::Vector3d& p_map, const maps::GpsTime& now, std::size_t next_stop,
                                          const std::function<void(const std::string&)>& progress = {});
  /// \brief The mission's points (map frame) at their heights: a plan item's own (converted
  /// with the terrain and the geoid, checked against the altitude limits when the Approver was
  /// made), else cruise height above the terrain.
  [[nodiscard]] std::vector<Eigen::Vector3d> missionStops() const;
  /// \brief The terrain's ellipsoidal height under a map point; none outside the terrain model.
  [[nodiscard]] std::optional<double> groundHeight(const Eigen::Vector2d& xy_map) const;

  [[nodiscard]] const Mission& mission() const;
  /// \brief The mission's map frame (origin at the start).
  [[nodiscard]] const maps::PlaneFrame& frame() const;
  /// \brief The map frame's projection for a stream of fixes: interpolated, within 1e-8 m of
  /// frame().toPlane and about ten times faster (maps/plane_grid.hpp).
  [[nodiscard]] const maps::PlaneGrid& fixProjection() const;
  /// \brief The mission's orbit files (for live PLs from raw pseudoranges).
  [[nodiscard]] const integrity::OrbitSource& orbits() const;
  /// \brief The zones and obstacles loaded from the mission's files.
  [[nodiscard]] const geofence::Obstructions& obstructions() const;
  /// \brief Reads the mission's zone and buildings files again (a zone set's new version written
  /// over its file): checks and replans from now on use them.
  /// \throws maps::ParseError naming a bad file; the zones read before stay.
  void reloadZones();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace skylane::planner
