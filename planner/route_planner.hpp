#pragma once
/// \file
/// \brief Geometric route planning in the local ENU frame with OMPL (I. A. Şucan, M. Moll and
/// L. E. Kavraki, "The Open Motion Planning Library", IEEE Robotics & Automation Magazine 19(4),
/// 2012, doi:10.1109/MRA.2012.2205651). OMPL stays inside route_planner.cpp.
///
/// The state space is R³ bounded by the operating limits. A state is valid when the caller's
/// predicate says so (the vehicle inflated to its first-level box clear of the zones and
/// obstacles, above the terrain); a motion is checked every `resolution_m` metres (not OMPL's
/// default fraction of the space's extent). The objective is the path integral of
/// 1 + extra_cost(p) (trapezoid rule every cost_step_m metres): path length when the
/// extra cost is zero, longer paths preferred where the predicted protection level nears the
/// alert limit. Simplification keeps validity: OMPL's PathSimplifier only accepts shortcuts
/// whose motions are valid.
///
/// Planners: RRT* (Karaman & Frazzoli, IJRR 30(7), 2011), Informed RRT* (Gammell, Srinivasa &
/// Barfoot, IROS 2014), BIT* (Gammell, Srinivasa & Barfoot, ICRA 2015), PRM* (Karaman &
/// Frazzoli 2011). A seed makes a run reproducible when the iteration budget, not the time
/// limit, ends the search (OMPL's seed generator is re-seeded before each query). PRM* grows its
/// roadmap in a second thread, so its result can still vary between runs.
///
/// Clutter (planner/lattice_search.hpp): when the OMPL search ends without an exact path, a
/// lattice seed is searched (weighted A*, coarse to fine), refined by OMPL's PathSimplifier under
/// the same objective, and every motion of the result is checked again every resolution_m before
/// it is taken. PlannerKind::kLattice goes to the lattice seed at once.

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skylane::planner {

/// \brief The OMPL planners offered.
enum class PlannerKind { kRrtStar, kInformedRrtStar, kBitStar, kPrmStar, kLattice };

/// \brief "rrtstar", "informed_rrtstar", "bitstar", "prmstar", "lattice".
[[nodiscard]] std::string_view plannerName(PlannerKind k);
/// \brief Parses a planner name; std::nullopt when unknown.
[[nodiscard]] std::optional<PlannerKind> parsePlannerKind(std::string_view name);

/// \brief A cost per metre on square cells over x–y, row by row from `lower`; a point beyond
/// the grid takes its nearest cell's. Inline: the planner reads it at every step of every motion.
struct CostGrid {
  Eigen::Vector2d lower = Eigen::Vector2d::Zero();
  double cell_m = 1.0;
  int cols = 1, rows = 1;
  std::vector<double> cost;  ///< cols × rows, ≥ 0

  [[nodiscard]] std::size_t cellOf(const Eigen::Vector3d& p) const {
    const int c = std::clamp(static_cast<int>((p.x() - lower.x()) / cell_m), 0, cols - 1);
    const int r = std::clamp(static_cast<int>((p.y() - lower.y()) / cell_m), 0, rows - 1);
    return static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c);
  }
  [[nodiscard]] double at(const Eigen::Vector3d& p) const { return cost[cellOf(p)]; }
  /// ∫ (1 + cost) ds along the motion a → b by the trapezoid rule over steps of at most step_m:
  /// the planner's objective for one motion.
  [[nodiscard]] double motionCost(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double step_m) const {
    const double len = (b - a).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(len / step_m)));
    double sum = 0.5 * (at(a) + at(b));
    for (int i = 1; i < n; ++i) sum += at(a + (b - a) * (static_cast<double>(i) / n));
    return len * (1.0 + sum / n);
  }
};

/// \brief One planning query.
struct PathProblem {
  Eigen::Vector3d lower_enu_m = Eigen::Vector3d::Zero();  ///< bounds of the search box
  Eigen::Vector3d upper_enu_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d start_enu_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d goal_enu_m = Eigen::Vector3d::Zero();
  std::function<bool(const Eigen::Vector3d&)> is_valid;   ///< required
  const CostGrid* extra_cost = nullptr;  ///< ≥ 0 per metre (the caller keeps it); none = path length
  double cost_step_m = 25.0;   ///< the cost integral's step along a motion (trapezoid rule)
  double resolution_m = 2.0;   ///< motion checking step
  double time_limit_s = 30.0;  ///< a safety net: the iteration budget should end the search
  /// \brief The search ends after this many checks of the planner's termination condition
  /// (about one per iteration): the same seed then gives the same route whatever the machine's
  /// load. When the time limit ends the search first, the route depends on the speed.
  std::uint64_t max_iterations = 3000;
  std::uint64_t seed = 1;
  PlannerKind planner = PlannerKind::kRrtStar;
  bool simplify = true;
  /// \brief Stop as soon as a path is found whose cost is within this factor of the straight
  /// line's length (1 = run to the time limit unless the straight line itself is valid).
  double good_enough_factor = 1.0;
  /// \brief When the OMPL search ends without an exact path, search the lattice seed
  /// (planner/lattice_search.hpp) and refine it; kLattice searches it at once.
  bool lattice_fallback = true;
};

/// \brief How the query ended (OMPL's PlannerStatus, in skylane's words).
enum class PathStatus { kExact, kApproximate, kNoSolution, kInvalidStart, kInvalidGoal };
/// \brief "exact", "approximate", "no_solution", "invalid_start", "invalid_goal".
[[nodiscard]] std::string_view pathStatusName(PathStatus s);

/// \brief The result.
struct PathResult {
  PathStatus status = PathStatus::kNoSolution;
  std::vector<Eigen::Vector3d> points;  ///< start … goal (exact), or start … nearest (approximate)
  double length_m = 0.0;
  double cost = 0.0;                    ///< objective value (= length when no extra cost)
  double planning_time_s = 0.0;
  double simplify_time_s = 0.0;
  std::uint64_t iterations = 0;         ///< termination checks made
  bool stopped_by_time = false;         ///< the time limit ended the search (not reproducible)
  std::string planner;
  bool straight_line = false;           ///< the direct segment was valid and taken without search
  /// \brief The lattice seed was searched (the OMPL search found no exact path, or kLattice).
  bool lattice_searched = false;
  bool lattice_seed = false;            ///< the route is the refined lattice seed
  double lattice_step_m = 0.0;          ///< the step of the lattice that found it (else the finest searched)
  std::uint64_t lattice_state_checks = 0;  ///< validity checks the lattice search made
  bool lattice_budget_spent = false;       ///< the lattice search ended on its check budget
  double lattice_time_s = 0.0;
};

/// \brief Plans one path. The straight segment is tried first (it is optimal when valid).
/// \throws std::invalid_argument for empty bounds, a missing predicate or a bad resolution.
[[nodiscard]] PathResult planPath(const PathProblem& problem);

/// \brief Length of a polyline [m].
[[nodiscard]] double polylineLength(const std::vector<Eigen::Vector3d>& points);

}  // namespace skylane::planner
