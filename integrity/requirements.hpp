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

}  // namespace skylane::integrity
