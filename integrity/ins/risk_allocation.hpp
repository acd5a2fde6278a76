#pragma once
/// \file
/// \brief Fault modes of a GNSS/IMU integrated navigation system with one IMU, their prior
/// probabilities and the split of the integrity requirement among them (J. Zhao & D. Song,
/// "Integrity monitoring method for UAV GNSS/IMU integrated navigation system", Acta
/// Aeronautica et Astronautica Sinica 45(7), 2024 §§1.3, 2.1, 2.2; docs/method.md §5.3).
///
/// Reading of the damaged equations (the OCR lost every formula; the printed numbers fix them):
/// - Eq. (4) (class 1, IMU fault detected, GNSS alone): P(FF) = (1−P_sat)^K,
///   P(GS) = K·P_sat·(1−P_sat)^(K−1), P(GM) = 1 − P(FF) − P(GS). For K = 10, P_sat = 1e-5 the
///   paper prints P(GS) ≤ 9.9991e-5 and P(GM) ≤ 4.4998e-9; these formulas give exactly that.
/// - Eq. (7) (class 2, no IMU fault detected), GNSS and IMU faults independent: the class-1
///   priors times (1−P_IMU), and P(I) = (1−P_sat)^K·P_IMU, P(GSI) = K·P_sat(1−P_sat)^(K−1)·P_IMU.
///   The paper prints P(GS) ≤ 9.9891e-5, P(GM) ≤ 4.4953e-9, P(GSI) ≤ 9.9991e-8: reproduced.
/// - Allocation rule (§2): a mode whose prior is at most 1/20 of the *total* requirement
///   I_req = 1e-7 (so ≤ 5e-9; GM's 4.4998e-9 passes only against the total, not against the
///   per-direction 5e-8) gets its prior as its budget and needs no protection level; the rest
///   of the direction's budget is split evenly among the remaining modes. The paper prints
///   1.1376e-9 for class 2, but (5e-8 − 4.4953e-9)/4 = 1.1376e-8: a misprint (docs/method.md §5.3).
/// - The paper's class 2 leaves out "multi-satellite and IMU" (GMI), prior
///   P(GM)·P_IMU/(1−P_IMU) ≈ 4.5e-12 for K = 10. Left out, the requirement is not fully
///   accounted for, so skylane adds it as a prior-budgeted mode by default
///   (`include_gm_imu`); the even share becomes 1.13751e-8. Without it the paper's 1.1376e-8.

#include <array>
#include <string_view>

namespace skylane::integrity {

/// \brief The fault modes of Zhao & Song 2024 (plus GMI, see the file comment).
enum class InsFaultMode {
  kFaultFree,      ///< no GNSS and no IMU fault
  kGnssSingle,     ///< GS: one satellite faulty, IMU healthy
  kGnssMulti,      ///< GM: two or more satellites faulty, IMU healthy
  kImu,            ///< I: IMU faulty, GNSS healthy
  kGnssSingleImu,  ///< GSI: one satellite and the IMU faulty
  kGnssMultiImu,   ///< GMI: two or more satellites and the IMU faulty
};
inline constexpr int kNumInsFaultModes = 6;

/// \brief Short name as in the paper: "FF", "GS", "GM", "I", "GSI", "GMI".
[[nodiscard]] std::string_view faultModeName(InsFaultMode m);

/// \brief Which detection outcome the budget is for (Zhao & Song 2024 Fig. 3).
enum class DetectionClass {
  kGnssAlone,   ///< class 1: IMU fault detected, the system degrades to GNSS (modes FF, GS, GM)
  kIntegrated,  ///< class 2: no IMU fault detected (FF, GS, GM, I, GSI, GMI)
};

/// \brief Inputs of the allocation.
struct RiskAllocationConfig {
  double i_req = 1e-7;          ///< total integrity requirement per epoch
  double vertical_share = 0.5;  ///< share of i_req for the vertical (the rest horizontal)
  double p_sat = 1e-5;          ///< prior probability of one satellite's fault
  double p_imu = 1e-3;          ///< prior probability of the IMU's fault
  double negligible_fraction = 1.0 / 20.0;  ///< "far smaller": prior ≤ this × i_req
  bool include_gm_imu = true;   ///< budget GMI (see file comment); false reproduces the paper
};

/// \brief One mode's prior, budget and conditional risk.
struct ModeBudget {
  bool considered = false;   ///< the mode exists in this detection class
  double prior = 0.0;        ///< P(F_i)
  double budget = 0.0;       ///< I_req(F_i) in one direction (horizontal or vertical)
  bool needs_pl = false;     ///< false: budget = prior, the mode needs no protection level
  /// \brief P(HMI | F_i) = min(1, budget / prior): what the mode's protection level must meet.
  double conditional = 0.0;
};

/// \brief The allocation of one direction's budget over the modes of one detection class.
struct RiskAllocation {
  DetectionClass detection = DetectionClass::kIntegrated;
  int num_sats = 0;
  double direction_budget = 0.0;  ///< I_req,H or I_req,V
  std::array<ModeBudget, kNumInsFaultModes> modes{};
  [[nodiscard]] const ModeBudget& of(InsFaultMode m) const { return modes[static_cast<int>(m)]; }
};

/// \brief Priors of every mode (Zhao & Song 2024 Eqs. (4), (7); docs/method.md Eqs. (5.7)–(5.8)) for K satellites in view.
/// \throws std::invalid_argument for K < 1 or probabilities outside [0, 1).
[[nodiscard]] std::array<double, kNumInsFaultModes> faultModePriors(int num_sats, DetectionClass detection,
                                                                    const RiskAllocationConfig& cfg);

/// \brief Splits one direction's budget (vertical when `vertical`, else horizontal).
[[nodiscard]] RiskAllocation allocateRisk(int num_sats, DetectionClass detection, bool vertical,
                                          const RiskAllocationConfig& cfg);

}  // namespace skylane::integrity
