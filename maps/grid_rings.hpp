#pragma once
/// \file
/// \brief Nearest-first walk over the cells of a rectangular grid in square rings (cells at the
/// same Chebyshev distance from a start cell): the visiting order of the building index's
/// culled sky-mask query (maps/sky_mask.hpp).

#include <algorithm>
#include <cstddef>

namespace skylane::maps {

/// \brief Visits the cells (c, r), 0 ≤ c < cols, 0 ≤ r < rows, of a grid ring by ring around the
/// cell (ci, cj): ring k holds the cells with max(|c − ci|, |r − cj|) = k, rings in increasing k.
/// (ci, cj) may lie outside the grid.
///
/// Every cell of the grid is visited exactly once (unless stopped), `visit(c, r)` is never called
/// outside the grid. `stop(k)` is asked before each ring k that has a cell in the grid, and ends
/// the walk when true; rings that miss the grid are skipped without being asked (a ring with no
/// cell cannot change what the caller's stop depends on). Within a ring: for each column c from
/// left to right its cell in the lower then the upper row of the ring, then for each row between
/// them its cell in the left then the right column.
///
/// Each ring is clipped to the grid before it is walked, so the work is O(cols·rows + K) for K
/// rings that reach the grid — not O(K²): an unclipped square ring around a cell of a long, thin
/// grid (buildings strung along one axis, 3000 × 5 cells) passes ~4K² positions outside it.
/// \return the work done: one per ring walked plus one per step of the loops along a ring's
/// rows and columns (each step visits one or two cells), so at most cols·rows + K.
template <class Stop, class Visit>
std::size_t walkGridRings(int ci, int cj, int cols, int rows, const Stop& stop, const Visit& visit) {
  if (cols <= 0 || rows <= 0) return 0;
  // Chebyshev distance from (ci, cj) to the grid (first ring with a cell in it) and to its
  // farthest corner (last ring).
  const auto gap = [](int v, int n) { return v < 0 ? -v : (v >= n ? v - (n - 1) : 0); };
  const int first = std::max(gap(ci, cols), gap(cj, rows));
  const int last = std::max({ci, cols - 1 - ci, cj, rows - 1 - cj});
  std::size_t work = 0;
  for (int ring = first; ring <= last; ++ring) {
    ++work;
    if (stop(ring)) break;
    if (ring == 0) {
      visit(ci, cj);
      ++work;
      continue;
    }
    const int lower = cj - ring, upper = cj + ring, left = ci - ring, right = ci + ring;
    const bool has_lower = lower >= 0, has_upper = upper < rows;  // the ring's rows inside the grid
    const bool has_left = left >= 0, has_right = right < cols;    // its columns inside the grid
    if (has_lower || has_upper) {
      for (int c = std::max(left, 0); c <= std::min(right, cols - 1); ++c, ++work) {
        if (has_lower) visit(c, lower);
        if (has_upper) visit(c, upper);
      }
    }
    if (has_left || has_right) {
      for (int r = std::max(lower + 1, 0); r <= std::min(upper - 1, rows - 1); ++r, ++work) {
        if (has_left) visit(left, r);
        if (has_right) visit(right, r);
      }
    }
  }
  return work;
}

}  // namespace skylane::maps
