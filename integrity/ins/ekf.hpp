#pragma once
/// \file
/// \brief Error-state extended Kalman filter for a single IMU tightly coupled with GNSS
/// pseudoranges, with barometric-height and magnetometer-heading updates and closed-loop
/// correction of the strapdown solution (as in "Estimation algorithm of the computer-integrated navigation complex of an unmanned aerial vehicle", Electronics and Control Systems 2012 No. 4(34); docs/method.md §5.1: INS error states reset to zero after each
/// feedback; Groves 2013 §14.2 (ECEF error model) and §14.3.3 (tightly coupled measurement model)).
///
/// Error state δx = truth − estimate (18 states): δr (0–2), δv (3–5) in ECEF; attitude error φ
/// (6–8) with C_true = Exp(φ)·Ĉ; accelerometer and gyro bias errors (9–11, 12–14); receiver clock
/// bias and drift [m, m/s] (15, 16); barometer bias [m] (17). Continuous dynamics:
///   δṙ = δv
///   δv̇ = Γ·δr − 2Ω_ie·δv − [(Ĉ f̃)×]·φ − Ĉ·δb_a       (Γ = ∂g/∂r ≈ −μ/r³ (I − 3 r̂ r̂ᵀ))
///   φ̇  = −Ω_ie·φ − Ĉ·δb_g
///   biases, baro bias: random walks; clock: bias' = drift, drift' = white.
/// Pseudorange i: ν_i = ρ_i − (|s_i − r̂| + ĉ) = −u_iᵀ·δr + δc + noise (u_i the unit vector to the
/// satellite). Baro: ν = h_b − (ĥ + b̂_b) = upᵀ·δr + δb_b. Heading: ν = ψ_m − ψ̂ = ∂ψ/∂φ·φ.
///
/// Besides P the filter keeps, for every satellite it has used, the sensitivity of δx to a
/// constant bias of 1 m on that satellite's pseudorange (the ARAIM nominal bias b_nom): M ← Φ·M
/// in prediction, M ← (I − K H)·M − K·E in a GNSS update. Protection levels bound that bias's
/// effect by Σ_i |M_qi|·b_nom,i.

#include "integrity/gnss/satellite_id.hpp"
#include "integrity/ins/strapdown.hpp"

#include <Eigen/Core>

#include <map>
#include <vector>

namespace skylane::integrity::ins {

inline constexpr int kNumStates = 18;
inline constexpr int kPos = 0, kVel = 3, kAtt = 6, kAccBias = 9, kGyroBias = 12, kClock = 15, kDrift = 16, kBaro = 17;
using StateVector = Eigen::Matrix<double, kNumStates, 1>;
using StateMatrix = Eigen::Matrix<double, kNumStates, kNumStates>;

/// \brief The filter's noise model (what it assumes; the simulator may differ).
struct EkfConfig {
  double accel_noise_mps_rts = 2.0e-3;   ///< VRW
  double gyro_noise_rad_rts = 1.75e-4;   ///< ARW
  double accel_bias_rw_mps2_rts = 3e-4;
  double gyro_bias_rw_radps_rts = 1e-5;
  double accel_bias_mps2 = 3e-2;         ///< initial bias σ
  double gyro_bias_radps = 5e-4;
  double clock_h0 = 2e-19;
  double clock_hm2 = 2e-20;
  double baro_noise_m = 0.3;
  double baro_bias_m = 3.0;
  double baro_bias_rw_m_rts = 0.01;
  double heading_noise_rad = 2.0 * M_PI / 180.0;
  double initial_position_m = 5.0;       ///< initial σ per axis
  double initial_velocity_mps = 0.5;
  double initial_attitude_rad = 2.0 * M_PI / 180.0;
  double initial_clock_m = 30.0;
  double initial_drift_mps = 1.0;
  double covariance_rate_hz = 10.0;      ///< how often P (and M) are propagated
  /// Baro and heading readings with ν²/(h P hᵀ + r) above this are refused: χ²(1) at 1e-7
  /// (|ν| > 5.33 σ), so a wrong reading cannot pull the filter outside what its PLs cover.
  double aiding_gate_chi2 = 28.37;
};

/// \brief One pseudorange as the filter sees it.
struct RangeInput {
  SatId sat;
  Eigen::Vector3d sat_ecef_m = Eigen::Vector3d::Zero();
  double pseudorange_m = 0.0;
  double sigma_m = 1.0;  ///< σ_int
  double bnom_m = 0.0;
};

/// \brief Everything a GNSS update leaves for integrity monitoring (ENU = local frame at r̂).
struct GnssUpdateRecord {
  bool ok = false;
  std::vector<SatId> sats;               ///< measurement order
  Eigen::VectorXd sigma;                 ///< σ_int per measurement
  Eigen::VectorXd innovation;            ///< ν (before the update)
  Eigen::MatrixXd S;                     ///< innovation covariance H P⁻ Hᵀ + R
  Eigen::MatrixXd S_inv_Hpc;             ///< S⁻¹ H_pc (n × 4; H_pc = position and clock columns of H)
  Eigen::MatrixXd H;                     ///< n × 18
  Eigen::MatrixXd K;                     ///< 18 × n
  Eigen::Matrix3d R_enu_ecef = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d P_pos_enu = Eigen::Matrix3d::Zero();  ///< posterior position covariance, ENU
  Eigen::Vector3d correction_enu = Eigen::Vector3d::Zero();  ///< position part of K·ν, ENU
  /// \brief Bias sensitivities after the update: position rows in ENU, one column per satellite
  /// in `bias_sats` (every satellite the filter has used), and its b_nom.
  Eigen::MatrixXd M_pos_enu;
  Eigen::MatrixXd N_innov;               ///< n × bias_sats: sensitivity of ν to the biases
  std::vector<SatId> bias_sats;
  Eigen::VectorXd bias_bnom;
};

/// \brief The error-state EKF with its strapdown solution.
class InsEkf {
 public:
  InsEkf(const EkfConfig& cfg, const NavState& initial, double clock_m, double drift_mps);

  /// \brief Mechanises one IMU interval (bias-corrected) and propagates P at the covariance rate.
  void propagate(const Eigen::Vector3d& dtheta_rad, const Eigen::Vector3d& dv_mps, double dt_s);
  /// \brief Barometric height update (ellipsoidal height + baro bias).
  /// \returns false when the innovation test (EkfConfig::aiding_gate_chi2) refused the reading.
  bool updateBaro(double h_m);
  /// \brief Magnetometer heading update (clockwise from north, declination removed).
  /// \returns false when the innovation test refused the reading.
  bool updateHeading(double heading_rad);
  /// \brief Tightly coupled pseudorange update; returns the record for integrity monitoring.
  GnssUpdateRecord updateGnss(const std::vector<RangeInput>& ranges);

  [[nodiscard]] const NavState& nav() const { return nav_; }
  [[nodiscard]] double clock_m() const { return clock_m_; }
  [[nodiscard]] double drift_mps() const { return drift_mps_; }
  [[nodiscard]] const Eigen::Vector3d& accelBias() const { return accel_bias_; }
  [[nodiscard]] const Eigen::Vector3d& gyroBias() const { return gyro_bias_; }
  [[nodiscard]] double baroBias_m() const { return baro_bias_m_; }
  [[nodiscard]] const StateMatrix& covariance() const { return P_; }
  /// \brief Heading of the body's forward axis (clockwise from north) [rad].
  [[nodiscard]] double heading_rad() const;
  /// \brief Predicted pseudorange of a satellite from the current estimate.
  [[nodiscard]] double predictedRange_m(const Eigen::Vector3d& sat_ecef_m) const;

 private:
  void propagateCovariance();
  /// Scalar update (Joseph form, expanded); applies the correction and resets δx.
  /// \returns false (and leaves the state alone) when ν²/s exceeds `gate_chi2`.
  bool updateScalar(const Eigen::Matrix<double, 1, kNumStates>& h, double nu, double r, double gate_chi2);
  void applyCorrection(const StateVector& dx);

  EkfConfig cfg_;
  NavState nav_;
  Eigen::Vector3d accel_bias_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero();
  double clock_m_ = 0.0;
  double drift_mps_ = 0.0;
  double baro_bias_m_ = 0.0;
  StateMatrix P_ = StateMatrix::Zero();
  std::map<SatId, StateVector> sensitivity_;  ///< M columns
  std::map<SatId, double> bnom_;
  // Accumulated since the last covariance propagation.
  double acc_dt_s_ = 0.0;
  Eigen::Vector3d acc_dv_ecef_ = Eigen::Vector3d::Zero();
};

}  // namespace skylane::integrity::ins
