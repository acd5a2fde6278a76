#pragma once
/// \file
/// \brief Protection levels of the GNSS/INS filter: the fault-mode PLs (docs/method.md §5.4; Zhao & Song 2024,
/// §3) and the three-hypothesis INS PL (docs/method.md §5.5; US 10,466,362 claims 1–7).
///
/// **The fault-mode PL (Zhao & Song 2024), as skylane reads it.** The paper's Eqs. (18)–(35) are lost in the OCR; the text
/// keeps their structure: the fault-free error is N(0, σ_q²) with σ_q from the filter covariance
/// (Eq. 18); for the GS mode the estimate error is written through the filter innovation, which
/// carries the effect of past-epoch faults, plus (B_k + K'_k)·f_k for the current epoch's fault
/// (Eqs. 23–32), and (B_k + K'_k)·f_k is bounded by the largest "characteristic slope" times the
/// minimum detectable bias of the LSR test, with the non-centrality ξ_b²·s_mm/σ_m² (Eqs. 33–35);
/// GSI has the same form (Eq. 37); the I mode uses the innovations to express the past fault.
/// skylane's derivation of that structure (δx = truth − estimate, ν = H δx⁻ + μ + f):
/// - a deterministic prior error β⁻ (any past GNSS or IMU fault) shows in the innovation mean
///   H_pc β⁻_pc (only position and clock enter H). With G = (H_pcᵀ S⁻¹ H_pc)⁻¹ H_pcᵀ S⁻¹
///   (G H_pc = I), β̂⁻ = G ν, and the post-update position bias β = β⁻_p − K_p H β⁻ is estimated
///   by A ν with A = G_p − K_p (this A ν is the paper's "innovation expression");
/// - e_p − A ν is free of β⁻ and, since the posterior error is uncorrelated with the innovation,
///   has variance P_pp + A S Aᵀ (σ'_q below);
/// - a current-epoch fault f on satellite m adds −(K_p + A) f = −G_p f to e_p − A ν: the slope is
///   |G_p,qm| (the paper's t_qm), and the LSR test sees it with non-centrality f² s_mm / σ_m², so
///   max_m |G_p,qm| σ_m p_bias / √s_mm bounds it until detection is likely (Brown & Chin);
/// - nominal biases |b_i| ≤ b_nom,i (ARAIM ISM) add Σ_i |sensitivity_qi| b_nom,i.
/// Hence, with p_q the mode's conditional risk on axis q and K = Q⁻¹(p_q / 2):
///   FF:      PL_q = K σ_q + Σ|M_qi| b_nom,i
///   I:       PL_q = |(A ν)_q| + K σ'_q + Σ|(M − A N)_qi| b_nom,i
///   GS, GSI: PL_q = the I form + max_m |G_p,qm| σ_m p_bias(P_md = p_q) / √s_mm
/// For |f| below the minimum detectable bias the noise term keeps P(|e_q| > PL_q) ≤ p_q; above
/// it the fault goes undetected with probability ≤ p_q: P(HMI | mode) ≤ p_q either way.
/// HPL = √(PL_E² + PL_N²) (the paper's Eq. 39); each horizontal axis gets half of the mode's
/// horizontal conditional risk, so the union bound keeps the horizontal total (the paper does not
/// say how it splits it). Final PL = max over the modes that need one (Eq. 38).
///
/// **The three-hypothesis INS PL (US 10,466,362), as read** (docs/method.md §5.5): HPL = max{HPL_GNSS,fault,
/// HPL_IMU,fault, HPL_IMU,nominal}, VPL alike, with
///   HPL_IMU,nominal = Q⁻¹(λ·P_nom)·σ_h, σ_h = √(σ_E² + σ_N²) from the filter covariance;
///   HPL_IMU,fault = Q⁻¹(λ·P_ins)·σ_fault,h + mean over the last N epochs of |(K ν)_h| — the
///     patent prints "(K_k,i + Γ_k,i ω_k,i)", a gain plus a vector; read as the horizontal part of
///     the filter correction K ν (the process-noise term Γω is unknown at run time and its
///     covariance is already in σ); σ_fault from K S Kᵀ (the innovation covariance mapped to ENU);
///   HPL_GNSS,fault = mean over N of μ_h + Q⁻¹(P_gnss/2)·σ_h, μ_h = max_i HSlope_i·p_bias (RAIM);
/// λ = 1/12, 5/12, 9/12 (aviation, tactical, consumer). The patent's vertical K's print
/// "Q⁻¹(1 − …)": with Q read as the CDF this is the same positive multiplier, so one form is
/// used. The patent gives no P_HMI split: skylane gives each hypothesis a third of each
/// direction's budget (configurable).

#include "integrity/ins/ekf.hpp"
#include "integrity/ins/risk_allocation.hpp"
#include "integrity/raim/raim.hpp"

#include <array>
#include <deque>
#include <string>

namespace skylane::integrity::ins {

/// \brief One fault mode's protection levels.
struct ModePl {
  bool needs_pl = false;  ///< false: the mode's prior is its budget (no PL), or it is not considered
  std::array<double, 3> axis_m{};  ///< east, north, up
  double hpl_m = 0.0;
  double vpl_m = 0.0;
};

/// \brief The fault-mode protection levels at one epoch.
struct FaultModePls {
  bool available = false;
  std::string reason;
  std::array<ModePl, kNumInsFaultModes> modes{};
  double hpl_m = 0.0;
  double vpl_m = 0.0;
  InsFaultMode deciding_h = InsFaultMode::kFaultFree;
  InsFaultMode deciding_v = InsFaultMode::kFaultFree;
  double bias_estimate_up_m = 0.0;  ///< (A ν)_U
};

/// \brief Fault-mode PL settings.
struct FaultModeConfig {
  RiskAllocationConfig risk;
  double pfa_gnss = 1e-5;  ///< false-alert probability of the LSR test (also used by the FDE)
};

/// \brief The fault-mode protection levels (class 2: no IMU fault detected) from a GNSS update.
[[nodiscard]] FaultModePls faultModeProtectionLevels(const GnssUpdateRecord& rec, const FaultModeConfig& cfg);

/// \brief The innovation test statistic for IMU faults: the prior position/clock bias estimated
/// from the innovations, G ν, normalised by its covariance G S Gᵀ: (Gν)ᵀ(G S Gᵀ)⁻¹(Gν) ~ χ²(4)
/// per fault-free epoch (one clock). Returns a negative number when fewer than 4 satellites.
[[nodiscard]] double imuInnovationStatistic(const GnssUpdateRecord& rec);

/// \brief Three-hypothesis INS PL settings.
struct ThreeHypothesisInsConfig {
  double phmi_h = 0.5e-7;
  double phmi_v = 0.5e-7;
  std::array<double, 3> share{1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0};  ///< nominal, INS fault, GNSS fault
  double lambda = 9.0 / 12.0;  ///< error weight ratio of the IMU grade
  int window = 10;             ///< N epochs of the means
};

/// \brief The three-hypothesis INS HPL/VPL with each hypothesis' part.
struct ThreeHypothesisInsPl {
  bool available = false;
  double hpl_m = 0.0, vpl_m = 0.0;
  double hpl_nominal_m = 0.0, hpl_imu_fault_m = 0.0, hpl_gnss_fault_m = 0.0;
  double vpl_nominal_m = 0.0, vpl_imu_fault_m = 0.0, vpl_gnss_fault_m = 0.0;
};

/// \brief The three-hypothesis INS PL monitor: keeps the last N corrections and RAIM biases.
class ThreeHypothesisInsMonitor {
 public:
  explicit ThreeHypothesisInsMonitor(const ThreeHypothesisInsConfig& cfg);
  /// \brief Adds an epoch and returns its protection levels. `raim` is the snapshot RAIM of the
  /// satellites the filter used (for μ); an unavailable RAIM makes the epoch unavailable.
  ThreeHypothesisInsPl push(const GnssUpdateRecord& rec, const RaimPl& raim);

 private:
  ThreeHypothesisInsConfig cfg_;
  std::deque<Eigen::Vector3d> corrections_;  ///< |K ν| parts: (horizontal, up, –)
  std::deque<Eigen::Vector2d> mu_;            ///< (μ_h, μ_v)
};

/// \brief The patent's error weight ratio λ for an IMU grade index (0 aviation, 1 tactical, 2 consumer).
[[nodiscard]] double imuErrorWeightRatio(int grade_index);

}  // namespace skylane::integrity::ins
