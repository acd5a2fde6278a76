#pragma once
/// \file
/// \brief ARAIM multiple-hypothesis solution separation (MHSS): subset solutions, thresholds,
/// the optimised protection level (docs/method.md §4.5; CN 110687557 A), the equal-allocation bound, EMT, σ_acc and
/// availability.
///
/// References: WG-C ARAIM Technical Subgroup, "Reference Airborne Algorithm Description Document"
/// v3.0 (2017) — ADD; J. Blanch et al., "Baseline Advanced RAIM User Algorithm and Possible
/// Improvements", IEEE TAES 51(1) 713–732, 2015 — TAES; R. Xue & Y. Zhao, CN 110687557 A (ARAIM PL optimisation patent, Beihang University, 2020):
/// the PL is the root of the integrity-risk equation over all monitored subsets, which is the
/// optimal allocation of PHMI among them and never larger than the equal-allocation bound.
///
/// Symbol table (ADD → skylane): σ_q^(k) → sigma[q], σ_ss,q^(k) → sigma_ss[q], b_q^(k) → bias[q],
/// T_k,q → threshold[q], p_fault,k → prior, K_fa,q → k_fa_h / k_fa_v, P_not_monitored →
/// p_not_monitored; axes q = 0 east, 1 north, 2 up (the ADD's 1, 2, 3).

#include "integrity/araim/fault_modes.hpp"
#include "integrity/raim/wls.hpp"
#include "integrity/requirements.hpp"

#include <array>
#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief Which probability of a fault mode is compared with P_EMT for the EMT.
enum class EmtProbability {
  /// The mode's own (exclusive, merged) prior p_k — MAAST for ARAIM's convention, the default.
  /// A single-satellite mode at P_sat = P_EMT = 1e-5 has p_k = 1e-5·∏(1 − p) < P_EMT: not counted.
  kModePrior,
  /// The product ∏ p_e of the mode's events (the ISM's nominal rate): that mode counts.
  kEventProduct,
};

/// \brief ARAIM settings.
struct AraimConfig {
  Requirements requirements;
  FaultModeRule rule = FaultModeRule::kAddsUntilThreshold;
  double fc_thres = 0.0;  ///< fault consolidation threshold (fault_modes.hpp); 0 = off
  EmtProbability emt_probability = EmtProbability::kModePrior;
  bool horizontal_only = false;  ///< availability from HPL ≤ HAL alone (H-ARAIM)
  ExclusionPl exclusion_pl = ExclusionPl::kAllocated;  ///< the PL after FDE (araimFde)
  /// Constellations with P_const > P_HMI are exclusion candidates too (MAAST's `fde_wf_flag`;
  /// off by default: with two constellations, the other one's fault cannot be monitored after
  /// one is excluded, so that outcome has no PL unless P_const is within P_THRES).
  bool exclude_constellations = false;
  /// Single-satellite subsets from the all-in-view solution by a rank-one down-date
  /// (Sherman–Morrison, docs/method.md §4.2), falling back to the subset's own normal matrix
  /// when the satellite's redundancy 1 − h_i is below 1e-3. false: every subset from its own
  /// normal matrix (the reference the down-date is tested against).
  bool subset_downdate = true;
};

/// \brief One monitored fault mode with its subset solution.
struct SubsetSolution {
  std::vector<int> removed;  ///< indices into the geometry's satellites
  double prior = 0.0;
  double event_prior = 0.0;  ///< ∏ p_e of the mode's events (compared with P_EMT under kEventProduct)
  std::array<double, 3> sigma{};      ///< σ_q^(k) [m], integrity covariance
  std::array<double, 3> sigma_ss{};   ///< σ_ss,q^(k) [m], accuracy covariance (C_acc)
  std::array<double, 3> bias{};       ///< b_q^(k) [m]
  std::array<double, 3> threshold{};  ///< T_k,q [m]
  std::array<double, 3> sigma_acc{};  ///< σ_q,acc^(k) [m]
  Eigen::MatrixXd S;                  ///< rows 0..2 of S^(k) (3 × n), zero columns for removed satellites
};

/// \brief The bisection's initial bracket of one axis (ADD Appendix B bounds).
struct PlBracket {
  double low_m = 0.0;   ///< the largest single term alone uses the whole budget here
  double high_m = 0.0;  ///< every term uses at most budget/(N+1) here (the equal-allocation bound)
};

/// \brief ARAIM protection levels and everything behind them.
struct AraimResult {
  bool pl_computed = false;  ///< false: too few satellites, degenerate geometry, risk budget exhausted
  /// The all-in-view solution exists: σ_acc and the EMT are computed (also when the PL is not).
  bool accuracy_computed = false;
  bool available = false;    ///< against VAL/HAL/EMT/σ_acc (or HAL alone in horizontal-only mode)
  std::string reason;
  double hpl_m = 0, vpl_m = 0;
  double hpl_equal_allocation_m = 0, vpl_equal_allocation_m = 0;
  std::array<double, 2> hpl_axis_m{};  ///< east, north
  double emt_m = 0;
  double sigma_acc_v_m = 0;  ///< √(S⁰ C_acc S⁰ᵀ)_UU
  int fault_modes = 0;       ///< monitored (and monitorable) fault modes, fault-free excluded
  int unmonitorable_modes = 0;  ///< selected modes whose subset is singular (prior added to P_not_monitored)
  int downdated_modes = 0;  ///< monitored modes solved by the rank-one down-date (AraimConfig::subset_downdate)
  int n_fault_max = 0;
  double p_not_monitored = 0;
  /// Share ρ of the integrity budget this outcome was solved with: 1 for detection only,
  /// 1/(N_exc + 1) under exclusion (ExclusionPl::kAllocated).
  double budget_share = 1.0;
  double k_fa_h = 0, k_fa_v = 0;
  std::array<double, 3> sigma0{}, bias0{};
  std::array<PlBracket, 3> initial_bracket{};  ///< per axis east, north, up
  Eigen::MatrixXd S0;  ///< rows 0..2 of the all-in-view S
  std::vector<SubsetSolution> subsets;
};

/// \brief Integrity-risk terms of one axis: p·Q̃((PL − T − b)/σ) each; the fault-free term has
/// p = 2, T = 0 (ADD Eq. 31–32).
struct RiskTerm {
  double prior = 0, threshold = 0, bias = 0, sigma = 1;
};

/// \brief Total integrity risk Σ p·Q̃((PL − T − b)/σ) at PL, with Q̃(x) = 1 for x < 0 (ADD Eq. 7–8).
[[nodiscard]] double integrityRisk(const std::vector<RiskTerm>& terms, double pl);

/// \brief The risk of integrityRisk and its derivative in PL (−Σ p φ(z)/σ over the terms with
/// z ≥ 0; the Q̃ = 1 part is flat).
struct RiskAndSlope {
  double risk = 0.0, slope = 0.0;
};
[[nodiscard]] RiskAndSlope integrityRiskAndSlope(const std::vector<RiskTerm>& terms, double pl);

/// \brief Solves integrityRisk(PL) = budget inside the ADD's bracket (Appendix B) by a
/// safeguarded Newton iteration, stopping when the bracket is ≤ tol; returns the upper end
/// (conservative by ≤ tol).
/// `equal_allocation` receives the initial upper bound max_j(T_j + b_j + Q⁻¹(budget/((N+1)p_j))σ_j).
[[nodiscard]] double solveProtectionLevel(const std::vector<RiskTerm>& terms, double budget, double tol,
                                          double* equal_allocation = nullptr, PlBracket* initial = nullptr);

/// \brief ARAIM MHSS protection levels for a geometry (σ_int, σ_acc, b_nom set) under an ISM
/// (fault detection only: the whole integrity budget, ρ = 1).
[[nodiscard]] AraimResult araimProtectionLevels(const Geometry& g, const ErrorModel& model, const AraimConfig& cfg);

/// \brief The fault modes araimProtectionLevels monitors for `g` (before the subset solutions:
/// a mode that turns out unmonitorable is still listed).
[[nodiscard]] FaultModeSet araimFaultModes(const Geometry& g, const ErrorModel& model, const AraimConfig& cfg);

/// \brief The MHSS protection levels over the given fault modes (indices into `g`) with the
/// share ρ ∈ (0, 1] of the integrity budget: Eq. (4.5) with budgets ρ·𝓑_q (docs/method.md §4.3).
[[nodiscard]] AraimResult araimLevelsOverModes(const Geometry& g, FaultModeSet modes, const AraimConfig& cfg,
                                               double budget_share);

}  // namespace skylane::integrity
