#include "planner/lattice_search.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <queue>
#include <set>
#include <unordered_map>

namespace skylane::planner {

bool motionIsValid(const PathProblem& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, bool with_ends,
                   std::uint64_t* checks) {
  const double len = (b - a).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(len / p.resolution_m)));
  for (int i = with_ends ? 0 : 1; i <= (with_ends ? steps : steps - 1); ++i) {
    if (checks) ++*checks;
    if (!p.is_valid(a + (b - a) * (static_cast<double>(i) / steps))) return false;
  }
  return true;
}

namespace {

/// The 16 horizontal moves (king and knight moves of the grid).
constexpr std::array<std::array<int, 2>, 16> kMoves{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {1, -1}, {-1, 1},
                                                     {-1, -1}, {1, 2}, {2, 1}, {-1, 2}, {-2, 1}, {1, -2}, {2, -1},
                                                     {-1, -2}, {-2, -1}}};
constexpr int kBias = 1 << 20;  ///< grid indices are stored biased, 21 bits each
constexpr std::uint64_t kGoalKey = std::numeric_limits<std::uint64_t>::max();
/// The goal is reached from a node this many steps away (horizontally), past one knight move.
constexpr double kGoalReach = 2.3;

struct NodeIndex {
  int i = 0, j = 0, k = 0;
};

std::uint64_t keyOf(const NodeIndex& n) {
  return (static_cast<std::uint64_t>(n.i + kBias) << 24) | (static_cast<std::uint64_t>(n.j + kBias) << 3) |
         static_cast<std::uint64_t>(n.k + 1);
}
NodeIndex indexOf(std::uint64_t key) {
  return {static_cast<int>((key >> 24) & 0x1FFFFF) - kBias, static_cast<int>((key >> 3) & 0x1FFFFF) - kBias,
          static_cast<int>(key & 0x7) - 1};
}

/// One lattice: step h, layers −L…L of dz about the leg's own height surface.
struct Lattice {
  const PathProblem& p;
  double h = 0.0, dz = 0.0;
  int layers = 0;  ///< L
  Eigen::Vector2d s, d;  ///< the leg's start (x, y) and its horizontal direction to the goal
  double len2 = 0.0;

  Lattice(const PathProblem& problem, double step, int half_layers) : p(problem), h(step), layers(half_layers) {
    s = p.start_enu_m.head<2>();
    d = p.goal_enu_m.head<2>() - s;
    len2 = d.squaredNorm();
    dz = std::max(h, (p.upper_enu_m.z() - p.lower_enu_m.z()) / 4.0);
  }
  [[nodiscard]] Eigen::Vector3d position(const NodeIndex& n) const {
    const Eigen::Vector2d xy = s + h * Eigen::Vector2d(n.i, n.j);
    const double t = len2 > 0.0 ? std::clamp((xy - s).dot(d) / len2, 0.0, 1.0) : 0.0;
    const double z = p.start_enu_m.z() + t * (p.goal_enu_m.z() - p.start_enu_m.z()) + n.k * dz;
    return {xy.x(), xy.y(), z};
  }
  [[nodiscard]] bool inBox(const Eigen::Vector3d& x) const {
    return (x.array() >= p.lower_enu_m.array()).all() && (x.array() <= p.upper_enu_m.array()).all();
  }
  /// Motion cost: length, times 1 + the extra cost at its middle when there is one.
  [[nodiscard]] double cost(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    const double len = (b - a).norm();
    return p.extra_cost ? len * (1.0 + p.extra_cost->at(0.5 * (a + b))) : len;
  }
};

struct OpenEntry {
  double f = 0.0, g = 0.0;
  std::uint64_t key = 0, parent = 0;
};
/// Smallest f first; ties by the smaller key (deterministic).
struct OpenOrder {
  bool operator()(const OpenEntry& a, const OpenEntry& b) const { return a.f != b.f ? a.f > b.f : a.key > b.key; }
};

struct NodeRecord {
  double g_best = std::numeric_limits<double>::infinity();
  std::uint64_t parent = 0;
  signed char valid = -1;  ///< -1 not checked, 0 invalid, 1 valid
  bool closed = false;
};

/// One weighted A* over one lattice; lazy: a node and the motion reaching it are checked when the
/// node leaves the open list.
class LatticeAStar {
 public:
  LatticeAStar(const Lattice& lattice, const LatticeOptions& o, LatticeResult& r, std::chrono::steady_clock::time_point t0)
      : l_(lattice), o_(o), r_(r), t0_(t0) {}

  bool run(std::vector<Eigen::Vector3d>& path) {
    const std::uint64_t start = keyOf({0, 0, 0});
    nodes_[start] = {0.0, start, 1, false};
    open_.push({heuristic(l_.p.start_enu_m), 0.0, start, start});
    while (!open_.empty()) {
      const OpenEntry e = open_.top();
      open_.pop();
      if (outOfBudget()) return false;
      if (e.key == kGoalKey) {
        if (!innerSamplesValid(l_.position(indexOf(e.parent)), l_.p.goal_enu_m)) continue;  // the goal is valid
        path = reconstruct(e.parent);
        path.push_back(l_.p.goal_enu_m);
        return true;
      }
      if (!take(e)) continue;
      expand(e.key);
    }
    return false;
  }

 private:
  [[nodiscard]] double heuristic(const Eigen::Vector3d& x) const {
    return o_.heuristic_weight * (l_.p.goal_enu_m - x).norm();
  }
  bool outOfBudget() {
    if (r_.state_checks >= o_.max_state_checks) {
      r_.stopped_by_budget = true;
      return true;
    }
    if ((++r_.expansions & 1023u) == 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count() > o_.time_limit_s) {
      r_.stopped_by_time = true;
    }
    return r_.stopped_by_time;
  }
  /// The entry's node, if it is still open and it and the motion from its parent are valid.
  bool take(const OpenEntry& e) {
    NodeRecord& n = nodes_[e.key];
    if (n.closed || e.g > n.g_best) return false;
    const Eigen::Vector3d x = l_.position(indexOf(e.key));
    if (n.valid < 0) {
      ++r_.state_checks;
      n.valid = l_.inBox(x) && l_.p.is_valid(x) ? 1 : 0;
    }
    if (n.valid == 0) {
      n.closed = true;
      return false;
    }
    // Both ends are valid: the motion's inner samples every resolution_m.
    if (!innerSamplesValid(l_.position(indexOf(e.parent)), x)) {
      failed_.insert({e.parent, e.key});
      reopen(e.key, x);
      return false;
    }
    n.closed = true;
    n.parent = e.parent;
    return true;
  }
  /// The motion reaching a node failed: it is reached again from each expanded neighbour whose
  /// motion to it has not failed (an entry that lost to the failed one at push time is gone).
  void reopen(std::uint64_t key, const Eigen::Vector3d& x) {
    NodeRecord& n = nodes_[key];
    n.g_best = std::numeric_limits<double>::infinity();
    const NodeIndex c = indexOf(key);
    auto from = [&](const NodeIndex& m) {
      const std::uint64_t mk = keyOf(m);
      const auto it = nodes_.find(mk);
      if (it == nodes_.end() || !it->second.closed || it->second.valid != 1 || failed_.count({mk, key})) return;
      const Eigen::Vector3d y = l_.position(m);
      const double g = it->second.g_best + l_.cost(y, x);
      if (g >= nodes_[key].g_best) return;
      nodes_[key].g_best = g;
      open_.push({g + heuristic(x), g, key, mk});
    };
    for (const auto& mv : kMoves) from({c.i - mv[0], c.j - mv[1], c.k});
    for (int dk : {-1, 1}) {
      if (std::abs(c.k + dk) <= l_.layers) from({c.i, c.j, c.k + dk});
    }
  }
  /// The samples strictly between a and b (motionIsValid's, without its ends), counted.
  bool innerSamplesValid(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return motionIsValid(l_.p, a, b, /*with_ends=*/false, &r_.state_checks);
  }
  void expand(std::uint64_t key) {
    const NodeIndex c = indexOf(key);
    const Eigen::Vector3d x = l_.position(c);
    const double g = nodes_[key].g_best;
    const Eigen::Vector3d& goal = l_.p.goal_enu_m;
    if ((goal.head<2>() - x.head<2>()).norm() <= kGoalReach * l_.h) {
      const double gg = g + l_.cost(x, goal);
      open_.push({gg, gg, kGoalKey, key});
    }
    for (const auto& m : kMoves) push({c.i + m[0], c.j + m[1], c.k}, key, x, g);
    for (int dk : {-1, 1}) {
      if (std::abs(c.k + dk) <= l_.layers) push({c.i, c.j, c.k + dk}, key, x, g);
    }
  }
  void push(const NodeIndex& n, std::uint64_t parent, const Eigen::Vector3d& from, double g_from) {
    if (std::abs(n.i) >= kBias || std::abs(n.j) >= kBias) return;
    const Eigen::Vector3d x = l_.position(n);
    if (!l_.inBox(x)) return;
    const std::uint64_t key = keyOf(n);
    NodeRecord& rec = nodes_[key];
    if (rec.closed || rec.valid == 0) return;
    const double g = g_from + l_.cost(from, x);
    if (g >= rec.g_best) return;
    rec.g_best = g;
    open_.push({g + heuristic(x), g, key, parent});
  }
  std::vector<Eigen::Vector3d> reconstruct(std::uint64_t key) const {
    std::vector<Eigen::Vector3d> out;
    const std::uint64_t start = keyOf({0, 0, 0});
    for (;;) {
      out.push_back(key == start ? l_.p.start_enu_m : l_.position(indexOf(key)));
      if (key == start) break;
      key = nodes_.at(key).parent;
    }
    std::reverse(out.begin(), out.end());
    return out;
  }

  const Lattice& l_;
  const LatticeOptions& o_;
  LatticeResult& r_;
  std::chrono::steady_clock::time_point t0_;
  std::priority_queue<OpenEntry, std::vector<OpenEntry>, OpenOrder> open_;
  std::unordered_map<std::uint64_t, NodeRecord> nodes_;
  std::set<std::pair<std::uint64_t, std::uint64_t>> failed_;  ///< motions (parent, node) found invalid
};

/// The objective of a path on the lattice's terms (length × (1 + extra cost at each middle)).
double pathCost(const Lattice& l, const std::vector<Eigen::Vector3d>& path) {
  double c = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) c += l.cost(path[i - 1], path[i]);
  return c;
}

/// The lattice steps tried, coarse to fine: the leg's length / 128 clamped to
/// [2·resolution, 40 m], halved down to the motion resolution.
std::vector<double> latticeSteps(const PathProblem& p) {
  const double finest = p.resolution_m;
  const double first = std::clamp((p.goal_enu_m - p.start_enu_m).norm() / 128.0, 2.0 * finest, std::max(40.0, 2.0 * finest));
  std::vector<double> steps;
  for (double h = first; h > finest * 1.0001; h /= 2.0) steps.push_back(h);
  steps.push_back(finest);
  return steps;
}

}  // namespace

std::vector<Eigen::Vector3d> withoutCollinearVertices(const std::vector<Eigen::Vector3d>& path) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (out.size() >= 1 && i + 1 < path.size()) {
      const Eigen::Vector3d a = path[i] - out.back(), b = path[i + 1] - path[i];
      if (a.cross(b).norm() <= 1e-9 * a.norm() * b.norm() && a.dot(b) > 0.0) continue;
    }
    out.push_back(path[i]);
  }
  return out;
}

LatticeResult latticeSearch(const PathProblem& p, const LatticeOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  LatticeResult r;
  const std::vector<double> steps = latticeSteps(p);
  double best = std::numeric_limits<double>::infinity();
  for (int half_layers : {0, 1}) {
    int finer_left = 1;  // after the first lattice that finds a path, one finer one more
    for (double h : steps) {
      // Layers above and below only on the coarser lattices: they triple the nodes, and a leg
      // they help (a zone whose floor or ceiling the height surface meets) is rarely that narrow.
      if (half_layers > 0 && h < 2.0 * p.resolution_m) continue;
      if (r.found && finer_left-- == 0) break;
      const Lattice lattice(p, h, half_layers);
      std::vector<Eigen::Vector3d> path;
      const bool found = LatticeAStar(lattice, o, r, t0).run(path);
      const double cost = found ? pathCost(lattice, path) : 0.0;
      if (found && cost < best) {
        best = cost;
        r.found = true;
        r.points = std::move(path);
        r.step_m = h;
        r.layers = 2 * half_layers + 1;
      } else if (!r.found) {  // the finest step searched, and its layers
        r.layers = r.step_m == 0.0 || h < r.step_m ? 2 * half_layers + 1 : r.layers;
        r.step_m = r.step_m == 0.0 ? h : std::min(r.step_m, h);
      }
      if (r.stopped_by_budget || r.stopped_by_time) break;
    }
    if (r.found || r.stopped_by_budget || r.stopped_by_time) break;
  }
  r.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace skylane::planner
