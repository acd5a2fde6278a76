#pragma once
/// \file
/// \brief A lattice seed for routes through clutter: A* over a state lattice of the
/// planning query's free space, coarse to fine, with the same state-validity predicate and the
/// same motion check as every route (docs/method.md §7.1, "Clutter").
///
/// The lattice's horizontal nodes lie on a square grid of step h anchored at the start; a node's
/// height follows the straight leg (linear in the progress from start to goal, clamped), offset
/// by whole layers of dz. Moves: the 16 neighbours of the grid (the 8 king moves and the 8 knight
/// moves, so that the seed turns by 26.6° steps, not only 45°) in a layer, and one layer up or
/// down. A node is checked when it is taken from the open list (lazy evaluation), a move every
/// resolution_m metres; a motion found invalid is not taken again, and its node is offered again
/// from each of its expanded neighbours (so that the lazy search misses no path of the lattice);
/// the goal is reached from any node within 2.3 h whose straight motion to it is valid. The
/// search is A* (P. E. Hart, N. J. Nilsson and B. Raphael, "A Formal Basis for the Heuristic
/// Determination of Minimum Cost Paths", IEEE Trans. Systems Science and Cybernetics 4(2), 1968):
/// the lattice's shortest path. A heuristic inflated by ε > 1 (I. Pohl, "Heuristic search viewed
/// as path finding in a graph", Artificial Intelligence 1(3), 1970) finds one at most ε times
/// it after fewer checks; on the 48 km² clutter bench ε = 1.5 took a quarter of the checks for a
/// route 10 % longer, and the approval as long in all (the longer route has more samples).
/// Lattices of this kind for planning are those of M. Pivtoraiko, R. A. Knepper and A. Kelly, "Differentially constrained mobile robot
/// motion planning in state lattices", Journal of Field Robotics 26(3), 2009.
///
/// Step length relative to free space: the first step is the leg's length / 128 clamped to
/// [2·resolution, 40 m]; a lattice that finds no path is halved, down to the motion resolution,
/// so that a passage about as wide as the finest step (plus the planning volume the predicate
/// already holds) is found when one exists; the lattice after the first that finds one is
/// searched too, and the cheaper path kept (a coarse lattice passes fewer gaps: a detour). Each
/// step is tried first on the leg's own height surface; then the steps of at least 2·resolution with a layer above and below. Deterministic:
/// the same problem gives the same seed (ties broken by node index).

#include "planner/route_planner.hpp"

#include <cstdint>
#include <vector>

namespace skylane::planner {

/// \brief Limits of one lattice search.
struct LatticeOptions {
  double heuristic_weight = 1.0;          ///< ε ≥ 1: the seed is at most ε × the lattice's shortest
  std::uint64_t max_state_checks = 3000000;  ///< over every step tried (reproducible)
  double time_limit_s = 30.0;             ///< a safety net: then not reproducible
};

/// \brief What the lattice search found.
struct LatticeResult {
  bool found = false;
  std::vector<Eigen::Vector3d> points;  ///< start … goal (every motion checked every resolution_m)
  double step_m = 0.0;                  ///< the lattice step that found it (else the finest searched)
  int layers = 0;                       ///< height layers of that lattice (1 or 3)
  std::uint64_t state_checks = 0;       ///< validity checks of nodes and of motions' samples
  std::uint64_t expansions = 0;         ///< entries taken from the open list over every step tried
  bool stopped_by_budget = false;       ///< max_state_checks ended it
  bool stopped_by_time = false;         ///< the time limit ended it (not reproducible)
  double time_s = 0.0;
};

/// \brief Searches the lattice, coarse to fine, for a path from the problem's start to its goal
/// (both assumed valid and inside the box).
[[nodiscard]] LatticeResult latticeSearch(const PathProblem& problem, const LatticeOptions& options = {});

/// \brief The path without the vertices inside runs of the same direction (on the line through
/// their neighbours): the same polyline with fewer vertices. Its motions are sampled at other
/// places than the runs' own, so it must be checked again.
[[nodiscard]] std::vector<Eigen::Vector3d> withoutCollinearVertices(const std::vector<Eigen::Vector3d>& path);

/// \brief Whether the straight motion a → b is valid, checked every `resolution_m` (both ends
/// included, or only the samples between them); adds the checks made to `*checks` when given.
[[nodiscard]] bool motionIsValid(const PathProblem& problem, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 bool with_ends = true, std::uint64_t* checks = nullptr);

}  // namespace skylane::planner
