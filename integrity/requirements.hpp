#pragma once
/// \file
/// \brief Integrity requirements shared by RAIM, ARAIM and the geofence checks.

namespace skylane::integrity {

/// \brief Integrity requirements (WG-C ARAIM ADD v3.0 Table 3 defaults, LPV-200).
struct Requirements {
  double phmi_vert = 9.8e-8;
  double phmi_hor = 2e-9;
  double pfa_vert = 3.9e-6;
  double pfa_hor = 9e-8;
  double p_thres = 8e-8;
  double p_emt = 1e-5;
  double tol_pl_m = 5e-2;
  double val_m = 35.0;
  double hal_m = 40.0;
  double emt_m = 15.0;
  double sigma_acc_m = 1.87;
};

/// \brief What a protection level after a fault exclusion accounts for (RAIM and ARAIM FDE;
/// docs/method.md §3.2a and §4.3).
enum class ExclusionPl {
  /// The integrity budget is shared by the outcomes of FDE — no exclusion and each of the N_exc
  /// exclusion candidates get ρ = 1/(N_exc + 1) of it — so that a wrong exclusion is bounded
  /// (J. Blanch, T. Walter, P. Enge, "Protection Levels after Fault Exclusion for Advanced RAIM",
  /// NAVIGATION 64(4), 2017; ARAIM: the modes of the remaining subset with their own thresholds
  /// T_k,j). The default.
  kAllocated,
  /// The plain detection-only PL of the remaining geometry with the whole budget (skylane before
  /// issue 18); it does not account for a wrong exclusion. Kept to compare.
  kRemainingGeometry,
};

}  // namespace skylane::integrity
