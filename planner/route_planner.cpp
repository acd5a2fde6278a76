#include "planner/route_planner.hpp"

#include "maps/module_loader.hpp"
#include "planner/lattice_search.hpp"
#include "planner/ompl_module.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>

#ifndef SKYLANE_OMPL_MODULE_BUILD_PATH
// CMake defines both for skylane_planner: the module in the build tree and where it is installed.
#define SKYLANE_OMPL_MODULE_BUILD_PATH ""
#define SKYLANE_OMPL_MODULE_INSTALL_PATH ""
#endif

namespace skylane::planner {

std::string_view plannerName(PlannerKind k) {
  switch (k) {
    case PlannerKind::kRrtStar: return "rrtstar";
    case PlannerKind::kInformedRrtStar: return "informed_rrtstar";
    case PlannerKind::kBitStar: return "bitstar";
    case PlannerKind::kPrmStar: return "prmstar";
    case PlannerKind::kLattice: return "lattice";
  }
  return "?";
}

std::optional<PlannerKind> parsePlannerKind(std::string_view name) {
  for (PlannerKind k : {PlannerKind::kRrtStar, PlannerKind::kInformedRrtStar, PlannerKind::kBitStar, PlannerKind::kPrmStar,
                        PlannerKind::kLattice}) {
    if (plannerName(k) == name) return k;
  }
  return std::nullopt;
}

std::string_view pathStatusName(PathStatus s) {
  switch (s) {
    case PathStatus::kExact: return "exact";
    case PathStatus::kApproximate: return "approximate";
    case PathStatus::kNoSolution: return "no_solution";
    case PathStatus::kInvalidStart: return "invalid_start";
    case PathStatus::kInvalidGoal: return "invalid_goal";
  }
  return "?";
}

double polylineLength(const std::vector<Eigen::Vector3d>& points) {
  double len = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) len += (points[i] - points[i - 1]).norm();
  return len;
}

namespace {

void checkProblem(const PathProblem& p) {
  if (!p.is_valid) throw std::invalid_argument("planPath: a state validity predicate is required");
  if (!(p.resolution_m > 0.0) || !std::isfinite(p.resolution_m)) {
    throw std::invalid_argument("planPath: the motion resolution must be a positive number of metres");
  }
  if (!((p.upper_enu_m - p.lower_enu_m).minCoeff() > 0.0)) {
    throw std::invalid_argument("planPath: the search box is empty (upper ≤ lower on some axis)");
  }
  if (!(p.time_limit_s > 0.0)) throw std::invalid_argument("planPath: the time limit must be > 0 s");
}

/// kInvalidStart or kInvalidGoal when that end is outside the box or not valid; nothing when
/// both are fine.
std::optional<PathStatus> invalidEnd(const PathProblem& p) {
  auto inside = [&](const Eigen::Vector3d& x) {
    return (x.array() >= p.lower_enu_m.array()).all() && (x.array() <= p.upper_enu_m.array()).all();
  };
  if (!inside(p.start_enu_m) || !p.is_valid(p.start_enu_m)) return PathStatus::kInvalidStart;
  if (!inside(p.goal_enu_m) || !p.is_valid(p.goal_enu_m)) return PathStatus::kInvalidGoal;
  return std::nullopt;
}

/// The OMPL module's entry points (libskylane_ompl.so, planner/ompl_module.cpp), loaded on the
/// first route that is not a straight line.
const detail::OmplModule& omplModule() {
  static const detail::OmplModule& module = [] () -> const detail::OmplModule& {
    const maps::detail::ModuleSpec spec{detail::kOmplModuleFile, "SKYLANE_OMPL_MODULE", "skylane_ompl_module_v3",
                                        SKYLANE_OMPL_MODULE_BUILD_PATH, SKYLANE_OMPL_MODULE_INSTALL_PATH,
                                        "planning a route around obstacles"};
    static_assert(detail::kOmplModuleAbi == 3, "rename the entry point with the ABI version");
    return maps::detail::moduleTable<detail::OmplModule>(spec);
  }();
  return module;
}

/// Every motion of `points` valid, checked every resolution_m (the route is taken only then).
bool everyMotionValid(const PathProblem& p, const std::vector<Eigen::Vector3d>& points) {
  for (std::size_t i = 1; i < points.size(); ++i) {
    if (!motionIsValid(p, points[i - 1], points[i])) return false;
  }
  return points.size() >= 2;
}

/// The path's cost under the problem's objective (OMPL's: length, or ∫ (1 + extra cost) ds).
double objectiveCost(const PathProblem& p, const std::vector<Eigen::Vector3d>& points) {
  if (!p.extra_cost) return polylineLength(points);
  double cost = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) cost += p.extra_cost->motionCost(points[i - 1], points[i], p.cost_step_m);
  return cost;
}

/// The lattice seed (planner/lattice_search.hpp), refined by OMPL and checked again: the refined
/// path when every motion of it is valid, else the seed itself (checked the same way).
void planFromLatticeSeed(const PathProblem& p, PathResult& out) {
  LatticeOptions options;
  options.time_limit_s = p.time_limit_s;
  const LatticeResult seed = latticeSearch(p, options);
  out.lattice_searched = true;
  out.lattice_step_m = seed.step_m;
  out.lattice_state_checks = seed.state_checks;
  out.lattice_budget_spent = seed.stopped_by_budget;
  out.lattice_time_s = seed.time_s;
  out.planning_time_s += seed.time_s;
  out.stopped_by_time = out.stopped_by_time || seed.stopped_by_time;
  if (!seed.found) return;
  // The first that passes the check: the refined seed with its straight runs merged (fewer
  // vertices for the simplifier), the refined seed as searched, the seed itself.
  std::optional<PathResult> taken;
  for (const std::vector<Eigen::Vector3d>& start : {withoutCollinearVertices(seed.points), seed.points}) {
    PathResult refined;
    omplModule().refine(p, start, refined);
    out.simplify_time_s += refined.simplify_time_s;
    if (everyMotionValid(p, refined.points)) {
      taken = std::move(refined);
      break;
    }
  }
  if (!taken && everyMotionValid(p, seed.points)) {
    taken.emplace();
    taken->points = seed.points;
    taken->cost = objectiveCost(p, seed.points);
  }
  if (!taken) return;
  out.points = std::move(taken->points);
  out.cost = taken->cost;
  out.status = PathStatus::kExact;
  out.lattice_seed = true;
}

}  // namespace

PathResult planPath(const PathProblem& p) {
  checkProblem(p);
  PathResult out;
  out.planner = std::string(plannerName(p.planner));
  if (const std::optional<PathStatus> invalid = invalidEnd(p)) {
    out.status = *invalid;
    return out;
  }
  if (!p.extra_cost && motionIsValid(p, p.start_enu_m, p.goal_enu_m)) {
    out.status = PathStatus::kExact;
    out.points = {p.start_enu_m, p.goal_enu_m};
    out.length_m = out.cost = polylineLength(out.points);
    out.straight_line = true;
    return out;
  }
  if (p.planner != PlannerKind::kLattice) {
    omplModule().plan(p, out);
  } else {
    out.status = PathStatus::kNoSolution;
  }
  if (out.status != PathStatus::kExact && (p.lattice_fallback || p.planner == PlannerKind::kLattice)) {
    planFromLatticeSeed(p, out);
  }
  out.length_m = polylineLength(out.points);
  return out;
}

}  // namespace skylane::planner
