#pragma once
/// \file
/// \brief Inside the approval (an internal header of planner/, not installed): Approver::Impl —
/// the mission's map frame, terrain, zones, orbits and integrity cost field. approval.cpp loads
/// the mission, answers the map and integrity questions (ground height, validity of a state, sky
/// masks, predicted PLs, the cost field) and runs the approval (Impl::run).

#include "planner/approval.hpp"
#include "planner/route_planner.hpp"

#include "geofence/corridor.hpp"
#include "geofence/fence.hpp"
#include "integrity/predict.hpp"
#include "maps/buildings.hpp"
#include "maps/geodesy.hpp"
#include "maps/sky_mask.hpp"
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

/// \brief A place later attempts keep away from after a violation there: centre (map frame) and
/// radius [m].
using Penalty = std::pair<Eigen::Vector3d, double>;

/// \brief The route sampled every sample_s seconds (and at its end), with sky masks computed once.
struct RouteSamples {
  std::vector<double> t_s;  ///< after departure
  std::vector<Eigen::Vector3d> xyz;
  std::vector<maps::Geodetic> geo;
  std::vector<std::optional<maps::SkyMask>> masks;
};

}  // namespace approval_steps

struct Approver::Impl {
  Mission m;
  maps::PlaneFrame frame;
  maps::Terrain terrain;
  geofence::LevelLimits limits;
  std::unique_ptr<geofence::Obstructions> obstructions;
  std::unique_ptr<maps::BuildingIndex> index;
  integrity::OrbitSource orbits;
  Eigen::Vector3d lower = Eigen::Vector3d::Zero(), upper = Eigen::Vector3d::Zero();
  // The predicted-PL grid at cruise height (mid-flight time) and the integrity cost from it.
  double cell_m = 50.0;
  int cols = 0, rows = 0;
  std::vector<double> cost;
  std::vector<Eigen::Vector2d> grid_pl;  ///< (HPL, VPL) per cell; NaN when unavailable
  bool cost_grid_built = false;

  /// \throws maps::ParseError naming the mission's field of a bad input.
  explicit Impl(Mission mission);

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
  [[nodiscard]] std::size_t cellOf(const Eigen::Vector3d& p) const;
  /// The volume a state must keep clear: the level-1 box, grown to the PL predicted there with a
  /// 20 % allowance for its change over the flight (the samples are checked exactly afterwards).
  [[nodiscard]] geofence::ProtectionVolume planningVolume(const Eigen::Vector3d& p) const;
  [[nodiscard]] double extraCost(const Eigen::Vector3d& p) const;
  /// ETA per point: horizontal at cruise speed, vertical at climb speed, whichever is slower.
  [[nodiscard]] std::vector<RoutePoint> timeRoute(const std::vector<Eigen::Vector3d>& pts) const;

  // --- the approval ---

  /// The approval steps of approval.hpp from `stops` (map frame) for each departure in turn;
  /// `from_vehicle`: a replan from where the vehicle is (no later-departure search).
  ApprovalReport run(const std::vector<Eigen::Vector3d>& stops, const std::vector<maps::GpsTime>& departures,
                     bool from_vehicle, const std::function<void(const std::string&)>& progress);
};

}  // namespace skylane::planner
