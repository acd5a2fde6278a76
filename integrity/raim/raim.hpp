#pragma once
/// \file
/// \brief Classic RAIM: least-squares-residual chi-square fault detection (Parkinson & Axelrad,
/// "Autonomous GPS integrity monitoring using the pseudorange residual", NAVIGATION 35(2), 1988),
/// Brown's thresholds and p_bias (R. G. Brown & G. Y. Chin, "GPS RAIM: Calculation of Threshold
/// and Protection Radius Using Chi-Square Methods — A Geometric Approach", ION RAIM Red Book V,
/// 1998), Baarda's w-test exclusion (W. Baarda, "A testing procedure for use in geodetic
/// networks", 1968) and slope-based protection levels with weighted slopes as in T. Walter &
/// P. Enge, "Weighted RAIM for Precision Approach", ION GPS 1995.
///
/// Symbol table (papers → skylane): T_d → threshold (√ of the χ² threshold of the normalised
/// WSSE), p_bias → p_bias (√ of the non-centrality with P_md), HSlope_i / VSlope_i → slopes,
/// K_md → k_md, σ_V → sigma_v_m.

#include "integrity/raim/wls.hpp"
#include "integrity/requirements.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief Brown's detection threshold and protection bias for one redundancy.
struct RaimThresholds {
  int dof = 0;             ///< n − number of states
  double threshold = 0.0;  ///< T_d: √χ²-quantile of the normalised test statistic, P(χ²_dof > T_d²) = P_fa
  double p_bias = 0.0;     ///< √λ with P(χ²_dof(λ) < T_d²) = P_md
};

/// \brief Computes T_d and p_bias for `dof` redundant measurements (cached per argument set).
/// \throws std::invalid_argument for dof < 1 or probabilities outside (0, 1).
[[nodiscard]] RaimThresholds raimThresholds(int dof, double pfa, double pmd);

/// \brief How the slope-based protection level is formed.
enum class RaimPlFormula {
  /// "max slope × p_bias plus the fault-free term" (docs/method.md Eq. (3.5)): PL_V = max_i VSlope_i·p_bias
  /// + Q⁻¹(P_md/2)·σ_V, PL_H = max_i HSlope_i·p_bias + √(−2 ln P_md)·σ_H,major. Rigorous: the
  /// position noise is independent of the residuals in WLS, so for a bias whose non-centrality
  /// is below p_bias² the exceedance is ≤ P_md by the noise term, and above it the miss
  /// probability itself is ≤ P_md. (Walter & Enge's slope·T_d + K_md·σ was measured to exceed
  /// P_md by 2.3× in raim_monte_carlo_test and is not offered.)
  kSlopePbiasPlusNoise,
  /// Brown & Chin 1998: PL = max_i slope_i · p_bias, the classic protection radius. It ignores
  /// the noise along the fault and under-bounds at the worst bias (measured ≈ 1.3–2.9 × P_md);
  /// kept for comparison with published RAIM availability figures.
  kSlopePbias,
};

/// \brief RAIM parameters. Probabilities are per independent sample.
struct RaimConfig {
  double pfa = 1e-6;        ///< false-alert probability of the χ² test (Brown's tables)
  double pmd = 1e-3;        ///< missed-detection probability
  double phmi_hor = 2e-9;   ///< fault-free horizontal integrity budget (K_ff,H)
  double phmi_vert = 9.8e-8;///< fault-free vertical integrity budget (K_ff,V)
  RaimPlFormula formula = RaimPlFormula::kSlopePbiasPlusNoise;
  int max_exclusions = 1;   ///< w-test exclusions attempted per epoch
  /// The PL of raimFde's outcomes (docs/method.md §3.2a): kAllocated gives every outcome —
  /// no exclusion and each of the N_exc possible exclusions — ρ = 1/(N_exc + 1) of P_md and of
  /// P_HMI, so that a wrong exclusion is bounded; kRemainingGeometry is the plain PL.
  ExclusionPl exclusion_pl = ExclusionPl::kAllocated;
};

/// \brief Protection levels for one geometry (no measurements needed).
struct RaimPl {
  bool available = false;
  std::string reason;       ///< why not available
  double hpl_m = 0.0;
  double vpl_m = 0.0;
  double sigma_h_m = 0.0;   ///< semi-major axis of the horizontal 1σ error ellipse
  double sigma_v_m = 0.0;
  double max_hslope = 0.0;  ///< max_i HSlope_i [m per unit normalised bias]
  double max_vslope = 0.0;
  int critical_sat_h = -1;  ///< index of the satellite with the largest horizontal slope
  int critical_sat_v = -1;
  RaimThresholds thresholds;
  Eigen::VectorXd hslope;   ///< per satellite
  Eigen::VectorXd vslope;
};

/// \brief Slope-based HPL/VPL for the geometry with integrity σ's. Fewer than states + 1
/// satellites, or a singular geometry, give `available = false` with the reason; never NaN.
[[nodiscard]] RaimPl raimProtectionLevels(const Geometry& g, const RaimConfig& cfg);
/// \brief The same with the geometry's weighted least-squares solution already at hand
/// (`wls` = solveWls(g.G, g.sigma_int)).
[[nodiscard]] RaimPl raimProtectionLevels(const Geometry& g, const WlsSolution& wls, const RaimConfig& cfg);

/// \brief The outcome of fault detection and exclusion on one epoch's measurements.
struct RaimFdeResult {
  bool solution_ok = false;   ///< a position could be computed
  bool fault_detected = false;  ///< the all-in-view χ² test failed
  bool fault_excluded = false;  ///< the test passes after excluding `excluded`
  std::vector<int> excluded;    ///< indices into the input geometry
  Eigen::VectorXd dx;           ///< state correction (ENU + clocks) from the kept satellites
  Eigen::VectorXd residuals;    ///< post-fit residuals of all input satellites [m]
  double test_statistic = 0.0;  ///< √(rᵀWr) of the final solution (normalised; compare to threshold)
  double threshold = 0.0;       ///< T_d of the final solution (0 when dof = 0)
  RaimPl pl;                    ///< protection levels of the final geometry (outcome share budget_share)
  Geometry final_geometry;
  int exclusion_candidates = 0; ///< N_exc: the exclusions raimFde may make (Σ_r C(n, r), r ≤ max_exclusions)
  double budget_share = 1.0;    ///< ρ the outcome's PL was solved with (1/(N_exc + 1) under kAllocated)
};

/// \brief N_exc for `n` satellites and `m` states: every set of up to `max_exclusions`
/// satellites whose removal leaves redundancy (n − r > m), Σ_r C(n, r).
[[nodiscard]] int raimExclusionCandidates(int n, int m, int max_exclusions);

/// \brief `cfg` for one outcome of FDE with share ρ: P_md, P_HMI,H and P_HMI,V multiplied by ρ
/// (the detection threshold, from P_fa, is unchanged).
[[nodiscard]] RaimConfig outcomeConfig(const RaimConfig& cfg, double budget_share);

/// \brief The predicted protection levels of a user who detects and excludes (raimFde): the
/// maximum over the outcomes — no exclusion, and each set of up to max_exclusions satellites
/// whose removal leaves redundancy — of the PL of the outcome's geometry with the outcome's
/// budget (outcomeConfig with ρ = 1/(N_exc + 1) under kAllocated, the whole budget under
/// kRemainingGeometry). Whatever the measurements, raimFde's PL on any epoch of this geometry
/// is one of these, so it never exceeds them. Not available when an outcome's PL is not, or
/// when there are more than kMaxPredictedExclusionOutcomes outcomes. The slopes and the
/// critical satellites are the no-exclusion outcome's.
[[nodiscard]] RaimPl raimFdeProtectionLevels(const Geometry& g, const RaimConfig& cfg);

/// \brief The most exclusion outcomes raimFdeProtectionLevels evaluates (C(40, 2) = 780 fit).
inline constexpr int kMaxPredictedExclusionOutcomes = 5000;

/// \brief Least-squares residual test, then w-test exclusion of the worst satellite while the
/// test fails and exclusions remain. `prefit` holds measured − predicted ranges [m].
[[nodiscard]] RaimFdeResult raimFde(const Geometry& g, const Eigen::VectorXd& prefit, const RaimConfig& cfg);

}  // namespace skylane::integrity
