/// \file
/// \brief libskylane_ompl.so: the OMPL search of planPath (planner/route_planner.hpp), loaded with
/// dlopen on the first route that is not a straight line (the only file of skylane that
/// includes OMPL; see planner/ompl_module.hpp).

#include "planner/ompl_module.hpp"

#include <ompl/base/Planner.h>
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/objectives/StateCostIntegralObjective.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/informedtrees/BITstar.h>
#include <ompl/geometric/planners/prm/PRMstar.h>
#include <ompl/geometric/planners/rrt/InformedRRTstar.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>
#include <ompl/util/Time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>

namespace skylane::planner::detail {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

Eigen::Vector3d toVector(const ob::State* s) {
  const auto* r = s->as<ob::RealVectorStateSpace::StateType>();
  return {r->values[0], r->values[1], r->values[2]};
}

/// ∫ (1 + extra_cost) ds along the path; Euclidean distance is an admissible heuristic.
class IntegrityCostObjective : public ob::StateCostIntegralObjective {
 public:
  IntegrityCostObjective(const ob::SpaceInformationPtr& si, const CostGrid& extra, double step_m)
      : ob::StateCostIntegralObjective(si, false), extra_(extra), step_m_(step_m) {
    description_ = "path length + integrity cost";
  }
  ob::Cost stateCost(const ob::State* s) const override { return ob::Cost(1.0 + extra_.at(toVector(s))); }
  /// Trapezoid rule over steps of at most step_m (the cost field's own resolution), rather than
  /// OMPL's validity-checking resolution, which would evaluate it every few metres.
  ob::Cost motionCost(const ob::State* s1, const ob::State* s2) const override {
    return ob::Cost(extra_.motionCost(toVector(s1), toVector(s2), step_m_));
  }
  ob::Cost motionCostHeuristic(const ob::State* s1, const ob::State* s2) const override {
    return ob::Cost(si_->distance(s1, s2));
  }

 private:
  const CostGrid& extra_;  ///< the caller's, alive for the query
  double step_m_;
};

/// OMPL's seed generator is process-wide; one query at a time re-seeds it so that a seed gives
/// the same route whatever ran before (OMPL logs an error when re-seeding after first use; its
/// generator is re-seeded all the same — see ompl/util/RandomNumbers.cpp).
std::mutex& omplMutex() {
  static std::mutex m;
  return m;
}

/// The search box as an OMPL state space.
std::shared_ptr<ob::RealVectorStateSpace> searchSpace(const PathProblem& p) {
  auto space = std::make_shared<ob::RealVectorStateSpace>(3);
  ob::RealVectorBounds bounds(3);
  for (int i = 0; i < 3; ++i) {
    bounds.setLow(i, p.lower_enu_m[i]);
    bounds.setHigh(i, p.upper_enu_m[i]);
  }
  space->setBounds(bounds);
  return space;
}

/// One OMPL query at a time, quiet, with OMPL's process-wide generator seeded from the problem.
class OmplQueryScope {
 public:
  explicit OmplQueryScope(const PathProblem& p) {
    ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
    ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(p.seed % 4294967291ULL + 1));
  }

 private:
  std::lock_guard<std::mutex> lock_{omplMutex()};  // taken before the constructor's body
};

/// The problem's validity checker, and motions checked every resolution_m metres (OMPL takes it
/// as a fraction of the extent).
void setValidity(ob::SpaceInformation& si, const ob::StateSpacePtr& space, const PathProblem& p) {
  si.setStateValidityChecker([&p](const ob::State* s) { return p.is_valid(toVector(s)); });
  si.setStateValidityCheckingResolution(std::min(1.0, p.resolution_m / space->getMaximumExtent()));
}

/// Validity checker, motion resolution, start and goal.
void setProblem(og::SimpleSetup& ss, const ob::StateSpacePtr& space, const PathProblem& p) {
  setValidity(*ss.getSpaceInformation(), space, p);
  ob::ScopedState<> start(space), goal(space);
  for (int i = 0; i < 3; ++i) {
    start[i] = p.start_enu_m[i];
    goal[i] = p.goal_enu_m[i];
  }
  ss.setStartAndGoalStates(start, goal, 1e-6);
}

/// Path length, or length + integrity cost; "good enough" at good_enough_factor × the straight line.
ob::OptimizationObjectivePtr objectiveFor(const ob::SpaceInformationPtr& si, const PathProblem& p) {
  ob::OptimizationObjectivePtr objective;
  if (p.extra_cost) {
    objective = std::make_shared<IntegrityCostObjective>(si, *p.extra_cost, p.cost_step_m);
  } else {
    objective = std::make_shared<ob::PathLengthOptimizationObjective>(si);
  }
  const double straight = (p.goal_enu_m - p.start_enu_m).norm();
  objective->setCostThreshold(ob::Cost(p.good_enough_factor > 1.0 ? p.good_enough_factor * straight : 0.0));
  return objective;
}

ob::PlannerPtr makePlanner(PlannerKind kind, const ob::SpaceInformationPtr& si) {
  ob::PlannerPtr planner;
  switch (kind) {
    case PlannerKind::kRrtStar: planner = std::make_shared<og::RRTstar>(si); break;
    case PlannerKind::kInformedRrtStar: planner = std::make_shared<og::InformedRRTstar>(si); break;
    case PlannerKind::kBitStar: planner = std::make_shared<og::BITstar>(si); break;
    case PlannerKind::kPrmStar: planner = std::make_shared<og::PRMstar>(si); break;
    case PlannerKind::kLattice: break;  // planPath searches the lattice seed without OMPL's planners
  }
  return planner;
}

/// Solves until the iteration budget or the time limit; records time, iterations and which
/// limit stopped it.
ob::PlannerStatus solveWithinLimits(og::SimpleSetup& ss, const PathProblem& p, PathResult& out) {
  const auto t0 = std::chrono::steady_clock::now();
  std::atomic<std::uint64_t> checks{0};
  std::atomic<bool> by_time{false};
  const ob::PlannerTerminationCondition timed = ob::timedPlannerTerminationCondition(p.time_limit_s);
  const ob::PlannerTerminationCondition ptc([&]() {
    if (++checks > p.max_iterations) return true;
    if (timed()) {
      by_time = true;
      return true;
    }
    return false;
  });
  const ob::PlannerStatus status = ss.solve(ptc);
  out.planning_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.iterations = checks;
  out.stopped_by_time = by_time;
  return status;
}

/// The solution path (simplified when asked) and its cost (planPath measures its length).
void takeSolution(og::SimpleSetup& ss, const ob::OptimizationObjectivePtr& objective, const PathProblem& p,
                  PathResult& out) {
  og::PathGeometric& path = ss.getSolutionPath();
  if (p.simplify) {
    const auto t1 = std::chrono::steady_clock::now();
    og::PathSimplifier simplifier(ss.getSpaceInformation(), ob::GoalPtr(), objective);
    simplifier.simplifyMax(path);
    out.simplify_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  }
  for (std::size_t i = 0; i < path.getStateCount(); ++i) out.points.push_back(toVector(path.getState(i)));
  out.cost = path.cost(objective).value();
}

/// Plans with OMPL (the straight line did not do).
void planWithOmpl(const PathProblem& p, PathResult& out) {
  const OmplQueryScope scope(p);

  const std::shared_ptr<ob::RealVectorStateSpace> space = searchSpace(p);
  og::SimpleSetup ss(space);
  setProblem(ss, space, p);
  const ob::SpaceInformationPtr si = ss.getSpaceInformation();
  const ob::OptimizationObjectivePtr objective = objectiveFor(si, p);
  ss.setOptimizationObjective(objective);
  ss.setPlanner(makePlanner(p.planner, si));
  ss.setup();

  const ob::PlannerStatus status = solveWithinLimits(ss, p, out);
  if (status != ob::PlannerStatus::EXACT_SOLUTION && status != ob::PlannerStatus::APPROXIMATE_SOLUTION) {
    out.status = PathStatus::kNoSolution;
    return;
  }
  out.status = status == ob::PlannerStatus::EXACT_SOLUTION ? PathStatus::kExact : PathStatus::kApproximate;
  takeSolution(ss, objective, p, out);
}

/// Refines a valid path (a lattice seed) with the PathSimplifier under the problem's objective
/// (shortcuts and vertex reduction: each change kept only when its motions are valid at the
/// problem's resolution and, for shortcuts, when it lowers the objective).
void refineWithOmpl(const PathProblem& p, const std::vector<Eigen::Vector3d>& seed, PathResult& out) {
  const OmplQueryScope scope(p);
  const std::shared_ptr<ob::RealVectorStateSpace> space = searchSpace(p);
  const auto si = std::make_shared<ob::SpaceInformation>(space);
  setValidity(*si, space, p);
  si->setup();
  const ob::OptimizationObjectivePtr objective = objectiveFor(si, p);
  og::PathGeometric path(si);
  for (const Eigen::Vector3d& x : seed) {
    ob::ScopedState<> s(space);
    for (int i = 0; i < 3; ++i) s[i] = x[i];
    path.append(s.get());
  }
  if (p.simplify) {
    // Shortcuts and vertex reduction until neither changes the path (at most kRefinePasses):
    // simplifyMax's collapseCloseVertices, quadratic in the vertices, and its B-spline
    // subdivision took most of the time on a lattice seed of hundreds of vertices.
    constexpr int kRefinePasses = 8;
    const auto t1 = std::chrono::steady_clock::now();
    og::PathSimplifier simplifier(si, ob::GoalPtr(), objective);
    for (int pass = 0; pass < kRefinePasses; ++pass) {
      const bool reduced = simplifier.reduceVertices(path);
      const bool shortened = simplifier.shortcutPath(path);
      if (!reduced && !shortened) break;
    }
    out.simplify_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  }
  out.points.clear();
  for (std::size_t i = 0; i < path.getStateCount(); ++i) out.points.push_back(toVector(path.getState(i)));
  out.cost = path.cost(objective).value();
}

}  // namespace
}  // namespace skylane::planner::detail

/// The module's one exported symbol (its name carries kOmplModuleAbi).
extern "C" __attribute__((visibility("default"))) const skylane::planner::detail::OmplModule* skylane_ompl_module_v3() {
  static const skylane::planner::detail::OmplModule module{&skylane::planner::detail::planWithOmpl,
                                                           &skylane::planner::detail::refineWithOmpl};
  return &module;
}
