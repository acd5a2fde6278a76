#include "geofence/corridor.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <queue>
#include <limits>
#include <utility>
#include <sstream>
#include <stdexcept>

namespace skylane::geofence {

/// legDistanceBoundsSq's bounds for one centre, and the leg nearest by them.
struct detail::LegBounds {
  std::vector<double> sq;
  std::size_t nearest = 0;
};

namespace {

double dimension(const Vehicle& v, Dimension d) {
  switch (d) {
    case Dimension::kLateral: return v.lateral_m;
    case Dimension::kLongitudinal: return v.longitudinal_m;
    case Dimension::kHeight: return v.height_m;
  }
  return 0.0;
}

const char* dimensionName(Dimension d) {
  switch (d) {
    case Dimension::kLateral: return "lateral";
    case Dimension::kLongitudinal: return "longitudinal";
    case Dimension::kHeight: return "height";
  }
  return "?";
}

/// Checks k against [lo, hi]; outside it throws, or with override records a warning.
void checkFactor(const char* name, double k, double lo, double hi, bool override_ranges,
                 std::vector<std::string>& warnings) {
  if (!(std::isfinite(k) && k > 0.0)) {
    std::ostringstream s;
    s << name << " must be a positive finite factor, got " << k;
    throw std::invalid_argument(s.str());
  }
  if (k >= lo && k <= hi) return;
  std::ostringstream s;
  s << name << " = " << k << " is outside the box levels' range [" << lo << ", " << hi << "]";
  if (!override_ranges) throw std::invalid_argument(s.str() + " (pass the override to accept it)");
  warnings.push_back(s.str() + ": accepted by override");
}

/// A segment's piece seen from a disk of horizontal points (centre x, radius `reach_m`): the
/// distance from x to the segment, and the range of the centre line's height over the disk.
/// The nearest point of the segment is a + t·(b − a) with t = clamp(s / L, 0, 1), s the
/// projection of the point on the segment's direction and L its horizontal length; s sweeps
/// exactly [s(x) − reach, s(x) + reach] over the disk and t is monotone in s, so the centre
/// line's heights over the disk are exactly those at the two clamped ends of that interval.
/// The clamp is the end-cap rule: over a half-disk beyond a waypoint the height is flat at the
/// waypoint's, so the slope shrinks the band only by the part of the disk that projects inside
/// the segment. A vertical segment (L = 0) spans its whole climb at every point.
struct PieceAt {
  double distance_m = 0.0;
  /// Every point of the disk has heights [floor_centre − VAL, ceiling_centre + VAL] in the piece
  /// (and some point no more): the highest and lowest centre-line heights over the disk, or the
  /// lowest and highest of a vertical segment.
  double floor_centre_m = 0.0, ceiling_centre_m = 0.0;
};

PieceAt pieceAt(const detail::CorridorLeg& leg, const Eigen::Vector2d& x, double reach_m) {
  const Eigen::Vector3d& a = leg.a;
  const Eigen::Vector3d& b = leg.b;
  const Eigen::Vector2d& d = leg.d;
  const double length_m = leg.length_m;
  PieceAt p;
  if (length_m == 0.0) {
    p.distance_m = (x - a.head<2>()).norm();
    p.floor_centre_m = std::min(a.z(), b.z());
    p.ceiling_centre_m = std::max(a.z(), b.z());
    return p;
  }
  const double s_m = (x - a.head<2>()).dot(d) / length_m;
  const double t = std::clamp(s_m / length_m, 0.0, 1.0);
  p.distance_m = (x - (a.head<2>() + t * d)).norm();
  const double t_back = std::clamp((s_m - reach_m) / length_m, 0.0, 1.0);
  const double t_ahead = std::clamp((s_m + reach_m) / length_m, 0.0, 1.0);
  const double z_back = a.z() + t_back * (b.z() - a.z()), z_ahead = a.z() + t_ahead * (b.z() - a.z());
  p.floor_centre_m = std::max(z_back, z_ahead);
  p.ceiling_centre_m = std::min(z_back, z_ahead);
  return p;
}

/// Margins of the piece for every point within the reach of x (the disk `p` was taken over),
/// for heights z ± vpl: horizontal HAL − d − reach (exact: the distance to a convex set grows by
/// exactly `reach` across a disk of that radius), vertical the band that every point of the disk
/// allows (exact by pieceAt).
std::pair<double, double> pieceMargins(const PieceAt& p, double reach_m, double z, double vpl, double hal,
                                       double val) {
  const double h = hal - p.distance_m - reach_m;
  const double v = std::min((p.ceiling_centre_m + val) - (z + vpl), (z - vpl) - (p.floor_centre_m - val));
  return {h, v};
}

/// One piece seen from a column (or every column of a disk): its horizontal margin h and the
/// heights [lo, hi] it holds there.
struct PieceColumn {
  double h_m, lo_m, hi_m;
};

/// How far the heights [bottom, top] of a column lie inside the union of the pieces: the
/// largest δ such that [bottom − δ, top + δ] lies in the union of the height bands of the
/// pieces with h ≥ δ (negative: by how much the column is not covered). A column may be
/// covered by two pieces' bands together and by neither alone (at a joint between legs of
/// different heights). Computed as the max over the sets S of the pieces with the j largest h
/// of min(smallest h in S, the best component [L, U] of S's bands: min(bottom − L, U − top));
/// a set of the j largest dominates every other set of its smallest h. With one piece this is
/// min(h, v) of pieceMargins. Monotone: it never grows when an h shrinks or a band narrows, so
/// bounds valid over a cell give a lower bound over the cell.
double columnMargin(std::vector<PieceColumn> pieces, double bottom_m, double top_m) {
  std::sort(pieces.begin(), pieces.end(), [](const PieceColumn& a, const PieceColumn& b) { return a.h_m > b.h_m; });
  double best = -std::numeric_limits<double>::infinity();
  std::vector<std::pair<double, double>> bands;
  for (const PieceColumn& p : pieces) {
    if (p.h_m <= best) break;  // every later set has min h ≤ this one's
    bands.emplace_back(p.lo_m, p.hi_m);
    std::sort(bands.begin(), bands.end());
    double cover = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < bands.size();) {
      double lo = bands[k].first, hi = bands[k].second;
      for (++k; k < bands.size() && bands[k].first <= hi; ++k) hi = std::max(hi, bands[k].second);
      cover = std::max(cover, std::min(bottom_m - lo, hi - top_m));
    }
    best = std::max(best, std::min(p.h_m, cover));
  }
  return best;
}

/// The margins of one protection volume (height z ± vpl) against the corridor's pieces (alert
/// limits hal, val), capped by the operating limits' margin.
struct MarginField {
  const std::vector<detail::CorridorLeg>& legs;
  double z, vpl, hal, val;
  double operating_margin_m;

  [[nodiscard]] std::size_t segmentCount() const { return legs.size(); }
  /// Piece i over the disk of radius reach_m round x.
  [[nodiscard]] PieceAt piece(std::size_t i, const Eigen::Vector2d& x, double reach_m) const {
    return pieceAt(legs[i], x, reach_m);
  }
  [[nodiscard]] std::pair<double, double> marginsOf(const PieceAt& p, double reach_m) const {
    auto [h, v] = pieceMargins(p, reach_m, z, vpl, hal, val);
    return std::pair{h, std::min(v, operating_margin_m)};
  }
  /// f(q) with reach: a lower bound, for every column within reach_m of q, on how far the
  /// column's heights [z − vpl, z + vpl] lie inside the union of the pieces (columnMargin);
  /// exact at reach 0.
  [[nodiscard]] double bound(const Eigen::Vector2d& q, double reach_m) const {
    std::vector<PieceColumn> pieces;
    pieces.reserve(segmentCount());
    for (std::size_t i = 0; i < segmentCount(); ++i) {
      const PieceAt p = piece(i, q, reach_m);
      pieces.push_back({hal - p.distance_m - reach_m, p.floor_centre_m - val, p.ceiling_centre_m + val});
    }
    return std::min(columnMargin(std::move(pieces), z - vpl, z + vpl), operating_margin_m);
  }
};

/// One piece holding the whole volume: both margins exact (pieceAt, pieceMargins), so when the
/// volume reaches a single piece its verdict is exact. Sets the best piece's segment and
/// margins in `out`.
struct BestPiece {
  double margin_m = -std::numeric_limits<double>::infinity();  ///< min(h, v) of the best piece
  std::size_t reached = 0;  ///< pieces whose alert limit the volume reaches
};

/// Far above the rounding of a distance in the map frame (coordinates of up to 10⁷ m: 10⁻⁹ m).
constexpr double kOutOfPlaySlack_m = 1e-6;

/// A lower bound on the square of each leg's distance d from the centre, found without a square
/// root or a division: the larger of the squared distances to the leg's bounding box and to its
/// line (rounding: ≈ 10⁻⁹ m at 10⁷ m, far below kOutOfPlaySlack_m). Returns the leg with the
/// smallest bound (the first of equals).
std::size_t legDistanceBoundsSq(const MarginField& f, const Eigen::Vector2d& c2, std::vector<double>& out) {
  out.resize(f.segmentCount());
  std::size_t nearest = 0;
  for (std::size_t i = 0; i < f.segmentCount(); ++i) {
    const detail::CorridorLeg& leg = f.legs[i];
    const double dx = std::max({0.0, leg.box_lo.x() - c2.x(), c2.x() - leg.box_hi.x()});
    const double dy = std::max({0.0, leg.box_lo.y() - c2.y(), c2.y() - leg.box_hi.y()});
    const double line = leg.normal.dot(c2) - leg.normal_offset_m;
    out[i] = std::max(dx * dx + dy * dy, line * line);
    if (out[i] < out[nearest]) nearest = i;
  }
  return nearest;
}

using detail::LegBounds;

/// The square of the distance beyond which a piece can neither beat `floor_m` (its
/// min(h, v) ≤ h = HAL − d − HPL would lie below it) nor be reached by the volume
/// (d > HAL + HPL): a piece whose distance bound exceeds it changes nothing in bestSinglePiece.
double outOfPlaySq(const MarginField& f, double hpl, double floor_m) {
  const double need_m = std::max(f.hal + hpl, f.hal - hpl - floor_m) + kOutOfPlaySlack_m;
  return need_m * need_m;
}

/// A floor below which no leg's min(h, v) can change bestSinglePiece's result: the min(h, v),
/// m_s, of the seed (`seed`: the piece of the leg nearest by its distance bound), less
/// (legs + 2) tolerances. Why a leg j below it (m_j < m_s − (N + 2)·tol,
/// and out of reach) may be skipped although the scan is sequential and its ties (within tol,
/// to the larger other margin) are not transitive: a selection lowers the best by at most tol.
/// After s is scanned the best is ≥ m_s − tol, so it never falls to within tol of m_j in the at
/// most N − 1 selections left: j is never selected after s. Before s, a scan that selects j and
/// one that skips it hold bests that both lie within tol of m_j or below, and their larger rises
/// by at most tol per leg while they differ: when s comes both lie more than tol below m_s, both
/// select s, and from there on they agree.
double seedFloor(const MarginField& f, const PieceAt& seed, double hpl, double tolerance_m) {
  const auto [h, v] = f.marginsOf(seed, hpl);
  return std::min(h, v) - (static_cast<double>(f.segmentCount()) + 2.0) * tolerance_m;
}

BestPiece bestSinglePiece(const MarginField& f, const Eigen::Vector2d& c2, double hpl, double tolerance_m,
                          const LegBounds& bounds, Containment& out) {
  BestPiece best;
  std::size_t segment = 0;
  double best_other_m = -std::numeric_limits<double>::infinity();
  const std::vector<double>& bound_sq = bounds.sq;
  const std::size_t seed = bounds.nearest;
  const PieceAt seed_piece = f.piece(seed, c2, hpl);
  const double seed_floor_m = seedFloor(f, seed_piece, hpl, tolerance_m);
  double out_of_play_sq = outOfPlaySq(f, hpl, seed_floor_m);
  for (std::size_t i = 0; i < f.segmentCount(); ++i) {
    if (bound_sq[i] > out_of_play_sq) continue;
    const PieceAt p = i == seed ? seed_piece : f.piece(i, c2, hpl);
    const auto [h, v] = f.marginsOf(p, hpl);
    // Pieces whose min(h, v) agree within the tolerance are tied (often the same quantity by
    // other sums: two level legs' shared vertical margin); the tie goes to the larger other
    // margin, not to the last bit of rounding, which depends on the frame.
    const double m = std::min(h, v), other = std::max(h, v);
    if (m > best.margin_m + tolerance_m || (m >= best.margin_m - tolerance_m && other > best_other_m)) {
      best.margin_m = m;
      best_other_m = other;
      segment = i;
      out.margin_h_m = h;
      out.margin_v_m = v;
      out_of_play_sq = outOfPlaySq(f, hpl, std::max(best.margin_m - tolerance_m, seed_floor_m));
    }
    if (p.distance_m <= f.hal + hpl) ++best.reached;
  }
  out.segment = segment;
  return best;
}

/// Bounds on the volume's margin in the union of the pieces: lower ≤ margin ≤ upper.
struct UnionMargin {
  double lower, upper;
};

/// A quadtree cell of the branch and bound: the lower bound on it, centre q, half side.
struct BoundCell {
  double lower;
  Eigen::Vector2d q;
  double half;
  bool operator<(const BoundCell& o) const { return lower > o.lower; }  // smallest first
};

/// Across a joint: no single piece holds the disk (centre c2, radius hpl), but their union may.
/// The volume's margin in the union is min over the disk of f(x), the column margin at x
/// (columnMargin: how far the column's heights lie inside the union of the pieces' bands); it
/// is bounded on a quadtree cell (centre q, circumradius ρ) from below by the column margin of
/// the pieces' bounds with reach ρ (valid for every column of the cell), and from above by f
/// at any point of the disk. Best-first branch and bound narrows the two to
/// `accuracy_m`, or stops as soon as the upper bound is at most `no_gain_m`: then the union
/// cannot beat the best single piece by more than the tolerance and its bounds are not used.
/// That stop matters where the minimum over the disk is attained along an arc, not at a point —
/// a disk centred on a waypoint, whose boundary behind the end cap (or outside the turn) is all
/// at distance HPL from the path: narrowing the bounds there to `accuracy_m` means covering the
/// whole arc with cells of that size (π·HPL / accuracy cells, up to the 200,000-cell cap: 4.5 s
/// for the 900 m volumes fuzz_fence checks on its own seed, a timeout), while the union's
/// margin there equals the best piece's (hal − HPL) and the first boundary point evaluated
/// shows it.
UnionMargin unionMargin(const MarginField& f, const Eigen::Vector2d& c2, double hpl, double accuracy_m, double no_gain_m) {
  std::priority_queue<BoundCell> cells;
  const double half0 = std::max(hpl, accuracy_m);
  cells.push({f.bound(c2, half0 * std::sqrt(2.0)), c2, half0});
  double upper = f.bound(c2, 0.0);  // f at the centre
  double lower = upper;
  for (int evaluations = 0; !cells.empty(); ++evaluations) {
    const BoundCell cell = cells.top();
    lower = cell.lower;
    if (lower >= upper - accuracy_m || upper <= no_gain_m || evaluations > 200000) break;
    cells.pop();
    // f at the cell's point nearest to its centre inside the disk tightens the upper bound.
    const Eigen::Vector2d x = (cell.q - c2).norm() > hpl ? Eigen::Vector2d(c2 + hpl * (cell.q - c2).normalized()) : cell.q;
    upper = std::min(upper, f.bound(x, 0.0));
    const double half = cell.half / 2;
    for (const Eigen::Vector2d& o : {Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1), Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1)}) {
      const Eigen::Vector2d q = cell.q + o * half;
      const double rho = half * std::sqrt(2.0);
      if ((q - c2).norm() - rho > hpl) continue;  // misses the disk
      cells.push({f.bound(q, rho), q, half});
    }
    if (cells.empty()) lower = upper;
  }
  return {lower, upper};
}

}  // namespace

LevelLimits alertLimits(const Vehicle& vehicle, const BoxLevels& levels) {
  LevelLimits out;
  for (Dimension d : {levels.mapping.horizontal, levels.mapping.vertical}) {
    const double size = dimension(vehicle, d);
    if (!(std::isfinite(size) && size > 0.0)) {
      std::ostringstream s;
      s << "vehicle " << dimensionName(d) << " size must be a positive number of metres, got " << size;
      throw std::invalid_argument(s.str());
    }
  }
  checkFactor("k1", levels.k1, 1.1, 1.3, levels.override_ranges, out.warnings);
  checkFactor("k2", levels.k2, 100.0, 1000.0, levels.override_ranges, out.warnings);
  const double h = dimension(vehicle, levels.mapping.horizontal), v = dimension(vehicle, levels.mapping.vertical);
  out.level1 = {levels.k1 * h, levels.k1 * v};
  out.level2 = {levels.k2 * h, levels.k2 * v};
  return out;
}

void requireValid(const ProtectionVolume& volume) {
  if (!volume.p_map.allFinite()) throw std::invalid_argument("protection volume position is not finite");
  if (!(std::isfinite(volume.hpl_m) && volume.hpl_m >= 0 && std::isfinite(volume.vpl_m) && volume.vpl_m >= 0)) {
    std::ostringstream s;
    s << "protection levels must be finite and ≥ 0, got HPL " << volume.hpl_m << " m, VPL " << volume.vpl_m << " m";
    throw std::invalid_argument(s.str());
  }
}

const char* verdictName(Verdict v) {
  switch (v) {
    case Verdict::kInside: return "inside";
    case Verdict::kOutside: return "outside";
    case Verdict::kIndeterminate: return "indeterminate";
  }
  return "?";
}

Corridor::Corridor(std::vector<Eigen::Vector3d> path_map, AlertLimits limits, OperatingLimits operating)
    : path_(std::move(path_map)), limits_(limits), operating_(operating) {
  if (path_.size() < 2) {
    throw std::invalid_argument("a corridor needs at least 2 waypoints, got " + std::to_string(path_.size()));
  }
  for (std::size_t i = 0; i < path_.size(); ++i) {
    if (!path_[i].allFinite()) throw std::invalid_argument("corridor waypoint " + std::to_string(i) + " is not finite");
  }
  if (!(std::isfinite(limits_.hal_m) && limits_.hal_m > 0 && std::isfinite(limits_.val_m) && limits_.val_m > 0)) {
    std::ostringstream s;
    s << "corridor alert limits must be positive, got HAL " << limits_.hal_m << " m, VAL " << limits_.val_m << " m";
    throw std::invalid_argument(s.str());
  }
  if (std::isnan(operating_.floor_h_ell_m) || std::isnan(operating_.ceiling_h_ell_m) ||
      operating_.floor_h_ell_m >= operating_.ceiling_h_ell_m) {
    std::ostringstream s;
    s << "operating limits must have floor < ceiling, got " << operating_.floor_h_ell_m << " … "
      << operating_.ceiling_h_ell_m << " m";
    throw std::invalid_argument(s.str());
  }
  legs_.reserve(path_.size() - 1);
  for (std::size_t i = 0; i + 1 < path_.size(); ++i) {
    const Eigen::Vector3d& a = path_[i];
    const Eigen::Vector3d& b = path_[i + 1];
    const Eigen::Vector2d d = (b - a).head<2>();
    const double length_m = d.norm();
    const Eigen::Vector2d normal = length_m > 0 ? Eigen::Vector2d(-d.y() / length_m, d.x() / length_m) : Eigen::Vector2d::Zero();
    legs_.push_back({a, b, d, length_m, a.head<2>().cwiseMin(b.head<2>()), a.head<2>().cwiseMax(b.head<2>()), normal,
                     normal.dot(a.head<2>())});
  }
}

std::array<Eigen::Vector3d, 8> Corridor::segmentBoxCorners(std::size_t segment) const {
  if (segment >= segmentCount()) throw std::out_of_range("segmentBoxCorners: no segment " + std::to_string(segment));
  const Eigen::Vector3d& a = path_[segment];
  const Eigen::Vector3d& b = path_[segment + 1];
  const Eigen::Vector2d d = (b - a).head<2>();
  const double length_m = d.norm();
  // u along the segment (east for a vertical one), n to its left; a vertical segment gets a
  // square of half-side HAL.
  const Eigen::Vector2d u = length_m > 0 ? Eigen::Vector2d(d / length_m) : Eigen::Vector2d(1, 0);
  const Eigen::Vector2d n(-u.y(), u.x());
  const bool vertical = length_m == 0.0;
  const Eigen::Vector2d reach = vertical ? Eigen::Vector2d(limits_.hal_m * u) : Eigen::Vector2d::Zero();
  const double z_min = std::min(a.z(), b.z()), z_max = std::max(a.z(), b.z());
  const double za_lo = (vertical ? z_min : a.z()) - limits_.val_m, za_hi = (vertical ? z_max : a.z()) + limits_.val_m;
  const double zb_lo = (vertical ? z_min : b.z()) - limits_.val_m, zb_hi = (vertical ? z_max : b.z()) + limits_.val_m;
  const Eigen::Vector2d a2 = a.head<2>() - reach, b2 = b.head<2>() + reach, w = limits_.hal_m * n;
  const auto at = [](const Eigen::Vector2d& p, double z) { return Eigen::Vector3d(p.x(), p.y(), z); };
  return {at(a2 - w, za_lo), at(b2 - w, zb_lo), at(b2 + w, zb_lo), at(a2 + w, za_lo),
          at(a2 - w, za_hi), at(b2 - w, zb_hi), at(b2 + w, zb_hi), at(a2 + w, za_hi)};
}

Containment Corridor::contains(const ProtectionVolume& volume, double tolerance_m) const {
  thread_local LegBounds bounds;  // per-thread scratch: no allocation once grown
  return containsWithBounds(volume, tolerance_m, bounds, false);
}

std::pair<Containment, Containment> Corridor::containsWith(const Corridor& other, const ProtectionVolume& volume,
                                                           double tolerance_m) const {
  thread_local LegBounds bounds;
  const bool same_path = path_.size() == other.path_.size() &&
                         std::memcmp(path_.data(), other.path_.data(), path_.size() * sizeof(Eigen::Vector3d)) == 0;
  Containment mine = containsWithBounds(volume, tolerance_m, bounds, false);
  return {mine, other.containsWithBounds(volume, tolerance_m, bounds, same_path)};
}

Containment Corridor::containsWithBounds(const ProtectionVolume& volume, double tolerance_m, LegBounds& bounds,
                                         bool bounds_known) const {
  requireValid(volume);
  if (!(tolerance_m >= 0.0 && std::isfinite(tolerance_m))) {  // the legs' skipping relies on it too
    throw std::invalid_argument("corridor containment tolerance must be finite and ≥ 0, got " + std::to_string(tolerance_m));
  }
  const Eigen::Vector3d& c = volume.p_map;
  const double hpl = volume.hpl_m, vpl = volume.vpl_m, hal = limits_.hal_m, val = limits_.val_m;
  // The operating limits bound every piece.
  const double operating_margin_m =
      std::min(operating_.ceiling_h_ell_m - (c.z() + vpl), (c.z() - vpl) - operating_.floor_h_ell_m);
  const MarginField field{legs_, c.z(), vpl, hal, val, operating_margin_m};
  const Eigen::Vector2d c2 = c.head<2>();

  Containment out;
  if (!bounds_known) bounds.nearest = legDistanceBoundsSq(field, c2, bounds.sq);
  const BestPiece best = bestSinglePiece(field, c2, hpl, tolerance_m, bounds, out);
  if (best.margin_m < tolerance_m && best.reached >= 2) {
    const UnionMargin u = unionMargin(field, c2, hpl, std::max(tolerance_m, 1e-3 * hal), best.margin_m + tolerance_m);
    // lower ≤ the union margin ≤ upper (a point of the volume has margin `upper`); report the
    // certified lower bound when it beats the best piece by more than the tolerance. Where the
    // other pieces add nothing (the common case well outside), the union's margin equals the
    // best piece's min(h, v) and the two are the same quantity summed in different orders: a
    // bare `>` was decided by their last bit, which depends on the frame's rounding. A gain within
    // the tolerance is none. But the gain is known only to the search's accuracy (HAL/1000, far
    // coarser than the tolerance), and where the search stops within it depends on the frame: its
    // quadtree cells are axis-aligned in the map frame, so a rotated scene gets other cells and
    // another certified bound. So a union that gains less than the accuracy is reported in one
    // frame and not in another, and the report must not jump there. The deciding margin does not
    // (L against min(h, v), which differ by the gain); the horizontal one did: the union's (L, L)
    // against the piece's (h, v) put margin_h at -26.35 m in one frame and -11.30 m in the
    // rotated one (Fence.WholeSceneTranslatedAndRotated trial 199, clang ASan build: the union
    // gains 7.6 mm, the accuracy is 24 mm). The union's horizontal room is at least the best
    // piece's h (the union holds that piece's footprint), so margin_h is max(L, h): a valid
    // bound, and the piece's h on both sides of the switch where the vertical margin decides.
    if (u.lower > best.margin_m + tolerance_m) {
      out.across_joint = true;
      out.margin_h_m = std::max(u.lower, out.margin_h_m);
      out.margin_v_m = u.lower;
      out.verdict = u.lower > tolerance_m ? Verdict::kInside
                                          : (u.upper < -tolerance_m ? Verdict::kOutside : Verdict::kIndeterminate);
      return out;
    }
  }
  const double m = std::min(out.margin_h_m, out.margin_v_m);
  out.verdict = std::abs(m) <= tolerance_m ? Verdict::kIndeterminate : (m > 0 ? Verdict::kInside : Verdict::kOutside);
  return out;
}

}  // namespace skylane::geofence
