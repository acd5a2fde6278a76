#include "integrity/araim/fde.hpp"

#include "integrity/araim/exclusion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace skylane::integrity {
namespace {

Eigen::VectorXd subVector(const Eigen::VectorXd& y, const std::vector<int>& removed) {
  Eigen::VectorXd out(y.size() - static_cast<Eigen::Index>(removed.size()));
  for (Eigen::Index i = 0, j = 0; i < y.size(); ++i) {
    if (!std::binary_search(removed.begin(), removed.end(), static_cast<int>(i))) out[j++] = y[i];
  }
  return out;
}

Geometry subGeometry(const Geometry& g, const std::vector<int>& removed) {
  Geometry out = g;
  for (auto it = removed.rbegin(); it != removed.rend(); ++it) out = out.without(*it);  // highest index first
  return out;
}

struct Fit {
  bool ok = false;
  Eigen::VectorXd dx;
  double wsse = 0.0;
};

Fit fit(const Geometry& g, const Eigen::VectorXd& y) {
  Fit f;
  const WlsSolution w = solveWls(g.G, g.sigma_int);
  if (!w.ok) return f;
  f.ok = true;
  f.dx = w.S * y;
  const Eigen::VectorXd r = y - g.G * f.dx;
  f.wsse = r.cwiseQuotient(g.sigma_int).squaredNorm();
  return f;
}

}  // namespace

double solutionSeparationRatio(const AraimResult& r, const Eigen::VectorXd& y) {
  const Eigen::Vector3d x0 = r.S0 * y;
  double worst = 0.0;
  for (const SubsetSolution& s : r.subsets) {
    const Eigen::Vector3d xk = s.S * y;
    for (int q = 0; q < 3; ++q) {
      const double t = s.threshold[q];
      const double sep = std::abs(xk[q] - x0[q]);
      worst = std::max(worst, t > 0 ? sep / t : (sep > 0 ? std::numeric_limits<double>::infinity() : 0.0));
    }
  }
  return worst;
}

namespace {

/// The all-in-view solution and the solution-separation test against `out.pl`; false when there
/// is nothing further to do (no solution, no PL, or no detection).
bool testAllInView(const Geometry& g, const Eigen::VectorXd& y, AraimFdeResult& out) {
  const Fit all = fit(g, y);
  if (!all.ok) {
    out.pl.pl_computed = out.pl.available = false;
    if (out.pl.reason.empty()) out.pl.reason = "singular geometry";
    return false;
  }
  out.solution_ok = true;
  out.dx = all.dx;
  out.final_geometry = g;
  if (!out.pl.pl_computed) return false;  // nothing to test against; the reason says why
  out.max_test_ratio = solutionSeparationRatio(out.pl, y);
  out.fault_detected = out.max_test_ratio > 1.0;
  return out.fault_detected;
}

/// ExclusionPl::kRemainingGeometry: candidates are the monitored modes, the PL after an
/// exclusion is the plain PL of the remaining geometry (skylane before issue 18).
AraimFdeResult fdeWithRemainingGeometryPl(const Geometry& g, const Eigen::VectorXd& y, const ErrorModel& model,
                                          const AraimConfig& cfg) {
  AraimFdeResult out;
  out.pl = araimProtectionLevels(g, model, cfg);
  if (!testAllInView(g, y, out)) return out;

  // Exclusion: candidates are the monitored modes, fewest satellites first.
  double best_wsse = std::numeric_limits<double>::infinity();
  std::size_t best_size = std::numeric_limits<std::size_t>::max();
  // The candidates are taken out of out.pl first: out.pl is overwritten by a valid exclusion
  // inside the loop (iterating it in place read freed memory — found by ASan in session 5).
  std::vector<SubsetSolution> candidates = std::move(out.pl.subsets);
  out.pl.subsets.clear();
  for (const SubsetSolution& cand : candidates) {
    if (cand.removed.size() > best_size) break;  // a smaller valid exclusion was found already
    const Geometry gk = subGeometry(g, cand.removed);
    const Eigen::VectorXd yk = subVector(y, cand.removed);
    const AraimResult rk = araimProtectionLevels(gk, model, cfg);
    if (!rk.pl_computed || solutionSeparationRatio(rk, yk) > 1.0) continue;
    const Fit fk = fit(gk, yk);
    if (!fk.ok || fk.wsse >= best_wsse) continue;
    best_wsse = fk.wsse;
    best_size = cand.removed.size();
    out.excluded = cand.removed;
    out.dx = fk.dx;
    out.final_geometry = gk;
    out.max_test_ratio = solutionSeparationRatio(rk, yk);
    out.pl = rk;
    out.fault_excluded = true;
  }
  if (!out.fault_excluded) {
    out.pl.subsets = std::move(candidates);
    out.pl.available = false;
    out.pl.reason = "fault detected and not excluded";
  }
  return out;
}

/// The all-in-view solution, its PL (the no-exclusion outcome, share ρ) and the detection test;
/// false when there is nothing further to do (no solution, no PL, or no detection).
bool detect(const Geometry& g, const Eigen::VectorXd& y, const FaultModeSet& modes, const AraimConfig& cfg, double rho,
            AraimFdeResult& out) {
  out.pl = araimLevelsOverModes(g, modes, cfg, rho);
  return testAllInView(g, y, out);
}

/// ExclusionPl::kAllocated (docs/method.md §4.3; Blanch, Walter & Enge 2017): the fixed
/// candidates, each valid when every test of its subset passes (T_k,j of the restricted modes);
/// among the valid ones with the fewest satellites the smallest weighted residual sum of squares
/// is excluded, and the PL is that outcome's, with ρ·P_HMI.
AraimFdeResult fdeWithAllocatedPl(const Geometry& g, const Eigen::VectorXd& y, const ErrorModel& model,
                                  const AraimConfig& cfg) {
  AraimFdeResult out;
  if (g.numSats() == 0) {
    out.pl = araimProtectionLevels(g, model, cfg);
    return out;
  }
  const FaultModeSet modes = araimFaultModes(g, model, cfg);
  const std::vector<std::vector<int>> candidates = exclusionCandidates(g, model, cfg);
  const double rho = exclusionBudgetShare(candidates.size());
  out.exclusion_candidates = static_cast<int>(candidates.size());
  if (!detect(g, y, modes, cfg, rho, out)) return out;
  double best_wsse = std::numeric_limits<double>::infinity();
  std::size_t best_size = std::numeric_limits<std::size_t>::max();
  for (const std::vector<int>& cand : candidates) {
    if (cand.size() > best_size) break;  // a smaller valid exclusion was found already
    AraimResult rk = araimLevelsAfterExclusion(g, modes, cand, cfg, rho);
    const Eigen::VectorXd yk = subVector(y, cand);
    if (!rk.pl_computed) continue;
    const double ratio = solutionSeparationRatio(rk, yk);
    if (ratio > 1.0) continue;
    const Geometry gk = withoutSatellites(g, cand);
    const Fit fk = fit(gk, yk);
    if (!fk.ok || fk.wsse >= best_wsse) continue;
    best_wsse = fk.wsse;
    best_size = cand.size();
    out.excluded = cand;
    out.dx = fk.dx;
    out.final_geometry = gk;
    out.max_test_ratio = ratio;
    out.pl = std::move(rk);
    out.fault_excluded = true;
  }
  if (!out.fault_excluded) {
    out.pl.available = false;
    out.pl.reason = "fault detected and not excluded";
  }
  return out;
}

}  // namespace

AraimFdeResult araimFde(const Geometry& g, const Eigen::VectorXd& y, const ErrorModel& model, const AraimConfig& cfg) {
  return cfg.exclusion_pl == ExclusionPl::kAllocated ? fdeWithAllocatedPl(g, y, model, cfg)
                                                     : fdeWithRemainingGeometryPl(g, y, model, cfg);
}

}  // namespace skylane::integrity
