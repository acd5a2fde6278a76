#pragma once
/// \file
/// \brief ARAIM solution-separation fault detection and exclusion on measured epochs.
///
/// Detection (ADD v3.0 §2.5, TAES 2015 Eqs. 18–21): for every monitored subset k and axis q,
/// |x̂_q^(k) − x̂_q^(0)| ≤ T_k,q; any violation is a detection.
///
/// Exclusion under ExclusionPl::kAllocated (the default; docs/method.md §4.3): the candidates
/// are fixed (every satellite, every constellation with P_const > P_HMI; exclusion.hpp), every
/// outcome's PL — the no-exclusion one included — is solved with ρ = 1/(N_exc + 1) of the
/// budget (J. Blanch, T. Walter, P. Enge, "Protection Levels after Fault Exclusion for Advanced
/// RAIM", NAVIGATION 64(4), 2017). A candidate k is valid when every test of its subset passes,
/// |x̂^(k,j) − x̂^(k)| ≤ T_k,j over the all-in-view modes restricted to k; among the valid
/// candidates with the fewest satellites the smallest weighted residual sum of squares is
/// excluded, and the PL is that outcome's. Under ExclusionPl::kRemainingGeometry (skylane before
/// issue 18) every monitored mode is a candidate, validity is the remaining geometry's own ARAIM,
/// and the PL is its plain PL with the whole budget.

#include "integrity/araim/mhss.hpp"

namespace skylane::integrity {

/// \brief Outcome of ARAIM FDE on one epoch.
struct AraimFdeResult {
  bool solution_ok = false;
  bool fault_detected = false;
  bool fault_excluded = false;
  std::vector<int> excluded;      ///< indices into the input geometry
  Eigen::VectorXd dx;             ///< state correction (ENU + clocks) of the final geometry
  Geometry final_geometry;
  double max_test_ratio = 0.0;    ///< max_k,q |Δx| / T of the final geometry (≤ 1 passes)
  int exclusion_candidates = 0;   ///< N_exc under ExclusionPl::kAllocated (pl.budget_share = 1/(N_exc + 1))
  AraimResult pl;                 ///< of the final outcome (pl.budget_share says with which share)
};

/// \brief Largest |x̂^(k) − x̂^(0)| / T_k,q over the monitored subsets and axes for measurements y.
[[nodiscard]] double solutionSeparationRatio(const AraimResult& r, const Eigen::VectorXd& y);

/// \brief Detection and exclusion on prefit residuals y (measured − predicted ranges [m]).
[[nodiscard]] AraimFdeResult araimFde(const Geometry& g, const Eigen::VectorXd& y, const ErrorModel& model,
                                      const AraimConfig& cfg);

}  // namespace skylane::integrity
