#pragma once
/// \file
/// \brief Pseudorange error model and integrity support message (ISM).
///
/// After the WG-C ARAIM Airborne Algorithm Description Document (ADD v3.1, 2019) §2.1 and
/// Stanford's MAAST: σ²_int,i = σ²_URA,i + σ²_tropo,i + σ²_user,i and σ²_acc,i with σ_URE.
/// Symbol table (ADD → skylane): σ_URA → ura_m, σ_URE → ure_m, b_nom → bnom_m,
/// P_sat → psat, P_const → pconst.

#include "integrity/gnss/satellite_id.hpp"

#include <array>
#include <optional>
#include <string>

namespace skylane::integrity {

/// \brief One constellation's integrity support message.
struct IsmEntry {
  double ura_m = 0.75;   ///< σ_URA, integrity overbound of the signal-in-space error
  double ure_m = 0.5;    ///< σ_URE, accuracy/continuity value
  double bnom_m = 0.5;   ///< maximum nominal bias
  double psat = 1e-5;    ///< prior probability of a satellite fault
  double pconst = 1e-8;  ///< prior probability of a constellation-wide fault
};

/// \brief Airborne (user) error models.
enum class UserErrorModel {
  kDualFrequency,    ///< ADD L1/L5 iono-free airborne model (multipath + noise, scaled by γ)
  kSingleFrequency,  ///< L1-only: DO-253 AAD-A noise + multipath plus DO-229 single-frequency iono
};

/// \brief ISM defaults: GPS σ_URA 0.75 m, σ_URE 0.5 m, b_nom 0.5 m, P_sat 1e-5, P_const 1e-8;
/// Galileo σ_URA 0.96 m, σ_URE 0.64 m, b_nom 0.5 m, P_sat 1e-5, P_const 1e-4 (the values of
/// the WG-C ARAIM reports and MAAST's example ISM); GLONASS and BeiDou take Galileo's values
/// until an ISM for them is published — override them from the geometry file.
[[nodiscard]] IsmEntry defaultIsm(Constellation c);

/// \brief The whole error model used to weight a geometry.
struct ErrorModel {
  std::array<IsmEntry, kNumConstellations> ism{defaultIsm(Constellation::kGps), defaultIsm(Constellation::kGalileo),
                                               defaultIsm(Constellation::kGlonass), defaultIsm(Constellation::kBeidou)};
  /// \brief Airborne model per constellation (index = Constellation value).
  std::array<UserErrorModel, kNumConstellations> user_model{UserErrorModel::kDualFrequency, UserErrorModel::kDualFrequency,
                                                            UserErrorModel::kDualFrequency, UserErrorModel::kDualFrequency};
  /// \brief Single frequency: vertical ionospheric error bound τ_vert [m]; unset = chosen from the
  /// geomagnetic latitude when the user position is known, else the worst case 9 m.
  std::optional<double> iono_tau_vert_m;

  [[nodiscard]] const IsmEntry& of(Constellation c) const { return ism[static_cast<int>(c)]; }
  [[nodiscard]] IsmEntry& of(Constellation c) { return ism[static_cast<int>(c)]; }
  /// \brief Sets the same airborne model for every constellation.
  void setUserModel(UserErrorModel m) { user_model.fill(m); }
};

/// \brief Tropospheric residual σ [m]: 0.12·1.001/√(0.002001 + sin²θ) (ADD Eq. 2; DO-229 A.4.2.4).
[[nodiscard]] double sigmaTropo_m(double elevation_rad);
/// \brief Airborne multipath σ [m]: 0.13 + 0.53·e^(−θ/10°) (DO-253, ADD Eq. 3).
[[nodiscard]] double sigmaMultipath_m(double elevation_rad);
/// \brief Airborne noise σ [m]: 0.15 + 0.43·e^(−θ/6.9°) (DO-253 AAD-A, ADD Eq. 3).
[[nodiscard]] double sigmaNoise_m(double elevation_rad);
/// \brief γ = (f1⁴ + f5⁴)/(f1² − f5²)² ≈ 6.6995, the iono-free noise amplification (ADD Eq. 3).
[[nodiscard]] double ionoFreeNoiseFactor();
/// \brief Single-frequency ionospheric residual σ [m] = F_pp·τ_vert (DO-229E J.2.3).
[[nodiscard]] double sigmaIonoSingleFrequency_m(double elevation_rad, double tau_vert_m);
/// \brief τ_vert [m] from geomagnetic latitude: 9 (≤ 20°), 4.5 (22.5°–55°), 6 (> 55°), linearly
/// interpolated between 20° and 22.5° (DO-229E Table J-1 layout).
[[nodiscard]] double ionoTauVert_m(double geomagnetic_lat_rad);
/// \brief σ²_user [m²] of the chosen airborne model at elevation θ (τ_vert for single frequency).
[[nodiscard]] double sigmaUserSquared(UserErrorModel model, double elevation_rad, double tau_vert_m);

/// \brief Per-satellite error budget.
struct RangeSigma {
  double sigma_int_m = 0.0;  ///< integrity σ (σ_URA based)
  double sigma_acc_m = 0.0;  ///< accuracy σ (σ_URE based)
  double bnom_m = 0.0;
};

/// \brief σ_int, σ_acc and b_nom for one satellite at elevation θ (ADD Eqs. 1–4).
[[nodiscard]] RangeSigma rangeSigma(const ErrorModel& model, Constellation c, double elevation_rad,
                                    double tau_vert_m);

}  // namespace skylane::integrity
