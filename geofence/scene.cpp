#include "geofence/scene.hpp"

#include "geofence/fcl_module.hpp"
#include "maps/module_loader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#ifndef SKYLANE_FCL_MODULE_BUILD_PATH
// CMake defines both for skylane_geofence: the module in the build tree and where it is installed.
#define SKYLANE_FCL_MODULE_BUILD_PATH ""
#define SKYLANE_FCL_MODULE_INSTALL_PATH ""
#endif

namespace skylane::geofence {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// FCL's cylinder for the volume is at least this wide and tall [m], so that it never
/// degenerates to a segment or a disk; the 1 mm it adds is well inside kExactBand_m, to which
/// FCL's distance must match the closed form.
constexpr double kFclMinSize_m = 1e-3;
/// A turn to the right of up to this sine is accepted as convex: the exact convex pieces of
/// airspace::convexPieces are rounded to doubles, which can bend a straight run by an ulp. FCL
/// works on the vertices' hull, which then holds the piece (the safe side).
constexpr double kConvexityTolerance = 1e-9;
/// A ring's edge as the distance below takes it: its start, its vector, length and squared length.
struct RingEdge {
  double ax, ay, ex, ey, length, length2;
};

/// The edge from a to b; none when it has no length (a repeated vertex adds nothing).
std::optional<RingEdge> ringEdge(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a;
  const double length = e.norm();
  if (length == 0.0) return std::nullopt;
  return RingEdge{a.x(), a.y(), e.x(), e.y(), length, length * length};
}

/// A point x seen from a ring's edge: `cross` > 0 when x lies left of it (the inside side of a
/// counter-clockwise ring), and (dx, dy) = x − the edge's point nearest to x.
struct EdgeView {
  double cross, dx, dy;
};

EdgeView viewFromEdge(const RingEdge& e, const Eigen::Vector2d& x) {
  const double ax = x.x() - e.ax, ay = x.y() - e.ay;
  const double t = std::clamp((ax * e.ex + ay * e.ey) / e.length2, 0.0, 1.0);
  return {e.ex * ay - e.ey * ax, ax - t * e.ex, ay - t * e.ey};
}

/// Signed horizontal distance from a point to a convex counter-clockwise ring, edge by edge:
/// positive outside (the distance to the ring), negative inside (minus the distance to its
/// boundary: the least distance to its edges' lines).
class SignedRingDistance {
 public:
  explicit SignedRingDistance(const Eigen::Vector2d& x) : x_(x) {}
  void add(const RingEdge& e) {
    const EdgeView v = viewFromEdge(e, x_);
    if (v.cross < 0) is_inside_ = false;
    inside_ = std::min(inside_, v.cross / e.length);
    outside2_ = std::min(outside2_, v.dx * v.dx + v.dy * v.dy);  // the root of the least is the least root
  }
  [[nodiscard]] double value() const { return is_inside_ ? -inside_ : std::sqrt(outside2_); }

 private:
  Eigen::Vector2d x_;
  double outside2_ = kInf, inside_ = kInf;
  bool is_inside_ = true;
};

/// Signed horizontal distance from x to the piece's shape: positive outside (distance to the
/// shape), negative inside (minus the distance to its boundary).
double signedHorizontalDistance(const airspace::PlanarPrism& p, const Eigen::Vector2d& x) {
  if (p.ring.empty()) return (x - p.centre).norm() - p.radius_m;
  SignedRingDistance d(x);
  for (std::size_t i = 0; i < p.ring.size(); ++i) {
    if (const auto e = ringEdge(p.ring[i], p.ring[(i + 1) % p.ring.size()])) d.add(*e);
  }
  return d.value();
}

/// Signed vertical distance from z to [floor, ceiling]: positive outside, negative inside.
double signedVerticalDistance(double floor, double ceiling, double z) { return std::max(floor - z, z - ceiling); }

/// The piece's height interval as FCL gets it: finite limits as they are; an unlimited floor
/// (ceiling) at the bottom (top) of the modelled band, or 1 km beyond the other limit when that
/// lies outside the band — so within the band the shape is the piece.
std::pair<double, double> fclHeights(const airspace::PlanarPrism& q) {
  constexpr double kBeyond_m = 1000.0;
  const double lo = std::isfinite(q.floor_h_ell_m)
                        ? q.floor_h_ell_m
                        : std::min(kSceneFloor_h_ell_m, std::isfinite(q.ceiling_h_ell_m) ? q.ceiling_h_ell_m - kBeyond_m : 0.0);
  const double hi = std::isfinite(q.ceiling_h_ell_m)
                        ? q.ceiling_h_ell_m
                        : std::max(kSceneCeiling_h_ell_m, std::isfinite(q.floor_h_ell_m) ? q.floor_h_ell_m + kBeyond_m : 0.0);
  return {lo, hi};
}

std::string pieceName(std::size_t i, const ScenePiece& p) {
  std::ostringstream s;
  s << "piece " << i << " (" << (p.owner == PieceOwner::kZone ? "zone " : "obstacle ") << p.owner_index << ")";
  return s.str();
}

void validatePiece(std::size_t i, const ScenePiece& p) {
  const airspace::PlanarPrism& q = p.prism;
  if (std::isnan(q.floor_h_ell_m) || std::isnan(q.ceiling_h_ell_m) || !(q.floor_h_ell_m < q.ceiling_h_ell_m)) {
    std::ostringstream s;
    s << pieceName(i, p) << ": floor " << q.floor_h_ell_m << " m must be below ceiling " << q.ceiling_h_ell_m << " m";
    throw std::invalid_argument(s.str());
  }
  if (q.ring.empty()) {
    if (!q.centre.allFinite() || !(std::isfinite(q.radius_m) && q.radius_m > 0)) {
      throw std::invalid_argument(pieceName(i, p) + ": a disk needs a finite centre and a positive radius");
    }
    return;
  }
  if (q.ring.size() < 3) throw std::invalid_argument(pieceName(i, p) + ": a ring needs at least 3 vertices");
  double area2 = 0;
  for (std::size_t k = 0; k < q.ring.size(); ++k) {
    const Eigen::Vector2d& a = q.ring[k];
    const Eigen::Vector2d& b = q.ring[(k + 1) % q.ring.size()];
    const Eigen::Vector2d& c = q.ring[(k + 2) % q.ring.size()];
    if (!a.allFinite()) throw std::invalid_argument(pieceName(i, p) + ": non-finite vertex");
    const Eigen::Vector2d ab = b - a, bc = c - b;
    if (ab.x() * bc.y() - ab.y() * bc.x() < -kConvexityTolerance * ab.norm() * bc.norm()) {
      throw std::invalid_argument(pieceName(i, p) + ": the ring must be convex and counter-clockwise (vertex " +
                                  std::to_string((k + 1) % q.ring.size()) + " turns right)");
    }
    area2 += a.x() * b.y() - b.x() * a.y();
  }
  if (!(area2 > 0)) throw std::invalid_argument(pieceName(i, p) + ": the ring has no area");
}

/// The query's own checks: a valid volume, a horizon ≥ 0, and heights inside the modelled band.
void checkQuery(const ProtectionVolume& volume, double horizon_m) {
  requireValid(volume);
  const Eigen::Vector3d& p = volume.p_map;
  if (!(std::isfinite(horizon_m) && horizon_m >= 0)) {
    throw std::invalid_argument("clearance horizon must be a finite number of metres ≥ 0, got " + std::to_string(horizon_m));
  }
  if (p.z() - volume.vpl_m < kSceneFloor_h_ell_m || p.z() + volume.vpl_m > kSceneCeiling_h_ell_m) {
    std::ostringstream s;
    s << "protection volume " << p.z() - volume.vpl_m << " … " << p.z() + volume.vpl_m
      << " m (ellipsoidal) reaches outside the modelled heights " << kSceneFloor_h_ell_m << " … "
      << kSceneCeiling_h_ell_m << " m";
    throw std::invalid_argument(s.str());
  }
}

/// Broad phase over the pieces' FCL AABBs: a uniform grid over x–y in one flat array (CSR:
/// each cell's entries one after the other), each entry a copy of its piece's FCL AABB, the
/// piece index and the cell of the box's lower corner (read in order, 56 bytes an entry). A
/// query visits the cells its box covers and tests each entry with FCL's rule (closed boxes:
/// touching overlaps) — so the grid finds exactly the pieces FCL's
/// DynamicAABBTreeCollisionManager::collide found, without its pointer chase down a tree of
/// 150 k leaves and a callback per overlap. A piece spanning several cells is reported only
/// from the cell holding the lower corner of its overlap with the query box (no duplicate, no
/// scratch set). Pieces spanning more than kMaxCellsPerPiece cells (a country-wide zone) sit in
/// one list every query tests.
class PieceGrid {
 public:
  /// Most cells one piece is entered in; a larger piece goes to the list of big pieces.
  static constexpr std::size_t kMaxCellsPerPiece = 64;
  /// Cells per piece at most (the grid's size: more cells make the offsets array outgrow the
  /// caches — on bench_fence's sparse scene, cells of 0.75 × the mean piece side, 4 M of them,
  /// made the query 2.8 times slower than one cell per piece).
  static constexpr double kCellsPerPiece = 1.0;
  /// Most cells along one axis.
  static constexpr int kMaxCellsPerAxis = 4096;

  /// `keys[i]` is what collect() reports for piece i (its ownerKey()).
  void build(std::vector<detail::FclBox> boxes, std::vector<std::uint64_t> keys);
  /// Appends to `out` the key of every piece whose AABB meets `q` (closed boxes), in no
  /// particular order.
  void collect(const detail::FclBox& q, std::vector<std::uint64_t>& out) const;

 private:
  /// A piece's entry in a cell: its FCL AABB (read in order with the cell, so the exact test
  /// needs no look-up elsewhere) and the cell of the box's lower corner (for reporting it once).
  struct Entry {
    detail::FclBox box;
    std::uint32_t piece;
    std::uint16_t cx0, cy0;
  };
  /// FCL's AABB::overlap.
  [[nodiscard]] static bool overlaps(const detail::FclBox& a, const detail::FclBox& q) {
    return !(a.min[0] > q.max[0] || a.min[1] > q.max[1] || a.min[2] > q.max[2] || q.min[0] > a.max[0] ||
             q.min[1] > a.max[1] || q.min[2] > a.max[2]);
  }
  [[nodiscard]] int cellX(double x) const {
    return static_cast<int>(std::clamp(std::floor((x - x0_) * inv_cell_), 0.0, static_cast<double>(nx_ - 1)));
  }
  [[nodiscard]] int cellY(double y) const {
    return static_cast<int>(std::clamp(std::floor((y - y0_) * inv_cell_), 0.0, static_cast<double>(ny_ - 1)));
  }
  /// Calls f(cell) for each cell of piece i's box; false (and no call) when it spans too many.
  template <typename F>
  bool forCells(std::size_t i, F&& f) const {
    const detail::FclBox& b = boxes_[i];
    const int cx0 = cellX(b.min[0]), cx1 = cellX(b.max[0]), cy0 = cellY(b.min[1]), cy1 = cellY(b.max[1]);
    if (static_cast<std::size_t>(cx1 - cx0 + 1) * static_cast<std::size_t>(cy1 - cy0 + 1) > kMaxCellsPerPiece) return false;
    for (int cy = cy0; cy <= cy1; ++cy) {
      for (int cx = cx0; cx <= cx1; ++cx) f(static_cast<std::size_t>(cy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(cx));
    }
    return true;
  }

  std::vector<detail::FclBox> boxes_;      ///< per piece, FCL's AABB
  std::vector<std::uint64_t> keys_;        ///< per piece, what collect() reports
  std::vector<std::uint32_t> cell_start_;  ///< nx·ny + 1 offsets into entries_
  std::vector<Entry> entries_;
  std::vector<std::uint32_t> big_pieces_;
  double x0_ = 0, y0_ = 0, inv_cell_ = 1;
  int nx_ = 1, ny_ = 1;
};

void PieceGrid::build(std::vector<detail::FclBox> boxes, std::vector<std::uint64_t> keys) {
  keys_ = std::move(keys);
  boxes_ = std::move(boxes);
  entries_.clear();
  big_pieces_.clear();
  cell_start_.assign(2, 0);
  if (boxes_.empty()) return;
  double x_lo = kInf, y_lo = kInf, x_hi = -kInf, y_hi = -kInf, area = 0;
  for (const detail::FclBox& b : boxes_) {
    x_lo = std::min(x_lo, b.min[0]);
    y_lo = std::min(y_lo, b.min[1]);
    x_hi = std::max(x_hi, b.max[0]);
    y_hi = std::max(y_hi, b.max[1]);
    area += (b.max[0] - b.min[0]) * (b.max[1] - b.min[1]);
  }
  const double extent = std::max({x_hi - x_lo, y_hi - y_lo, 1.0});
  // Cell side: the mean piece's (root of the mean AABB area), and no more than kCellsPerPiece
  // cells per piece.
  const double n = static_cast<double>(boxes_.size());
  const double mean_side = std::sqrt(area / n);
  const double by_count = std::sqrt((x_hi - x_lo) * (y_hi - y_lo) / (kCellsPerPiece * n));
  double cell = std::max({mean_side, by_count, extent / kMaxCellsPerAxis});
  if (!(cell > 0) || !std::isfinite(cell)) cell = extent;
  x0_ = x_lo;
  y0_ = y_lo;
  inv_cell_ = 1.0 / cell;
  nx_ = std::clamp(static_cast<int>(std::ceil((x_hi - x_lo) * inv_cell_)), 1, kMaxCellsPerAxis);
  ny_ = std::clamp(static_cast<int>(std::ceil((y_hi - y_lo) * inv_cell_)), 1, kMaxCellsPerAxis);
  const std::size_t cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  // Two passes (count, then fill) into one flat array.
  std::vector<std::uint32_t> next(cells + 1, 0);
  for (std::size_t i = 0; i < boxes_.size(); ++i) {
    if (!forCells(i, [&](std::size_t c) { ++next[c + 1]; })) big_pieces_.push_back(static_cast<std::uint32_t>(i));
  }
  for (std::size_t c = 0; c < cells; ++c) next[c + 1] += next[c];
  cell_start_ = next;
  entries_.resize(cell_start_.back());
  for (std::size_t i = 0; i < boxes_.size(); ++i) {
    const detail::FclBox& b = boxes_[i];
    const auto cx0 = static_cast<std::uint16_t>(cellX(b.min[0])), cy0 = static_cast<std::uint16_t>(cellY(b.min[1]));
    (void)forCells(i, [&](std::size_t c) { entries_[next[c]++] = Entry{b, static_cast<std::uint32_t>(i), cx0, cy0}; });
  }
}

void PieceGrid::collect(const detail::FclBox& q, std::vector<std::uint64_t>& out) const {
  for (const std::uint32_t i : big_pieces_) {
    if (overlaps(boxes_[i], q)) out.push_back(keys_[i]);
  }
  if (entries_.empty()) return;
  const int cx0 = cellX(q.min[0]), cx1 = cellX(q.max[0]), cy0 = cellY(q.min[1]), cy1 = cellY(q.max[1]);
  for (int cy = cy0; cy <= cy1; ++cy) {
    const std::size_t row = static_cast<std::size_t>(cy) * static_cast<std::size_t>(nx_);
    const Entry* e = entries_.data() + cell_start_[row + static_cast<std::size_t>(cx0)];
    for (int cx = cx0; cx <= cx1; ++cx) {
      const Entry* end = entries_.data() + cell_start_[row + static_cast<std::size_t>(cx) + 1];
      for (; e != end; ++e) {
        if (!overlaps(e->box, q)) continue;
        // Report from one cell only: the one holding the lower corner of box ∩ query (cellX and
        // cellY do not decrease, so the cell of a maximum is the maximum of the cells).
        if (std::max<int>(e->cx0, cx0) != cx || std::max<int>(e->cy0, cy0) != cy) continue;
        out.push_back(keys_[e->piece]);
      }
    }
  }
}

}  // namespace

namespace detail {

FclBox cylinderBox(const Eigen::Vector3d& p, double radius_m, double half_m) {
  return {{p.x() - radius_m, p.y() - radius_m, p.z() - half_m}, {p.x() + radius_m, p.y() + radius_m, p.z() + half_m}};
}

const FclModule& fclModule() {
  static const FclModule& module = []() -> const FclModule& {
    const maps::detail::ModuleSpec spec{kFclModuleFile, "SKYLANE_FCL_MODULE", "skylane_fcl_module_v3",
                                        SKYLANE_FCL_MODULE_BUILD_PATH, SKYLANE_FCL_MODULE_INSTALL_PATH,
                                        "checking protection volumes against zones and obstacles"};
    static_assert(kFclModuleAbi == 3, "rename the entry point with the ABI version");
    return maps::detail::moduleTable<FclModule>(spec);
  }();
  return module;
}

}  // namespace detail

namespace {

/// The separation the two margins give (Separation's formulas).
Separation fromMargins(double margin_h_m, double margin_v_m) {
  Separation s;
  s.margin_h_m = margin_h_m;
  s.margin_v_m = margin_v_m;
  s.meets = std::max(margin_h_m, margin_v_m) <= 0;
  s.clearance_m = std::hypot(std::max(margin_h_m, 0.0), std::max(margin_v_m, 0.0));
  return s;
}

}  // namespace

Separation separationMargins(const ProtectionVolume& volume, const airspace::PlanarPrism& piece) {
  return fromMargins(signedHorizontalDistance(piece, volume.p_map.head<2>()) - volume.hpl_m,
                     signedVerticalDistance(piece.floor_h_ell_m, piece.ceiling_h_ell_m, volume.p_map.z()) - volume.vpl_m);
}

namespace {

/// What the broad phase reports for a piece, in one word that sorts owner by owner and then by
/// piece: the owner kind (bit 63), the owner's index (bits 32–62) and the piece's (bits 0–31).
std::uint64_t ownerKey(const ScenePiece& p, std::size_t i) {
  return (static_cast<std::uint64_t>(p.owner == PieceOwner::kObstacle) << 63) |
         (static_cast<std::uint64_t>(p.owner_index) << 32) | static_cast<std::uint64_t>(i);
}
/// The margin that decides meeting: the volume meets the piece iff it is ≤ 0.
double deciding(const Separation& s) { return std::max(s.margin_h_m, s.margin_v_m); }

std::size_t keyPiece(std::uint64_t key) { return static_cast<std::size_t>(key & 0xffffffffu); }
std::uint64_t keyOwner(std::uint64_t key) { return key >> 32; }
PieceOwner keyOwnerKind(std::uint64_t key) { return (key >> 63) != 0 ? PieceOwner::kObstacle : PieceOwner::kZone; }
std::size_t keyOwnerIndex(std::uint64_t key) { return static_cast<std::size_t>((key >> 32) & 0x7fffffffu); }

/// The pieces' shapes laid out for separationMargins' formulas: each piece's ring edges
/// (ringEdge, computed once) one after the other, so that the margins are the same to the bit.
class ShapeTable {
 public:
  void add(const airspace::PlanarPrism& p);
  /// separationMargins(volume, piece i).
  [[nodiscard]] Separation margins(const ProtectionVolume& volume, std::size_t i) const;
  /// The vector from `centre` to the nearest point of piece i (zero when the centre lies in it):
  /// where FCL's own GJK starts its search (FclPieces::distance).
  [[nodiscard]] Eigen::Vector3d towardPiece(const Eigen::Vector3d& centre, std::size_t i) const;
  /// Asks the processor for piece i's record, then (once it is there) for its edges: a query's
  /// pieces lie far apart in memory, and reading them one after the other waited on each.
  void prefetchShape(std::size_t i) const { __builtin_prefetch(&shapes_[i]); }
  void prefetchEdges(std::size_t i) const {
    const Shape& p = shapes_[i];
    const char* first = reinterpret_cast<const char*>(edges_.data() + p.first);
    const char* end = reinterpret_cast<const char*>(edges_.data() + p.first + p.count);
    for (const char* a = first; a < end; a += 64) __builtin_prefetch(a);
  }

 private:
  struct Shape {
    std::uint32_t first = 0, count = 0;  ///< edges; none for a disk
    double floor = 0, ceiling = 0;
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    double radius = 0;
  };
  std::vector<Shape> shapes_;
  std::vector<RingEdge> edges_;
};

void ShapeTable::add(const airspace::PlanarPrism& p) {
  Shape s{static_cast<std::uint32_t>(edges_.size()), 0, p.floor_h_ell_m, p.ceiling_h_ell_m, p.centre, p.radius_m};
  for (std::size_t i = 0; i < p.ring.size(); ++i) {
    if (const auto e = ringEdge(p.ring[i], p.ring[(i + 1) % p.ring.size()])) {
      edges_.push_back(*e);
      ++s.count;
    }
  }
  shapes_.push_back(s);
}

Separation ShapeTable::margins(const ProtectionVolume& volume, std::size_t i) const {
  const Shape& p = shapes_[i];
  const Eigen::Vector2d x = volume.p_map.head<2>();
  double horizontal = 0.0;
  if (p.count == 0) {
    horizontal = (x - p.centre).norm() - p.radius;
  } else {
    SignedRingDistance d(x);
    for (const RingEdge* e = edges_.data() + p.first, *end = e + p.count; e != end; ++e) d.add(*e);
    horizontal = d.value();
  }
  return fromMargins(horizontal - volume.hpl_m, signedVerticalDistance(p.floor, p.ceiling, volume.p_map.z()) - volume.vpl_m);
}

Eigen::Vector3d ShapeTable::towardPiece(const Eigen::Vector3d& centre, std::size_t i) const {
  const Shape& p = shapes_[i];
  Eigen::Vector2d to_shape = Eigen::Vector2d::Zero();
  if (p.count == 0) {
    const Eigen::Vector2d out = centre.head<2>() - p.centre;
    const double r = out.norm();
    if (r > p.radius) to_shape = -out * ((r - p.radius) / r);
  } else {
    bool inside = true;
    double nearest2 = kInf;
    for (const RingEdge* e = edges_.data() + p.first, *end = e + p.count; e != end; ++e) {
      const EdgeView v = viewFromEdge(*e, centre.head<2>());
      if (v.cross < 0) inside = false;
      if (v.dx * v.dx + v.dy * v.dy < nearest2) {
        nearest2 = v.dx * v.dx + v.dy * v.dy;
        to_shape = {-v.dx, -v.dy};
      }
    }
    if (inside) to_shape.setZero();
  }
  return {to_shape.x(), to_shape.y(), std::clamp(centre.z(), p.floor, p.ceiling) - centre.z()};
}

}  // namespace

struct Scene::Impl {
  std::vector<ScenePiece> pieces;
  std::unique_ptr<detail::FclPieces> fcl;  ///< the pieces as FCL objects (libskylane_fcl.so)
  PieceGrid grid;
  ShapeTable shapes;

  /// A piece and its separation from the query volume.
  using Candidate = std::pair<std::size_t, Separation>;

  /// Broad phase: the keys (ownerKey) of the pieces whose AABBs meet `reach`'s, sorted owner by
  /// owner, into `found`.
  void candidates(const detail::FclBox& reach, std::vector<std::uint64_t>& found) const;
  /// End of the run of candidates from `first` on that share its owner.
  [[nodiscard]] static std::size_t ownerEnd(const std::vector<std::uint64_t>& candidates, std::size_t first);
  /// Calls visit(kind, index, begin, end) for the run [begin, end) of each owner `accept`
  /// takes, in order, until visit returns true; whether one did.
  template <class Visit>
  static bool forAcceptedOwners(const std::vector<std::uint64_t>& candidates,
                                const std::function<bool(PieceOwner, std::size_t)>& accept, Visit&& visit) {
    for (std::size_t first = 0; first < candidates.size();) {
      const std::size_t begin = first;
      first = ownerEnd(candidates, first);
      const PieceOwner kind = keyOwnerKind(candidates[begin]);
      const std::size_t index = keyOwnerIndex(candidates[begin]);
      if (accept(kind, index) && visit(kind, index, begin, first)) return true;
    }
    return false;
  }
  /// The query volume and whether this thread's FCL query cylinder is it yet: it is placed on
  /// the first narrow-phase distance of a query (most queries need none).
  struct NarrowQuery {
    const ProtectionVolume& volume;
    bool cylinder_placed = false;
  };
  /// Narrow phase of piece i against the volume (this thread's FCL query cylinder), starting
  /// from its closed-form separation.
  [[nodiscard]] Separation settle(std::size_t i, NarrowQuery& query, Separation s) const;
  /// One owner's candidates with their margins, sorted by deciding margin: [begin, end) of a
  /// query's list of candidates.
  struct OwnerGroup {
    PieceOwner kind;
    std::size_t index;
    std::size_t begin, end;
  };
  /// Appends the candidates [begin, end) of one owner, with their margins, to `group`, sorted
  /// by deciding margin, and asks FCL's module to prefetch the pieces the narrow phase will
  /// measure first (the first and the nearest).
  void appendOwnerGroup(const std::vector<std::uint64_t>& candidates, std::size_t begin, std::size_t end,
                        const ProtectionVolume& volume, std::vector<Candidate>& group) const;
  /// Whether query() at horizon 0 reports piece i (reachesAny).
  [[nodiscard]] bool reachedAtContact(std::size_t i, const ProtectionVolume& volume) const;
  /// The hit (or the nearest miss) among one owner's sorted candidates.
  [[nodiscard]] std::optional<SceneHit> ownerHit(const OwnerGroup& owner, std::vector<Candidate>& group,
                                                 NarrowQuery& query, double horizon_m) const;
};

void Scene::Impl::candidates(const detail::FclBox& reach, std::vector<std::uint64_t>& found) const {
  found.clear();
  grid.collect(reach, found);
  std::sort(found.begin(), found.end());
}

std::size_t Scene::Impl::ownerEnd(const std::vector<std::uint64_t>& found, std::size_t first) {
  std::size_t last = first;
  while (last < found.size() && keyOwner(found[last]) == keyOwner(found[first])) ++last;
  return last;
}

Separation Scene::Impl::settle(std::size_t i, NarrowQuery& query, Separation s) const {
  const ProtectionVolume& volume = query.volume;
  if (!query.cylinder_placed) {
    (void)fcl->placeCylinder(volume.p_map, std::max(volume.hpl_m, kFclMinSize_m), std::max(volume.vpl_m, kFclMinSize_m));
    query.cylinder_placed = true;
  }
  // FCL 0.7.0's two GJK solvers each stop metres off on some elongated pairs: libccd (its
  // default) beside a piece kilometres tall (an unlimited ceiling), its own (GST_INDEP) for a
  // thin tall volume (HPL ≪ VPL) — cases kept in tests/geofence/scene_test.cpp. So each is the
  // other's second opinion; FCL's answer counts where either agrees with the closed form, and
  // the exact predicate settles the rest. FCL's own goes first, its search started toward the
  // piece's nearest point: against a curved side (a disk's cylinder) a search from FCL's fixed
  // start creeps up on the distance, one started there converges in a few steps; with the piece
  // as its first shape it is also the quicker per vertex (fcl_module.cpp), at every ring size
  // measured (BM_OneZone: 4 to 64 sides).
  static constexpr std::array<detail::GjkSolver, 2> kSolvers{detail::GjkSolver::kIndep, detail::GjkSolver::kLibccd};
  const airspace::PlanarPrism& prism = pieces[i].prism;
  // FCL decides when its distance agrees with the closed form (Separation) to kExactBand_m and
  // both are clear of contact by more than the band, or when it reports contact and the
  // margins put the volume deep inside; anything else — contact, a near miss, a disagreement,
  // a failure — goes to the exact predicate. The clearance reported is the closed form.
  const double deciding_m = std::max(s.margin_h_m, s.margin_v_m);
  for (const detail::GjkSolver solver : kSolvers) {
    double d = 0.0;
    try {
      // From this thread's query cylinder, the volume (query()); only FCL's own GJK takes a start.
      const Eigen::Vector3d toward_piece =
          solver == detail::GjkSolver::kIndep ? shapes.towardPiece(volume.p_map, i) : Eigen::Vector3d::Zero();
      d = fcl->distance(i, solver, toward_piece);
    } catch (const std::exception&) {
      s.fcl_failed = true;  // FCL's GJK/EPA can throw near contact
      continue;
    }
    s.fcl_distance_m = d;
    if (d > kExactBand_m && deciding_m > kExactBand_m && std::abs(d - s.clearance_m) <= kExactBand_m) {
      s.meets = false;
      return s;
    }
    if (d <= 0 && deciding_m < -kExactBand_m) {
      s.meets = true;
      s.clearance_m = 0;
      return s;
    }
    if (std::abs(deciding_m) <= kExactBand_m) break;  // near contact: no solver can settle it
  }
  s.exact = true;
  s.meets = airspace::cylinderMeetsPrism(volume.p_map, volume.hpl_m, volume.vpl_m, prism);
  s.clearance_m = s.meets ? 0.0 : std::hypot(std::max(s.margin_h_m, 0.0), std::max(s.margin_v_m, 0.0));
  return s;
}

void Scene::Impl::appendOwnerGroup(const std::vector<std::uint64_t>& found, std::size_t begin, std::size_t end,
                                   const ProtectionVolume& volume, std::vector<Candidate>& group) const {
  const auto first = static_cast<std::ptrdiff_t>(group.size());
  for (std::size_t k = begin; k < end; ++k) shapes.prefetchEdges(keyPiece(found[k]));
  for (std::size_t k = begin; k < end; ++k) group.emplace_back(keyPiece(found[k]), shapes.margins(volume, keyPiece(found[k])));
  std::sort(group.begin() + first, group.end(),
            [](const auto& a, const auto& b) { return deciding(a.second) < deciding(b.second); });
  const auto nearest = std::min_element(group.begin() + first, group.end(), [](const auto& a, const auto& b) {
    return a.second.clearance_m < b.second.clearance_m;
  });
  fcl->prefetch(group[static_cast<std::size_t>(first)].first);
  fcl->prefetch(nearest->first);
}

std::optional<SceneHit> Scene::Impl::ownerHit(const OwnerGroup& owner, std::vector<Candidate>& group,
                                              NarrowQuery& query, double horizon_m) const {
  const auto at = [&](std::size_t k) -> Candidate& { return group[owner.begin + k]; };
  const std::size_t n = owner.end - owner.begin;
  std::optional<SceneHit> hit;
  std::size_t evaluated = 0;
  for (; evaluated < n && deciding(at(evaluated).second) <= kExactBand_m; ++evaluated) {
    const Separation s = settle(at(evaluated).first, query, at(evaluated).second);
    if (s.meets) {
      hit = SceneHit{owner.kind, owner.index, at(evaluated).first, s};
      break;
    }
    if (!hit || s.clearance_m < hit->separation.clearance_m) hit = SceneHit{owner.kind, owner.index, at(evaluated).first, s};
  }
  if (!hit || !hit->separation.meets) {
    // The nearest of the pieces not yet evaluated, when it may lie within the horizon.
    const auto rest = group.begin() + static_cast<std::ptrdiff_t>(owner.begin + std::min(evaluated, n));
    const auto end = group.begin() + static_cast<std::ptrdiff_t>(owner.end);
    const auto nearest = std::min_element(rest, end, [](const auto& a, const auto& b) {
      return a.second.clearance_m < b.second.clearance_m;
    });
    if (nearest != end && nearest->second.clearance_m <= horizon_m + kExactBand_m &&
        (!hit || nearest->second.clearance_m < hit->separation.clearance_m)) {
      hit = SceneHit{owner.kind, owner.index, nearest->first, settle(nearest->first, query, nearest->second)};
    }
  }
  return hit;
}

bool Scene::Impl::reachedAtContact(std::size_t i, const ProtectionVolume& volume) const {
  const double d = deciding(shapes.margins(volume, i));
  if (d <= 0.0) return true;  // met, or (the exact predicate disagreeing) clearance 0
  if (d > kExactBand_m) return false;
  return airspace::cylinderMeetsPrism(volume.p_map, volume.hpl_m, volume.vpl_m, pieces[i].prism);
}

Scene::Scene(std::vector<ScenePiece> pieces) : impl_(std::make_unique<Impl>()) {
  impl_->pieces = std::move(pieces);
  impl_->fcl = detail::fclModule().make();
  if (impl_->pieces.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("a scene holds at most 4294967295 pieces, got " + std::to_string(impl_->pieces.size()));
  }
  std::vector<detail::FclBox> boxes;
  std::vector<std::uint64_t> keys;
  boxes.reserve(impl_->pieces.size());
  keys.reserve(impl_->pieces.size());
  for (std::size_t i = 0; i < impl_->pieces.size(); ++i) {
    const ScenePiece& p = impl_->pieces[i];
    validatePiece(i, p);
    if (p.owner_index >= (std::size_t{1} << 31)) throw std::invalid_argument(pieceName(i, p) + ": owner index above 2^31 − 1");
    const auto [z_lo, z_hi] = fclHeights(p.prism);
    boxes.push_back(impl_->fcl->add(p.prism, z_lo, z_hi));
    keys.push_back(ownerKey(p, i));
    impl_->shapes.add(p.prism);
  }
  impl_->grid.build(std::move(boxes), std::move(keys));
}

Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

const std::vector<ScenePiece>& Scene::pieces() const { return impl_->pieces; }

std::vector<SceneHit> Scene::query(const ProtectionVolume& volume, double horizon_m,
                                   const std::function<bool(PieceOwner, std::size_t)>& accept) const {
  std::vector<SceneHit> hits;
  query(volume, horizon_m, accept, hits);
  return hits;
}

void Scene::query(const ProtectionVolume& volume, double horizon_m,
                  const std::function<bool(PieceOwner, std::size_t)>& accept, std::vector<SceneHit>& hits) const {
  hits.clear();
  checkQuery(volume, horizon_m);
  // Broad phase: the AABB of the volume's cylinder grown by the horizon, against the grid.
  // The narrow phase's distances are from this thread's FCL query cylinder, placed as the
  // volume itself before the first one (the module keeps one per thread: no allocation per
  // query; nothing between then and the last distance places another).
  const detail::FclBox reach = detail::cylinderBox(volume.p_map, volume.hpl_m + horizon_m, volume.vpl_m + horizon_m);
  Impl::NarrowQuery narrow{volume};
  // Per-thread scratch: no allocation per query once it has grown.
  thread_local std::vector<std::uint64_t> candidates;
  thread_local std::vector<Impl::Candidate> group;
  thread_local std::vector<Impl::OwnerGroup> owners;
  impl_->candidates(reach, candidates);
  for (const std::uint64_t key : candidates) impl_->shapes.prefetchShape(keyPiece(key));

  // The margins of every accepted owner's pieces first (FCL's data prefetched meanwhile), then
  // the narrow phase owner by owner.
  group.clear();
  owners.clear();
  Impl::forAcceptedOwners(candidates, accept, [&](PieceOwner kind, std::size_t index, std::size_t begin, std::size_t end) {
    const std::size_t from = group.size();
    impl_->appendOwnerGroup(candidates, begin, end, volume, group);
    owners.push_back({kind, index, from, group.size()});
    return false;
  });
  for (const Impl::OwnerGroup& owner : owners) {
    const std::optional<SceneHit> hit = impl_->ownerHit(owner, group, narrow, horizon_m);
    if (hit && (hit->separation.meets || hit->separation.clearance_m <= horizon_m)) hits.push_back(*hit);
  }
}

bool Scene::reachesAny(const ProtectionVolume& volume, const std::function<bool(PieceOwner, std::size_t)>& accept) const {
  checkQuery(volume, 0.0);
  const detail::FclBox reach = detail::cylinderBox(volume.p_map, volume.hpl_m, volume.vpl_m);
  thread_local std::vector<std::uint64_t> candidates;
  impl_->candidates(reach, candidates);
  return Impl::forAcceptedOwners(candidates, accept, [&](PieceOwner, std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      if (impl_->reachedAtContact(keyPiece(candidates[k]), volume)) return true;
    }
    return false;
  });
}

}  // namespace skylane::geofence
