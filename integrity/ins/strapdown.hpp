#pragma once
/// \file
/// \brief Strapdown inertial navigation in the Earth-centred Earth-fixed frame (P. D. Groves,
/// "Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems", 2nd ed., 2013,
/// §5.2 (ECEF mechanisation) and §2.4.7 (gravity model)).
///
/// One step from t to t + Δt with the body increments Δθ (rad) and Δv (m/s):
///   C⁺ = R_z(−ω_ie·Δt) · C · Exp(Δθ)                          (attitude, Groves Eq. 5.25 exact form)
///   v⁺ = v + C_mid·Δv + (g(r + v·Δt/2) − 2·Ω_ie·v)·Δt         (specific force, gravity, Coriolis)
///   r⁺ = r + (v + v⁺)·Δt/2                                   (trapezoid)
/// with C_mid = R_z(−ω_ie·Δt/2) · C · Exp(Δθ/2). `bodyIncrements` inverts exactly these
/// formulas, so a simulator that builds the IMU samples from a truth trajectory with it feeds the
/// mechanisation an error-free input (only the trapezoid's O(Δt³) position error remains).

#include <Eigen/Core>

namespace skylane::integrity::ins {

/// \brief Earth rotation rate ω_ie [rad/s] (WGS-84).
inline constexpr double kEarthRate_radps = 7.292115e-5;

/// \brief Gravity (gravitation + centrifugal) in ECEF at r [m/s²]: J2 gravitation (Groves Eq. 2.142)
/// plus ω_ie²·(x, y, 0).
[[nodiscard]] Eigen::Vector3d gravityEcef(const Eigen::Vector3d& r_ecef_m);

/// \brief The skew-symmetric matrix [a×].
[[nodiscard]] Eigen::Matrix3d skew(const Eigen::Vector3d& a);
/// \brief Rotation matrix of a rotation vector (Rodrigues).
[[nodiscard]] Eigen::Matrix3d expSo3(const Eigen::Vector3d& phi);
/// \brief Rotation vector of a rotation matrix (inverse of expSo3 for angles < π).
[[nodiscard]] Eigen::Vector3d logSo3(const Eigen::Matrix3d& R);

/// \brief The navigation state: position, velocity, attitude (body → ECEF).
struct NavState {
  Eigen::Vector3d r_ecef_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ecef_mps = Eigen::Vector3d::Zero();
  Eigen::Matrix3d C_ecef_body = Eigen::Matrix3d::Identity();
};

/// \brief One mechanisation step (file comment).
[[nodiscard]] NavState mechanise(const NavState& x, const Eigen::Vector3d& dtheta_rad, const Eigen::Vector3d& dv_mps,
                                 double dt_s);

/// \brief The body increments that carry `from` to `to` in `dt_s` under `mechanise` (attitude and
/// velocity exactly; position is whatever the trapezoid gives).
void bodyIncrements(const NavState& from, const NavState& to, double dt_s, Eigen::Vector3d& dtheta_rad,
                    Eigen::Vector3d& dv_mps);

/// \brief Body (FLU) → ENU for heading ψ (clockwise from north), pitch θ (nose up), roll φ
/// (right wing down): Rz(π/2 − ψ)·Ry(−θ)·Rx(φ).
[[nodiscard]] Eigen::Matrix3d bodyToEnu(double heading_rad, double pitch_rad, double roll_rad);

}  // namespace skylane::integrity::ins
