#include "maps/plane_grid.hpp"

#include "maps/geodesy.hpp"

#include <GeographicLib/Math.hpp>

#include <cmath>

namespace skylane::maps {

namespace {

constexpr int kN = PlaneGrid::kDegree + 1;  // nodes and coefficients per axis
constexpr int kHalf = PlaneGrid::kCellsPerSide / 2;

/// The k-th Chebyshev node on [-1, 1] (the zeros of T_kN).
double chebyshevNode(int k) { return std::cos(M_PI * (k + 0.5) / kN); }

/// T_0(u) … T_degree(u).
void chebyshevValues(double u, double (&t)[kN]) {
  t[0] = 1.0;
  t[1] = u;
  for (int k = 2; k < kN; ++k) t[k] = 2.0 * u * t[k - 1] - t[k - 2];
}

}  // namespace

/// The series of one cell: x = Σ cx[m][n] T_m(u) T_n(v), y likewise, with u and v the cell's
/// latitude and longitude offsets mapped onto [-1, 1].
struct PlaneGrid::Cell {
  double cx[kN][kN];
  double cy[kN][kN];
};

namespace {

/// The series through the exact projection at the cell's nodes (the discrete Chebyshev
/// transform, exact for polynomials of the degree).
PlaneGrid::Cell fitCell(const PlaneFrame& frame, double lat_deg, double lon_deg) {
  double fx[kN][kN], fy[kN][kN];
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) {
      const double lat = lat_deg + PlaneGrid::kCell_deg * (chebyshevNode(i) + 1.0) / 2.0;
      const double lon = lon_deg + PlaneGrid::kCell_deg * (chebyshevNode(j) + 1.0) / 2.0;
      const Eigen::Vector2d xy = frame.toPlaneDeg(lat, lon);
      fx[i][j] = xy.x();
      fy[i][j] = xy.y();
    }
  }
  PlaneGrid::Cell c{};
  for (int m = 0; m < kN; ++m) {
    for (int n = 0; n < kN; ++n) {
      double sx = 0, sy = 0;
      for (int i = 0; i < kN; ++i) {
        for (int j = 0; j < kN; ++j) {
          const double w = std::cos(M_PI * m * (i + 0.5) / kN) * std::cos(M_PI * n * (j + 0.5) / kN);
          sx += fx[i][j] * w;
          sy += fy[i][j] * w;
        }
      }
      const double scale = (m == 0 ? 1.0 : 2.0) * (n == 0 ? 1.0 : 2.0) / (kN * kN);
      c.cx[m][n] = sx * scale;
      c.cy[m][n] = sy * scale;
    }
  }
  return c;
}

Eigen::Vector2d evaluate(const PlaneGrid::Cell& c, double u, double v) {
  double tu[kN], tv[kN];
  chebyshevValues(u, tu);
  chebyshevValues(v, tv);
  double x = 0, y = 0;
  for (int m = 0; m < kN; ++m) {
    double ax = 0, ay = 0;
    for (int n = 0; n < kN; ++n) {
      ax += c.cx[m][n] * tv[n];
      ay += c.cy[m][n] * tv[n];
    }
    x += ax * tu[m];
    y += ay * tu[m];
  }
  return {x, y};
}

}  // namespace

PlaneGrid::PlaneGrid(const PlaneFrame& frame) : frame_(frame), origin_deg_(frame.origin_deg()) {}

PlaneGrid::~PlaneGrid() = default;

const PlaneGrid::Cell* PlaneGrid::cellAt(int i, int j) const {
  const std::size_t k = static_cast<std::size_t>(i) * kCellsPerSide + j;
  if (Slot* slots = slots_.load(std::memory_order_acquire)) {
    if (const Cell* c = slots[k].load(std::memory_order_acquire)) return c;
  }
  const std::lock_guard<std::mutex> lock(build_);
  if (!slot_storage_) {
    slot_storage_ = std::make_unique<Slot[]>(static_cast<std::size_t>(kCellsPerSide) * kCellsPerSide);
    for (std::size_t n = 0; n < static_cast<std::size_t>(kCellsPerSide) * kCellsPerSide; ++n) {
      slot_storage_[n].store(nullptr, std::memory_order_relaxed);
    }
    slots_.store(slot_storage_.get(), std::memory_order_release);
  }
  Slot& slot = slot_storage_[k];
  if (const Cell* c = slot.load(std::memory_order_relaxed)) return c;
  built_.push_back(std::make_unique<Cell>(fitCell(frame_, origin_deg_.x() + (i - kHalf) * kCell_deg,
                                                  origin_deg_.y() + (j - kHalf) * kCell_deg)));
  slot.store(built_.back().get(), std::memory_order_release);
  return built_.back().get();
}

Eigen::Vector2d PlaneGrid::toPlane(double lat_rad, double lon_rad) const {
  const double lat = rad2deg(lat_rad);
  const double dlat = lat - origin_deg_.x();
  const double dlon = GeographicLib::Math::AngDiff(origin_deg_.y(), rad2deg(lon_rad));
  const double fi = std::floor(dlat / kCell_deg), fj = std::floor(dlon / kCell_deg);
  if (!(std::abs(lat) <= kMaxLat_deg && fi >= -kHalf && fi < kHalf && fj >= -kHalf && fj < kHalf)) {
    return frame_.toPlane(lat_rad, lon_rad);  // far from the origin, near a pole, or not finite
  }
  const int i = static_cast<int>(fi) + kHalf, j = static_cast<int>(fj) + kHalf;
  const double u = 2.0 * (dlat - fi * kCell_deg) / kCell_deg - 1.0;
  const double v = 2.0 * (dlon - fj * kCell_deg) / kCell_deg - 1.0;
  return evaluate(*cellAt(i, j), u, v);
}

}  // namespace skylane::maps
