// Nearest-first ring walk over a grid (maps/grid_rings.hpp), the building index's visiting order.
#include "maps/grid_rings.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

namespace skylane::maps {
namespace {

using Cells = std::vector<std::pair<int, int>>;

int chebyshev(int c, int r, int ci, int cj) { return std::max(std::abs(c - ci), std::abs(r - cj)); }

/// The reference order, written independently: every position of every square ring around
/// (ci, cj) out to `last`, in the order the header documents, kept when inside the grid.
Cells referenceOrder(int ci, int cj, int cols, int rows, int last) {
  Cells out;
  const auto keep = [&](int c, int r) {
    if (c >= 0 && c < cols && r >= 0 && r < rows) out.emplace_back(c, r);
  };
  keep(ci, cj);
  for (int k = 1; k <= last; ++k) {
    for (int c = ci - k; c <= ci + k; ++c) keep(c, cj - k), keep(c, cj + k);
    for (int r = cj - k + 1; r <= cj + k - 1; ++r) keep(ci - k, r), keep(ci + k, r);
  }
  return out;
}

struct Walk {
  Cells visited;
  std::vector<int> asked;  ///< the rings stop() was asked about
  std::size_t work = 0;
};

Walk walk(int ci, int cj, int cols, int rows, int stop_at = -1) {
  Walk w;
  w.work = walkGridRings(
      ci, cj, cols, rows,
      [&](int ring) {
        w.asked.push_back(ring);
        return stop_at >= 0 && ring >= stop_at;
      },
      [&](int c, int r) { w.visited.emplace_back(c, r); });
  return w;
}

TEST(GridRings, LongThinGridIsWalkedInWorkLinearInItsCells) {
  // GIVEN a grid like that of the fuzzer's slow input (buildings strung 150 km east-west over
  // 200 m north-south, 50 m cells): 3000 × 5 cells, the walk starting at the western end
  const int cols = 3000, rows = 5;
  const Walk w = walk(0, 2, cols, rows);
  // THEN every cell is visited once, nearest ring first
  ASSERT_EQ(w.visited.size(), static_cast<std::size_t>(cols * rows));
  std::vector<char> seen(static_cast<std::size_t>(cols * rows), 0);
  int previous_ring = 0;
  for (const auto& [c, r] : w.visited) {
    ASSERT_TRUE(c >= 0 && c < cols && r >= 0 && r < rows) << c << ", " << r;
    char& s = seen[static_cast<std::size_t>(r * cols + c)];
    EXPECT_EQ(s, 0) << "cell " << c << ", " << r << " visited twice";
    s = 1;
    ASSERT_GE(chebyshev(c, r, 0, 2), previous_ring);
    previous_ring = chebyshev(c, r, 0, 2);
  }
  // AND the work is at most the 15 000 cells plus one per ring (rings 0 … 2999), where square
  // rings unclipped to the grid pass (2·2999 + 1)² ≈ 3.6e7 positions (and rings clipped only
  // along their length still step along rows outside the grid, ~4.5e6).
  EXPECT_EQ(w.asked.size(), static_cast<std::size_t>(cols));
  EXPECT_LE(w.work, static_cast<std::size_t>(cols * rows + cols));
  // ... exactly: ring 0, rings 1 and 2 (2 + 1 and 3 + 3 steps), then 5 steps for each of
  // rings 3 … 2999 along the eastern column, plus the 3000 rings themselves.
  EXPECT_EQ(w.work, static_cast<std::size_t>(1 + 3 + 6 + 5 * 2997 + 3000));
}

TEST(GridRings, StartOutsideTheGridSkipsTheRingsThatMissIt) {
  // GIVEN a 10 × 10 grid and a start 1000 cells west of it
  const Walk w = walk(-1000, 4, 10, 10);
  // THEN the first ring asked about is the first to reach the grid, the last its far corner
  ASSERT_FALSE(w.asked.empty());
  EXPECT_EQ(w.asked.front(), 1000);
  EXPECT_EQ(w.asked.back(), 1009);
  EXPECT_EQ(w.visited.size(), 100u);
  EXPECT_EQ(w.work, 100u + 10u);
  EXPECT_EQ(w.visited, referenceOrder(-1000, 4, 10, 10, 1009));
}

TEST(GridRings, OrderEqualsTheFilteredSquareRingsFromEveryStart) {
  // Property: from every start in and around grids of several shapes, the visits are the
  // reference's in-grid positions in its order.
  for (const auto& [cols, rows] : {std::pair{1, 1}, {1, 7}, {7, 1}, {4, 6}, {9, 3}}) {
    for (int ci = -3; ci < cols + 3; ++ci) {
      for (int cj = -3; cj < rows + 3; ++cj) {
        const int last = std::max({ci, cols - 1 - ci, cj, rows - 1 - cj});
        SCOPED_TRACE(std::to_string(cols) + " x " + std::to_string(rows) + " from " + std::to_string(ci) + ", " + std::to_string(cj));
        const Walk w = walk(ci, cj, cols, rows);
        EXPECT_EQ(w.visited, referenceOrder(ci, cj, cols, rows, last));
        EXPECT_EQ(w.asked.back(), last);
        EXPECT_LE(w.work, static_cast<std::size_t>(cols * rows) + w.asked.size());
      }
    }
  }
}

TEST(GridRings, StopEndsTheWalkBeforeTheRingItRefuses) {
  // GIVEN a 20 × 20 grid walked from its middle, stopped at ring 3
  const Walk w = walk(10, 10, 20, 20, 3);
  // THEN rings 0, 1, 2 (1 + 8 + 16 = 25 cells) are visited and ring 3 is asked, not walked
  EXPECT_EQ(w.visited.size(), 25u);
  EXPECT_EQ(w.asked, (std::vector<int>{0, 1, 2, 3}));
  for (const auto& [c, r] : w.visited) EXPECT_LE(chebyshev(c, r, 10, 10), 2);
}

TEST(GridRings, AnEmptyGridIsNoWork) {
  EXPECT_EQ(walk(0, 0, 0, 5).work, 0u);
  EXPECT_EQ(walk(0, 0, 5, 0).asked.size(), 0u);
}

}  // namespace
}  // namespace skylane::maps
