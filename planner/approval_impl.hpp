#pragma once
/// \file
/// \brief Inside the approval (an internal header of planner/, not installed): Approver::Impl —
/// the mission's map frame, terrain, zones, orbits and integrity cost field — and the state its
/// steps pass along. approval.cpp loads the mission and answers the map and integrity questions
/// (ground height, validity of a state, sky masks, predicted PLs, the cost field);
/// approval_steps.cpp holds the approval itself: Impl::run, a short list of steps, and the steps.

#include "planner/approval.hpp"
#include "planner/route_planner.hpp"

#include "geofence/corridor.hpp"
#include "geofence/fence.hpp"
#include "integrity/predict.hpp"
#include "maps/buildings.hpp"
#include "maps/geodesy.hpp"
#include "maps/sky_mask.hpp"
#include "maps/map_ground_grid.hpp"
#include "maps/plane_grid.hpp"
#include "maps/terrain.hpp"
#include "maps/time.hpp"

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace skylane::planner {

/// \brief The per-step state of an approval (see Approver::Impl::run).
namespace approval_steps {

/// \brief Calls the caller's progress callback, when there is one.
struct Say {
  const std::function<void(const std::string&)>& progress;
  void operator()(const std::string& message) const {
    if (progress) progress(message);
  }
};

/// \brief A place later attempts keep away from after a violation there: centre (map frame) and
/// radius [m].
using Penalty = std::pair<Eigen::Vector3d, double>;

/// \brief How the vehicle flies the leg to a stop and how long it stays there.
struct StopTiming {
  double speed_mps = 0.0;  ///< ground speed of the leg arriving at the stop (unused for the first)
  double hover_s = 0.0;    ///< time at the stop after arriving
};

/// \brief What every attempt of one approval shares.
struct ApprovalSetup {
  std::vector<Eigen::Vector3d> stops;     ///< map frame: the start (or the vehicle), waypoints, goal
  std::vector<StopTiming> timing;         ///< per stop
  double fastest_mps = 0.0;               ///< the fastest leg speed: the earliest the vehicle can be anywhere
  std::vector<maps::GpsTime> departures;  ///< tried in turn
  bool from_vehicle = false;              ///< a replan from where the vehicle is
  double direct_s = 0.0;                  ///< the straight legs at their speeds, and the hovers
  /// The end of the zones' activity window: the latest departure plus twice the direct flight
  /// time plus 2 min (a zone starting later cannot meet the vehicle).
  maps::GpsTime zones_until;
  Eigen::Vector3d box_lo = Eigen::Vector3d::Zero();  ///< the planner's search box (map frame)
  Eigen::Vector3d box_hi = Eigen::Vector3d::Zero();
  /// Round the vehicle (a replan) only its own point must be clear [m]; 0 for an approval.
  double exempt_m = 0.0;
};

/// \brief One attempt's route through the stops, planned leg by leg.
struct LegPlan {
  std::vector<Eigen::Vector3d> pts;  ///< start … goal when every leg is exact
  std::vector<std::size_t> stop_at;  ///< per stop reached: its index in pts
  PathResult last;                   ///< the last leg planned: the one that failed, if one did
  bool ok = true;                    ///< every leg exact
  std::size_t failed_leg = 0;        ///< when not ok: index into the stops of that leg's goal
};

/// \brief The route sampled every sample_s seconds (and at its end), with sky masks computed once.
struct RouteSamples {
  std::vector<double> t_s;  ///< after departure
  std::vector<Eigen::Vector3d> xyz;
  std::vector<maps::Geodetic> geo;
  std::vector<std::optional<maps::SkyMask>> masks;
};

/// \brief Both box levels along a route.
struct RouteCorridors {
  geofence::Corridor level1;
  geofence::Corridor level2;
};

/// \brief Reasons gathered sample by sample: one per kind and subject, kept where it is worst.
struct ReasonTally {
  std::vector<Reason> reasons;
  std::vector<int> occurrences;   ///< per reason: samples concerned
  std::vector<double> first_t_s;  ///< per reason: its first sample's time

  /// \brief Adds `reason`, placed at the sample `at`: a new kind and subject is appended; a known
  /// one counts another sample and is replaced when this one's value is larger.
  void add(Reason reason, const PredictedSample& at);
  /// \brief The reasons; one seen at several samples says how many and from when.
  [[nodiscard]] std::vector<Reason> summarised() const;
};

/// \brief What checking one route's samples found.
struct SampleChecks {
  std::vector<PredictedSample> predicted;
  ReasonTally reasons;
  int level1_exceedances = 0;     ///< samples' level-1 checks not inside
  std::vector<Penalty> violations;  ///< where the route broke a rule, to keep away from next time
};

/// \brief What one approval carries from attempt to attempt.
struct AttemptHistory {
  std::vector<Penalty> penalties;       ///< every attempt's violations so far
  std::vector<Reason> last_reasons;     ///< the last attempt's
  std::vector<RoutePoint> last_route;   ///< the last attempt's; empty when it found no route
  RouteSamples last_samples;            ///< the last route's samples
};

/// \brief How one attempt ended.
enum class AttemptOutcome {
  kApproved,    ///< every sample passed
  kViolations,  ///< some samples did not: penalise them and replan
  kNoRoute,     ///< no route (replanning cannot help): the next departure
};

}  // namespace approval_steps

struct Approver::Impl {
  Mission m;
  MissionRecord record;  ///< the mission's names and its inputs' digests when they were read
  maps::PlaneFrame frame;
  maps::PlaneGrid fix_projection{frame};  ///< the frame's projection for live fixes (maps/plane_grid.hpp)
  maps::Terrain terrain;
  /// The map frame's inverse projection over the search box, built once (maps/map_ground_grid.hpp):
  /// the ground and (lat, lon) of a state without a geodesic per state. Empty until the box is known.
  std::optional<maps::MapGroundGrid> ground_grid;
  geofence::LevelLimits limits;
  std::unique_ptr<geofence::Obstructions> obstructions;
  std::unique_ptr<maps::BuildingIndex> index;
  integrity::OrbitSource orbits;
  std::vector<Eigen::Vector3d> mission_stops;              ///< the mission's points at their heights (map frame)
  std::vector<approval_steps::StopTiming> mission_timing;  ///< per mission stop: leg speed and hover
  Eigen::Vector3d lower = Eigen::Vector3d::Zero(), upper = Eigen::Vector3d::Zero();
  // The predicted-PL grid at cruise height (mid-flight time) and the integrity cost from it.
  CostGrid cost_field;  ///< its cells (also the PL grid's); its cost empty when cost_weight is 0
  std::vector<Eigen::Vector2d> grid_pl;  ///< (HPL, VPL) per cell; NaN when unavailable
  bool cost_grid_built = false;

  /// \throws maps::ParseError naming the mission's field of a bad input.
  explicit Impl(Mission mission);
  /// Reads the mission's zone and buildings files into `obstructions` (and the buildings' index).
  void loadObstructions();

  // --- the mission's map and integrity (approval.cpp) ---

  /// Terrain height (ellipsoidal) under a map point; none outside the terrain model.
  [[nodiscard]] std::optional<double> ground(const Eigen::Vector2d& xy) const;
  [[nodiscard]] maps::Geodetic geodetic(const Eigen::Vector3d& p) const;
  /// Height band and max AMSL; then the vehicle's level-1 box clear of obstructions over [t0, t1).
  [[nodiscard]] bool valid(const Eigen::Vector3d& p, const maps::GpsTime& t0, const maps::GpsTime& t1,
                           const std::vector<approval_steps::Penalty>& penalties) const;
  [[nodiscard]] maps::SkyMask skyMaskAt(const maps::Geodetic& g) const;
  /// Whether sky masks are computed (there are buildings or a terrain raster).
  [[nodiscard]] bool masked() const;
  [[nodiscard]] integrity::PredictSample predictAt(const maps::Geodetic& g, const maps::GpsTime& t,
                                                   const std::optional<maps::SkyMask>& mask) const;
  /// max(HPL/HAL₂, VPL/VAL₂); ∞ without a PL.
  [[nodiscard]] double ratioOf(const integrity::PredictSample& s) const;
  void buildCostGrid(const maps::GpsTime& t_mid);
  /// The volume a state must keep clear: the level-1 box, grown to the PL predicted there with a
  /// 20 % allowance for its change over the flight (the samples are checked exactly afterwards).
  [[nodiscard]] geofence::ProtectionVolume planningVolume(const Eigen::Vector3d& p) const;
  /// The mission's points at their heights, with their legs' speeds and hovers (`mission_stops`,
  /// `mission_timing`); a plan item's height breaking the altitude limits is an error naming it.
  void placeStops();
  /// The ellipsoidal height of mission point `i` above ground `ground_m` (ellipsoidal).
  [[nodiscard]] double stopHeight(std::size_t i, double ground_m) const;
  /// A plan item's height against min_agl/max_agl/max_amsl at map point `xy`.
  void checkStopHeight(std::size_t i, const Eigen::Vector3d& p, double ground_m) const;
  /// ETA per point: horizontal at its leg's speed (`per_point[i].speed_mps` for the segment
  /// arriving at i), vertical at climb speed, whichever is slower; each point's hover after it.
  [[nodiscard]] std::vector<RoutePoint> timeRoute(const std::vector<Eigen::Vector3d>& pts,
                                                  const std::vector<approval_steps::StopTiming>& per_point) const;

  // --- the PLs for the mission's navigation and the levels' availability (approval_prediction.cpp) ---

  /// Every sample's place and PLs for the mission's navigation (no fence check yet).
  [[nodiscard]] std::vector<PredictedSample> predictRoute(const std::vector<RoutePoint>& route,
                                                          const approval_steps::RouteSamples& samples,
                                                          const maps::GpsTime& departure) const;
  void applyInsPrediction(const std::vector<RoutePoint>& route, const approval_steps::RouteSamples& samples,
                          const maps::GpsTime& departure, std::vector<PredictedSample>& out) const;
  /// The policy's minimum level-1 availability missed: a reason naming the worst stretch; none
  /// when it is met or the policy sets none.
  [[nodiscard]] std::optional<Reason> availabilityShortfall(const LevelAvailability& level1) const;

  // --- the approval (approval_steps.cpp) ---

  /// The approval steps of approval.hpp from `stops` (map frame; `stop_timing`: per stop, the
  /// speed of the leg to it and its hover) for each departure in turn;
  /// `from_vehicle`: a replan from where the vehicle is (no later-departure search).
  ApprovalReport run(const std::vector<Eigen::Vector3d>& stops,
                     const std::vector<approval_steps::StopTiming>& stop_timing,
                     const std::vector<maps::GpsTime>& departures, bool from_vehicle,
                     const std::function<void(const std::string&)>& progress);

  [[nodiscard]] approval_steps::ApprovalSetup boundFlightTime(const std::vector<Eigen::Vector3d>& stops,
                                                              const std::vector<approval_steps::StopTiming>& stop_timing,
                                                              const std::vector<maps::GpsTime>& departures,
                                                              bool from_vehicle) const;
  /// Per point of a leg plan: the speed of the segment arriving there and, at a stop, its hover.
  [[nodiscard]] std::vector<approval_steps::StopTiming> pointTiming(const approval_steps::ApprovalSetup& setup,
                                                                    const approval_steps::LegPlan& plan) const;
  void ensureCostField(const approval_steps::ApprovalSetup& setup, const approval_steps::Say& say);
  void fitSearchBox(approval_steps::ApprovalSetup& setup) const;
  bool tryDeparture(const approval_steps::ApprovalSetup& setup, const maps::GpsTime& departure,
                    approval_steps::AttemptHistory& history, ApprovalReport& report, const approval_steps::Say& say) const;
  approval_steps::AttemptOutcome attemptRoute(const approval_steps::ApprovalSetup& setup, const maps::GpsTime& departure,
                                              int attempt, approval_steps::AttemptHistory& history, ApprovalReport& report,
                                              const approval_steps::Say& say) const;
  [[nodiscard]] approval_steps::LegPlan planLegs(const approval_steps::ApprovalSetup& setup, const maps::GpsTime& departure,
                                                 int attempt, const std::vector<approval_steps::Penalty>& penalties,
                                                 PlannerStats& stats) const;
  [[nodiscard]] PathProblem legProblem(const approval_steps::ApprovalSetup& setup, const maps::GpsTime& departure,
                                       int attempt, std::size_t leg, const Eigen::Vector3d& from,
                                       const std::vector<approval_steps::Penalty>& penalties) const;
  void unflyableCause(const Eigen::Vector3d& p, const maps::GpsTime& from, const maps::GpsTime& until,
                      const std::string& what, Reason& r) const;
  [[nodiscard]] std::string legBlockers(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const maps::GpsTime& t0,
                                        const maps::GpsTime& t1) const;
  [[nodiscard]] std::string conflictCause(const geofence::Check& c, const geofence::TimedVolume& point,
                                          const geofence::ProtectionVolume& pv) const;
  [[nodiscard]] Reason planningReason(const approval_steps::ApprovalSetup& setup, const maps::GpsTime& departure,
                                      const approval_steps::LegPlan& plan, const std::string& status) const;
  [[nodiscard]] approval_steps::RouteSamples sampleRoute(const std::vector<RoutePoint>& route,
                                                         const approval_steps::Say& say) const;
  [[nodiscard]] approval_steps::RouteCorridors corridorsAlong(const std::vector<Eigen::Vector3d>& pts) const;
  [[nodiscard]] approval_steps::SampleChecks checkSamples(const approval_steps::ApprovalSetup& setup,
                                                          const maps::GpsTime& departure,
                                                          const std::vector<Eigen::Vector3d>& pts,
                                                          std::vector<PredictedSample> predicted,
                                                          std::vector<ZoneApproach>& zones) const;
  [[nodiscard]] PredictedSample predictSample(const approval_steps::RouteSamples& samples, std::size_t k,
                                              const maps::GpsTime& t) const;
  [[nodiscard]] geofence::FenceVerdict checkFence(const approval_steps::ApprovalSetup& setup,
                                                  const approval_steps::RouteCorridors& corridors, const maps::GpsTime& t,
                                                  const PredictedSample& ps, approval_steps::SampleChecks& checks,
                                                  std::vector<ZoneApproach>& zones) const;
  void noteZoneApproach(const geofence::Check& c, std::vector<ZoneApproach>& zones) const;
  [[nodiscard]] std::optional<maps::GpsTime> searchLaterDeparture(const maps::GpsTime& departure,
                                                                  const approval_steps::AttemptHistory& history) const;
  [[nodiscard]] bool routePassesAt(const maps::GpsTime& departure, const approval_steps::RouteCorridors& corridors,
                                   const std::vector<RoutePoint>& route, const approval_steps::RouteSamples& samples) const;
};

}  // namespace skylane::planner
