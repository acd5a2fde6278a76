#pragma once
/// \file
/// \brief The interface between planPath and its OMPL search, internal to planner/.
///
/// OMPL (with ODE, Boost.Serialization and Boost.Filesystem behind it) is not linked into
/// skylane: it would cost every process 3–4 ms and 7 MiB at start, and most commands never
/// search for a route. planPath (route_planner.cpp) checks the problem, tries the straight
/// segment, and only then loads libskylane_ompl.so (maps/module_loader.hpp) for the search.

#include "planner/route_planner.hpp"

namespace skylane::planner::detail {

/// \brief The entry points of the OMPL module.
struct OmplModule {
  /// \brief Plans with OMPL (the straight line did not do): fills status, points, cost, the
  /// times, iterations and stopped_by_time of `out`. Serialised inside (OMPL's seed generator
  /// is process-wide).
  void (*plan)(const PathProblem& problem, PathResult& out);
  /// \brief Refines a valid path (a lattice seed) with OMPL's PathSimplifier under the problem's
  /// objective when problem.simplify: fills points, cost and simplify_time_s of `out`. The caller
  /// checks every motion of the result again. Serialised and seeded like plan.
  void (*refine)(const PathProblem& problem, const std::vector<Eigen::Vector3d>& seed, PathResult& out);
};

/// \brief The interface version the module and skylane agree on (in the entry point's name).
inline constexpr int kOmplModuleAbi = 3;
/// \brief File name of the module.
inline constexpr const char* kOmplModuleFile = "libskylane_ompl.so";

}  // namespace skylane::planner::detail
