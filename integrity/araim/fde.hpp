#pragma once
/// \file
/// \brief ARAIM solution-separation fault detection and exclusion on measured epochs.
///
/// Detection (ADD v3.0 §2.5, TAES 2015 Eqs. 18–21): for every monitored subset k and axis q,
/// |x̂_q^(k) − x̂_q^(0)| ≤ T_k,q; any violation is a detection. Exclusion: every monitored fault
/// mode is a candidate (fewest satellites first); a candidate is valid when the ARAIM run on the
/// remaining satellites passes all of its own solution-separation tests; among valid candidates
/// the one whose solution has the smallest weighted residual sum of squares is excluded and the
/// protection levels are those of the remaining geometry. (The ADD's pre-allocation of the
/// integrity budget to exclusion outcomes — Blanch, Walter & Enge, NAVIGATION 64(4), 2017 — is
/// not applied yet: see docs/method.md §4.3.)

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
  AraimResult pl;                 ///< of the final geometry
};

/// \brief Largest |x̂^(k) − x̂^(0)| / T_k,q over the monitored subsets and axes for measurements y.
[[nodiscard]] double solutionSeparationRatio(const AraimResult& r, const Eigen::VectorXd& y);

/// \brief Detection and exclusion on prefit residuals y (measured − predicted ranges [m]).
[[nodiscard]] AraimFdeResult araimFde(const Geometry& g, const Eigen::VectorXd& y, const ErrorModel& model,
                                      const AraimConfig& cfg);

}  // namespace skylane::integrity
