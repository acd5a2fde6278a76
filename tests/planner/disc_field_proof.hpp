#pragma once
/// \file
/// \brief An independent proof that a route exists through a field of discs, for the clutter
/// tests and benchmarks: no planner, no skylane code — a grid of square cells and a
/// breadth-first search.

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <deque>
#include <vector>

namespace skylane::test {

/// \brief What the grid says about a field of discs.
struct DiscFieldProof {
  double blocked_fraction = 0.0;  ///< of the cells
  bool route = false;             ///< start and goal are joined through free cells
};

/// \brief Cells of `cell_m` over `area` (x0, x1, y0, y1): a cell is blocked when any point of its
/// square lies within radius + grow_m of a disc (x, y, radius) — conservative; start and goal
/// are joined when a chain of free cells sharing an edge links theirs (breadth-first search). A
/// chain of such squares is a flyable route, so `route` true proves one exists.
inline DiscFieldProof proveRouteThroughDiscs(const std::vector<Eigen::Vector3d>& discs, const Eigen::Vector4d& area,
                                             double cell_m, double grow_m, const Eigen::Vector2d& start,
                                             const Eigen::Vector2d& goal) {
  const int nx = static_cast<int>((area[1] - area[0]) / cell_m), ny = static_cast<int>((area[3] - area[2]) / cell_m);
  std::vector<char> blocked(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny), 0);
  for (const Eigen::Vector3d& c : discs) {
    const double reach = c.z() + grow_m;
    for (int i = std::max(0, static_cast<int>((c.x() - reach - area[0]) / cell_m) - 1);
         i < std::min(nx, static_cast<int>((c.x() + reach - area[0]) / cell_m) + 2); ++i) {
      for (int j = std::max(0, static_cast<int>((c.y() - reach - area[2]) / cell_m) - 1);
           j < std::min(ny, static_cast<int>((c.y() + reach - area[2]) / cell_m) + 2); ++j) {
        // The nearest point of the cell's square to the centre.
        const double qx = std::clamp(c.x(), area[0] + i * cell_m, area[0] + (i + 1) * cell_m);
        const double qy = std::clamp(c.y(), area[2] + j * cell_m, area[2] + (j + 1) * cell_m);
        if (std::hypot(qx - c.x(), qy - c.y()) <= reach) blocked[static_cast<std::size_t>(j) * nx + i] = 1;
      }
    }
  }
  DiscFieldProof proof;
  proof.blocked_fraction =
      static_cast<double>(std::count(blocked.begin(), blocked.end(), 1)) / static_cast<double>(blocked.size());
  const auto cell = [&](const Eigen::Vector2d& p) {
    return static_cast<std::size_t>((p.y() - area[2]) / cell_m) * static_cast<std::size_t>(nx) +
           static_cast<std::size_t>((p.x() - area[0]) / cell_m);
  };
  std::vector<char> seen(blocked.size(), 0);
  std::deque<std::size_t> queue{cell(start)};
  seen[queue.front()] = 1;
  while (!queue.empty() && !proof.route) {
    const std::size_t k = queue.front();
    queue.pop_front();
    proof.route = k == cell(goal);
    const int i = static_cast<int>(k % nx), j = static_cast<int>(k / nx);
    for (auto [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
      if (i + di < 0 || i + di >= nx || j + dj < 0 || j + dj >= ny) continue;
      const std::size_t n = static_cast<std::size_t>(j + dj) * nx + static_cast<std::size_t>(i + di);
      if (blocked[n] || seen[n]) continue;
      seen[n] = 1;
      queue.push_back(n);
    }
  }
  return proof;
}

}  // namespace skylane::test
