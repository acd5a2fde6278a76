#include "integrity/ins/ekf.hpp"

#include "integrity/gnss/ephemeris.hpp"

#include "maps/geodesy.hpp"

#include <Eigen/Cholesky>

#include <cmath>
#include <stdexcept>

namespace skylane::integrity::ins {

namespace {

constexpr double kGm_m3ps2 = 3.986004418e14;

}  // namespace

InsEkf::InsEkf(const EkfConfig& cfg, const NavState& initial, double clock_m, double drift_mps)
    : cfg_(cfg), nav_(initial), clock_m_(clock_m), drift_mps_(drift_mps) {
  if (!(cfg_.covariance_rate_hz > 0.0)) throw std::invalid_argument("ins ekf: covariance rate must be > 0 Hz");
  StateVector d;
  d.segment<3>(kPos).setConstant(cfg_.initial_position_m);
  d.segment<3>(kVel).setConstant(cfg_.initial_velocity_mps);
  d.segment<3>(kAtt).setConstant(cfg_.initial_attitude_rad);
  d.segment<3>(kAccBias).setConstant(cfg_.accel_bias_mps2);
  d.segment<3>(kGyroBias).setConstant(cfg_.gyro_bias_radps);
  d(kClock) = cfg_.initial_clock_m;
  d(kDrift) = cfg_.initial_drift_mps;
  d(kBaro) = cfg_.baro_bias_m;
  P_ = d.cwiseAbs2().asDiagonal();
}

void InsEkf::propagate(const Eigen::Vector3d& dtheta, const Eigen::Vector3d& dv, double dt) {
  const Eigen::Vector3d dtheta_c = dtheta - gyro_bias_ * dt;
  const Eigen::Vector3d dv_c = dv - accel_bias_ * dt;
  acc_dv_ecef_ += nav_.C_ecef_body * dv_c;
  nav_ = mechanise(nav_, dtheta_c, dv_c, dt);
  clock_m_ += drift_mps_ * dt;
  acc_dt_s_ += dt;
  if (acc_dt_s_ >= 1.0 / cfg_.covariance_rate_hz - 1e-9) propagateCovariance();
}

void InsEkf::propagateCovariance() {
  const double dt = acc_dt_s_;
  if (dt <= 0.0) return;
  const Eigen::Vector3d f_ecef = acc_dv_ecef_ / dt;  // mean specific force over the block
  const Eigen::Matrix3d& C = nav_.C_ecef_body;
  const Eigen::Vector3d& r = nav_.r_ecef_m;
  const double rn = r.norm();
  const Eigen::Vector3d ur = r / rn;
  const Eigen::Matrix3d Omega = skew(Eigen::Vector3d(0.0, 0.0, kEarthRate_radps));

  StateMatrix F = StateMatrix::Zero();
  F.block<3, 3>(kPos, kVel).setIdentity();
  F.block<3, 3>(kVel, kPos) = -kGm_m3ps2 / (rn * rn * rn) * (Eigen::Matrix3d::Identity() - 3.0 * ur * ur.transpose());
  F.block<3, 3>(kVel, kVel) = -2.0 * Omega;
  F.block<3, 3>(kVel, kAtt) = -skew(f_ecef);
  F.block<3, 3>(kVel, kAccBias) = -C;
  F.block<3, 3>(kAtt, kAtt) = -Omega;
  F.block<3, 3>(kAtt, kGyroBias) = -C;
  F(kClock, kDrift) = 1.0;
  const StateMatrix Fdt = F * dt;
  const StateMatrix Phi = StateMatrix::Identity() + Fdt + 0.5 * Fdt * Fdt;

  StateMatrix Q = StateMatrix::Zero();
  const double c2 = kSpeedOfLight_mps * kSpeedOfLight_mps;
  const double q_b = c2 * cfg_.clock_h0 / 2.0;
  const double q_d = 2.0 * M_PI * M_PI * c2 * cfg_.clock_hm2;
  for (int i = 0; i < 3; ++i) {
    Q(kVel + i, kVel + i) = cfg_.accel_noise_mps_rts * cfg_.accel_noise_mps_rts * dt;
    Q(kAtt + i, kAtt + i) = cfg_.gyro_noise_rad_rts * cfg_.gyro_noise_rad_rts * dt;
    Q(kAccBias + i, kAccBias + i) = cfg_.accel_bias_rw_mps2_rts * cfg_.accel_bias_rw_mps2_rts * dt;
    Q(kGyroBias + i, kGyroBias + i) = cfg_.gyro_bias_rw_radps_rts * cfg_.gyro_bias_rw_radps_rts * dt;
    // position picks up the velocity noise integrated over the block
    Q(kPos + i, kPos + i) = Q(kVel + i, kVel + i) * dt * dt / 3.0;
    Q(kPos + i, kVel + i) = Q(kVel + i, kPos + i) = Q(kVel + i, kVel + i) * dt / 2.0;
  }
  // Two-state clock (Brown & Hwang 4th ed. Eq. 9.3.11).
  Q(kClock, kClock) = q_b * dt + q_d * dt * dt * dt / 3.0;
  Q(kClock, kDrift) = Q(kDrift, kClock) = q_d * dt * dt / 2.0;
  Q(kDrift, kDrift) = q_d * dt;
  Q(kBaro, kBaro) = cfg_.baro_bias_rw_m_rts * cfg_.baro_bias_rw_m_rts * dt;

  P_ = Phi * P_ * Phi.transpose() + Q;
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  for (auto& [sat, m] : sensitivity_) m = Phi * m;
  acc_dt_s_ = 0.0;
  acc_dv_ecef_.setZero();
}

void InsEkf::applyCorrection(const StateVector& dx) {
  nav_.r_ecef_m += dx.segment<3>(kPos);
  nav_.v_ecef_mps += dx.segment<3>(kVel);
  nav_.C_ecef_body = expSo3(dx.segment<3>(kAtt)) * nav_.C_ecef_body;
  accel_bias_ += dx.segment<3>(kAccBias);
  gyro_bias_ += dx.segment<3>(kGyroBias);
  clock_m_ += dx(kClock);
  drift_mps_ += dx(kDrift);
  baro_bias_m_ += dx(kBaro);
}

bool InsEkf::updateScalar(const Eigen::Matrix<double, 1, kNumStates>& h, double nu, double r, double gate_chi2) {
  propagateCovariance();  // fold any pending propagation in first so that P belongs to now
  const StateVector PHt = P_ * h.transpose();
  const double s = h.dot(PHt) + r;
  if (!(s > 0.0)) throw std::runtime_error("ins ekf: innovation variance not positive");
  if (!(nu * nu / s <= gate_chi2)) return false;
  const StateVector K = PHt / s;
  // Joseph form expanded for a scalar measurement: (I − K h) P (I − K h)ᵀ + K r Kᵀ
  // = P − K PHtᵀ − PHt Kᵀ + s K Kᵀ (O(n²) instead of two n³ products).
  P_ += s * K * K.transpose() - K * PHt.transpose() - PHt * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  for (auto& [sat, m] : sensitivity_) m -= K * h.dot(m);  // M ← (I − K h) M
  applyCorrection(K * nu);
  return true;
}

bool InsEkf::updateBaro(double h_m) {
  const maps::Geodetic g = maps::ecefToGeodetic(nav_.r_ecef_m);
  const Eigen::Matrix3d R_enu_ecef = maps::rotationEcefToEnu(g.lat_rad, g.lon_rad);
  Eigen::Matrix<double, 1, kNumStates> h = Eigen::Matrix<double, 1, kNumStates>::Zero();
  h.segment<3>(kPos) = R_enu_ecef.row(2);
  h(kBaro) = 1.0;
  return updateScalar(h, h_m - (g.h_ell_m + baro_bias_m_), cfg_.baro_noise_m * cfg_.baro_noise_m, cfg_.aiding_gate_chi2);
}

double InsEkf::heading_rad() const {
  const maps::Geodetic g = maps::ecefToGeodetic(nav_.r_ecef_m);
  const Eigen::Vector3d f = maps::rotationEcefToEnu(g.lat_rad, g.lon_rad) * nav_.C_ecef_body.col(0);
  return std::atan2(f.x(), f.y());
}

bool InsEkf::updateHeading(double heading_rad) {
  const maps::Geodetic g = maps::ecefToGeodetic(nav_.r_ecef_m);
  const Eigen::Matrix3d R_enu_ecef = maps::rotationEcefToEnu(g.lat_rad, g.lon_rad);
  const Eigen::Vector3d f_ecef = nav_.C_ecef_body.col(0);
  const Eigen::Vector3d f = R_enu_ecef * f_ecef;
  const double h2 = f.x() * f.x() + f.y() * f.y();
  if (h2 < 1e-6) return false;  // nose vertical: heading undefined
  // ψ = atan2(f_E, f_N); δf = φ × f = −[f×]φ (ECEF), so ∂ψ/∂φ = (f_N, −f_E, 0)/(f_E² + f_N²) · R · (−[f×]).
  const Eigen::RowVector3d dpsi_df = Eigen::RowVector3d(f.y(), -f.x(), 0.0) / h2;
  Eigen::Matrix<double, 1, kNumStates> h = Eigen::Matrix<double, 1, kNumStates>::Zero();
  h.segment<3>(kAtt) = dpsi_df * R_enu_ecef * (-skew(f_ecef));
  return updateScalar(h, std::remainder(heading_rad - std::atan2(f.x(), f.y()), 2.0 * M_PI),
               cfg_.heading_noise_rad * cfg_.heading_noise_rad, cfg_.aiding_gate_chi2);
}

double InsEkf::predictedRange_m(const Eigen::Vector3d& sat_ecef_m) const {
  return (sat_ecef_m - nav_.r_ecef_m).norm() + clock_m_;
}

GnssUpdateRecord InsEkf::updateGnss(const std::vector<RangeInput>& ranges) {
  GnssUpdateRecord rec;
  const int n = static_cast<int>(ranges.size());
  if (n == 0) return rec;
  propagateCovariance();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, kNumStates);
  Eigen::VectorXd nu(n);
  rec.sigma.resize(n);
  for (int i = 0; i < n; ++i) {
    const RangeInput& in = ranges[i];
    const Eigen::Vector3d los = in.sat_ecef_m - nav_.r_ecef_m;
    H.block<1, 3>(i, kPos) = -(los / los.norm()).transpose();
    H(i, kClock) = 1.0;
    nu(i) = in.pseudorange_m - predictedRange_m(in.sat_ecef_m);
    rec.sigma(i) = in.sigma_m;
    rec.sats.push_back(in.sat);
    sensitivity_.try_emplace(in.sat, StateVector::Zero());
    bnom_[in.sat] = in.bnom_m;
  }
  // Sensitivities before the update, for N = H·M⁻ + E.
  rec.bias_sats.reserve(sensitivity_.size());
  Eigen::MatrixXd M_prior(kNumStates, static_cast<Eigen::Index>(sensitivity_.size()));
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(sensitivity_.size()));
  rec.bias_bnom.resize(static_cast<Eigen::Index>(sensitivity_.size()));
  int col = 0;
  for (const auto& [sat, m] : sensitivity_) {
    M_prior.col(col) = m;
    rec.bias_sats.push_back(sat);
    rec.bias_bnom(col) = bnom_[sat];
    for (int i = 0; i < n; ++i) {
      if (rec.sats[i] == sat) E(i, col) = 1.0;
    }
    ++col;
  }
  // S = H P Hᵀ + R = L Lᵀ; with W = L⁻¹ H P: K = (L⁻ᵀ W)ᵀ and K S Kᵀ = Wᵀ W, so the
  // posterior P − K S Kᵀ (= P − K H P for the optimal gain) is formed symmetric.
  const Eigen::MatrixXd HP = H * P_;
  rec.S = HP * H.transpose();
  rec.S.diagonal() += rec.sigma.cwiseAbs2();
  const Eigen::LLT<Eigen::MatrixXd> llt(rec.S);
  if (llt.info() != Eigen::Success) throw std::runtime_error("ins ekf: innovation covariance not positive definite");
  const Eigen::MatrixXd W = llt.matrixL().solve(HP);
  rec.K = llt.matrixU().solve(W).transpose();
  P_.noalias() -= W.transpose() * W;
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  rec.innovation = nu;
  rec.H = H;
  Eigen::MatrixXd Hpc(n, 4);
  Hpc.leftCols<3>() = H.middleCols<3>(kPos);
  Hpc.col(3) = H.col(kClock);
  rec.S_inv_Hpc = llt.solve(Hpc);
  // M⁺ = (I − K H) M⁻ − K E = M⁻ − K N with N = H M⁻ + E.
  rec.N_innov = H * M_prior + E;
  const Eigen::MatrixXd KN = rec.K * rec.N_innov;
  col = 0;
  for (auto& [sat, m] : sensitivity_) m -= KN.col(col++);
  applyCorrection(rec.K * nu);
  const maps::Geodetic g = maps::ecefToGeodetic(nav_.r_ecef_m);
  rec.R_enu_ecef = maps::rotationEcefToEnu(g.lat_rad, g.lon_rad);
  rec.P_pos_enu = rec.R_enu_ecef * P_.block<3, 3>(kPos, kPos) * rec.R_enu_ecef.transpose();
  rec.correction_enu = rec.R_enu_ecef * (rec.K * nu).segment<3>(kPos);
  rec.M_pos_enu.resize(3, static_cast<Eigen::Index>(sensitivity_.size()));
  col = 0;
  for (const auto& [sat, m] : sensitivity_) rec.M_pos_enu.col(col++) = rec.R_enu_ecef * m.segment<3>(kPos);
  rec.ok = true;
  return rec;
}

}  // namespace skylane::integrity::ins
