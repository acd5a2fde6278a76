#include "integrity/raim/raim.hpp"

#include "integrity/stats.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <tuple>

namespace skylane::integrity {
namespace {

/// A satellite whose residual projection M_ii is below this (relative to its weight) cannot be
/// checked by the residuals: its fault is undetectable and the slope infinite.
constexpr double kMinResidualObservability = 1e-9;

/// M_ii of the weighted residual projector M = W − W G P Gᵀ W: a bias b on satellite i adds
/// b²·M_ii to the non-centrality of the test statistic.
double residualProjectorDiagonal(const Geometry& g, const WlsSolution& wls, int i) {
  const double w = 1.0 / (g.sigma_int[i] * g.sigma_int[i]);
  return w - w * w * g.G.row(i).dot(wls.P * g.G.row(i).transpose());
}

double ellipseSemiMajor(double pee, double pnn, double pen) {
  const double half_sum = 0.5 * (pee + pnn);
  const double half_diff = 0.5 * (pee - pnn);
  return std::sqrt(half_sum + std::sqrt(half_diff * half_diff + pen * pen));
}

}  // namespace

RaimThresholds raimThresholds(int dof, double pfa, double pmd) {
  static std::mutex mutex;
  static std::map<std::tuple<int, double, double>, RaimThresholds> cache;
  const auto key = std::make_tuple(dof, pfa, pmd);
  {
    const std::lock_guard<std::mutex> lock(mutex);
    const auto it = cache.find(key);
    if (it != cache.end()) return it->second;
  }
  RaimThresholds t;
  t.dof = dof;
  const double t2 = chiSquareUpperQuantile(dof, pfa);
  t.threshold = std::sqrt(t2);
  t.p_bias = std::sqrt(nonCentralityForCdf(dof, t2, pmd));
  const std::lock_guard<std::mutex> lock(mutex);
  cache.emplace(key, t);
  return t;
}

namespace {

/// Why RAIM cannot run on the geometry's satellite count, or empty when it can.
std::string tooFewSatellites(const Geometry& g) {
  const int n = g.numSats(), m = g.numStates();
  if (n > m) return {};
  return "too few satellites: " + std::to_string(n) + " in view, RAIM needs at least " + std::to_string(m + 1) +
         " for " + std::to_string(m) + " unknowns";
}

}  // namespace

RaimPl raimProtectionLevels(const Geometry& g, const RaimConfig& cfg) {
  if (std::string why = tooFewSatellites(g); !why.empty()) {
    RaimPl out;
    out.reason = std::move(why);
    return out;
  }
  return raimProtectionLevels(g, solveWls(g.G, g.sigma_int), cfg);
}

RaimPl raimProtectionLevels(const Geometry& g, const WlsSolution& wls, const RaimConfig& cfg) {
  RaimPl out;
  const int n = g.numSats(), m = g.numStates();
  out.reason = tooFewSatellites(g);
  if (!out.reason.empty()) return out;
  if (!wls.ok) {
    out.reason = "singular geometry: the satellites do not fix position and clock";
    return out;
  }
  out.thresholds = raimThresholds(n - m, cfg.pfa, cfg.pmd);
  out.sigma_h_m = ellipseSemiMajor(wls.P(0, 0), wls.P(1, 1), wls.P(0, 1));
  out.sigma_v_m = std::sqrt(wls.P(2, 2));
  out.hslope.resize(n);
  out.vslope.resize(n);
  for (int i = 0; i < n; ++i) {
    const double w = 1.0 / (g.sigma_int[i] * g.sigma_int[i]);
    const double m_ii = residualProjectorDiagonal(g, wls, i);
    if (!(m_ii > kMinResidualObservability * w)) {
      // Not seen by the residuals. Harmless when it does not move the position either (the
      // only satellite of its constellation just fixes that clock); otherwise undetectable.
      const double effect = std::sqrt(w) * wls.S.col(i).head<3>().norm();
      if (effect < kMinResidualObservability) {
        out.hslope[i] = 0.0;
        out.vslope[i] = 0.0;
        continue;
      }
      out.reason = "satellite " + g.sats[static_cast<std::size_t>(i)].str() +
                   " is not observable in the residuals: its fault cannot be detected";
      return out;
    }
    out.hslope[i] = std::hypot(wls.S(0, i), wls.S(1, i)) / std::sqrt(m_ii);
    out.vslope[i] = std::abs(wls.S(2, i)) / std::sqrt(m_ii);
  }
  out.max_hslope = out.hslope.maxCoeff(&out.critical_sat_h);
  out.max_vslope = out.vslope.maxCoeff(&out.critical_sat_v);
  const double k_ff_h = normalTailInverse(cfg.phmi_hor / 2.0);
  const double k_ff_v = normalTailInverse(cfg.phmi_vert / 2.0);
  double hpl = 0, vpl = 0;
  if (cfg.formula == RaimPlFormula::kSlopePbias) {
    hpl = out.max_hslope * out.thresholds.p_bias;
    vpl = out.max_vslope * out.thresholds.p_bias;
  } else {
    // Horizontal noise: P(‖n‖ > x) ≤ exp(−x²/2σ²_major) for a 2-D Gaussian (χ²₂ tail bound).
    const double k_md_h = std::sqrt(-2.0 * std::log(cfg.pmd));
    const double k_md_v = normalTailInverse(cfg.pmd / 2.0);
    hpl = out.max_hslope * out.thresholds.p_bias + k_md_h * out.sigma_h_m;
    vpl = out.max_vslope * out.thresholds.p_bias + k_md_v * out.sigma_v_m;
  }
  // Never below the fault-free bound K_ff·σ.
  out.hpl_m = std::max(hpl, k_ff_h * out.sigma_h_m);
  out.vpl_m = std::max(vpl, k_ff_v * out.sigma_v_m);
  out.available = std::isfinite(out.hpl_m) && std::isfinite(out.vpl_m);
  if (!out.available) out.reason = "protection level is not finite";
  return out;
}

int raimExclusionCandidates(int n, int m, int max_exclusions) {
  double total = 0.0, choose = 1.0;  // C(n, r) built up in r
  for (int r = 1; r <= max_exclusions && n - r > m; ++r) {
    choose = choose * (n - r + 1) / r;
    total += choose;
  }
  return static_cast<int>(std::min(total, 1e9));
}

RaimConfig outcomeConfig(const RaimConfig& cfg, double budget_share) {
  RaimConfig c = cfg;
  c.pmd *= budget_share;
  c.phmi_hor *= budget_share;
  c.phmi_vert *= budget_share;
  return c;
}

namespace {

/// The configuration of every outcome of raimFde, with its share of P_md and P_HMI
/// (docs/method.md §3.2a): P(HMI | fault) ≤ Σ_outcomes P(HMI ∧ outcome | fault) ≤
/// (N_exc + 1)·ρ·P_md = P_md. Records N_exc and ρ in `out`.
RaimConfig fdeOutcomeConfig(const Geometry& g, const RaimConfig& cfg, RaimFdeResult& out) {
  if (cfg.exclusion_pl != ExclusionPl::kAllocated) return cfg;
  out.exclusion_candidates = raimExclusionCandidates(g.numSats(), g.numStates(), cfg.max_exclusions);
  out.budget_share = 1.0 / (out.exclusion_candidates + 1.0);
  return outcomeConfig(cfg, out.budget_share);
}

}  // namespace

namespace {

/// `g` without the satellites `removed` (ascending indices).
Geometry withoutSatellitesSet(const Geometry& g, const std::vector<int>& removed) {
  Geometry out = g;
  for (auto it = removed.rbegin(); it != removed.rend(); ++it) out = out.without(*it);
  return out;
}

/// Calls `visit` with every set of 1 to `max_r` of the indices 0..n−1 (ascending) whose removal
/// leaves more than `m` satellites, in lexicographic order; stops when `visit` returns false.
bool forEachExclusion(int n, int m, int max_r, std::vector<int>& set, int from,
                      const std::function<bool(const std::vector<int>&)>& visit) {
  if (static_cast<int>(set.size()) == max_r || n - static_cast<int>(set.size()) - 1 <= m) return true;
  for (int i = from; i < n; ++i) {
    set.push_back(i);
    const bool go_on = visit(set) && forEachExclusion(n, m, max_r, set, i + 1, visit);
    set.pop_back();
    if (!go_on) return false;
  }
  return true;
}

}  // namespace

RaimPl raimFdeProtectionLevels(const Geometry& g, const RaimConfig& cfg) {
  const int n_exc = raimExclusionCandidates(g.numSats(), g.numStates(), cfg.max_exclusions);
  const double share = cfg.exclusion_pl == ExclusionPl::kAllocated ? 1.0 / (n_exc + 1.0) : 1.0;
  const RaimConfig outcome = outcomeConfig(cfg, share);
  RaimPl worst = raimProtectionLevels(g, outcome);
  if (!worst.available) return worst;
  if (n_exc > kMaxPredictedExclusionOutcomes) {
    worst.available = false;
    worst.reason = std::to_string(n_exc) + " exclusion outcomes: more than the " + std::to_string(kMaxPredictedExclusionOutcomes) +
                   " predicted (lower raim.max_exclusions)";
    return worst;
  }
  std::vector<int> set;
  (void)forEachExclusion(g.numSats(), g.numStates(), cfg.max_exclusions, set, 0, [&](const std::vector<int>& removed) {
    const RaimPl pl = raimProtectionLevels(withoutSatellitesSet(g, removed), outcome);
    if (!pl.available) {
      worst.available = false;
      worst.reason = "after excluding " + std::to_string(removed.size()) + " satellite(s): " + pl.reason;
      return false;
    }
    worst.hpl_m = std::max(worst.hpl_m, pl.hpl_m);
    worst.vpl_m = std::max(worst.vpl_m, pl.vpl_m);
    return true;
  });
  return worst;
}

RaimFdeResult raimFde(const Geometry& g, const Eigen::VectorXd& prefit, const RaimConfig& fde_cfg) {
  RaimFdeResult out;
  const RaimConfig cfg = fdeOutcomeConfig(g, fde_cfg, out);
  std::vector<int> kept(static_cast<std::size_t>(g.numSats()));
  for (int i = 0; i < g.numSats(); ++i) kept[static_cast<std::size_t>(i)] = i;
  Geometry cur = g;
  Eigen::VectorXd y = prefit;
  for (int round = 0;; ++round) {
    const int n = cur.numSats(), m = cur.numStates();
    const WlsSolution wls = solveWls(cur.G, cur.sigma_int);
    if (!wls.ok) {
      out.solution_ok = false;
      out.pl = RaimPl{};
      out.pl.reason = "singular geometry or too few satellites (" + std::to_string(n) + ") for a position";
      return out;
    }
    out.solution_ok = true;
    out.dx = wls.S * y;
    const Eigen::VectorXd r = y - cur.G * out.dx;
    const Eigen::VectorXd w = cur.sigma_int.array().square().inverse();
    out.test_statistic = std::sqrt(r.dot(w.asDiagonal() * r));
    out.final_geometry = cur;
    if (n <= m) {  // no redundancy: no test possible
      out.threshold = 0;
      out.pl = raimProtectionLevels(cur, wls, cfg);
      break;
    }
    const RaimThresholds th = raimThresholds(n - m, cfg.pfa, cfg.pmd);
    out.threshold = th.threshold;
    if (out.test_statistic <= th.threshold) {
      if (round > 0) out.fault_excluded = true;
      out.pl = raimProtectionLevels(cur, wls, cfg);
      break;
    }
    if (round == 0) out.fault_detected = true;
    if (round >= cfg.max_exclusions || n - 1 <= m) {  // cannot exclude further: no valid PL
      out.pl = raimProtectionLevels(cur, wls, cfg);
      out.pl.available = false;
      out.pl.reason = "fault detected and not excluded";
      break;
    }
    // Baarda's w-test: w_i = (W r)_i / √M_ii; exclude the largest.
    int worst = -1;
    double worst_w = -1;
    for (int i = 0; i < n; ++i) {
      const double m_ii = residualProjectorDiagonal(cur, wls, i);
      if (!(m_ii > kMinResidualObservability * w[i])) continue;
      const double wi = std::abs(w[i] * r[i]) / std::sqrt(m_ii);
      if (wi > worst_w) { worst_w = wi; worst = i; }
    }
    if (worst < 0) {
      out.pl.available = false;
      out.pl.reason = "fault detected; no satellite can be isolated";
      break;
    }
    out.excluded.push_back(kept[static_cast<std::size_t>(worst)]);
    kept.erase(kept.begin() + worst);
    cur = cur.without(worst);
    Eigen::VectorXd y2(n - 1);
    for (int i = 0, j = 0; i < n; ++i) {
      if (i != worst) y2[j++] = y[i];
    }
    y = y2;
  }
  // Post-fit residuals of every input satellite against the final solution (clock per system).
  out.residuals.resize(g.numSats());
  for (int i = 0; i < g.numSats(); ++i) {
    double pred = g.G.row(i).head(3).dot(out.dx.head(3));
    const auto c = g.sats[static_cast<std::size_t>(i)].constellation;
    for (std::size_t k = 0; k < out.final_geometry.clocks.size(); ++k) {
      if (out.final_geometry.clocks[k] == c) pred += out.dx[3 + static_cast<int>(k)];
    }
    out.residuals[i] = prefit[i] - pred;
  }
  return out;
}

}  // namespace skylane::integrity
