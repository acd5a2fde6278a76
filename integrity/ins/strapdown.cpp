#include "integrity/ins/strapdown.hpp"

#include <Eigen/Geometry>

#include <cmath>

namespace skylane::integrity::ins {

namespace {

constexpr double kGm_m3ps2 = 3.986004418e14;  // WGS-84 μ
constexpr double kJ2 = 1.082627e-3;           // WGS-84 J2
constexpr double kA_m = 6378137.0;

Eigen::Matrix3d earthTurn(double angle_rad) {  // R_z(−angle): the Earth frame's turn over the step
  return Eigen::AngleAxisd(-angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

Eigen::Vector3d gravityEcef(const Eigen::Vector3d& r) {
  const double rn = r.norm();
  const double z2 = (r.z() / rn) * (r.z() / rn);
  const double f = 1.5 * kJ2 * (kA_m / rn) * (kA_m / rn);
  // Groves Eq. 2.142: γ = −μ/r³ · [r + 1.5 J2 (a/r)² ((1 − 5 z²/r²) x, (1 − 5 z²/r²) y, (3 − 5 z²/r²) z)]
  const Eigen::Vector3d gamma = -kGm_m3ps2 / (rn * rn * rn) *
                                Eigen::Vector3d(r.x() * (1.0 + f * (1.0 - 5.0 * z2)), r.y() * (1.0 + f * (1.0 - 5.0 * z2)),
                                                r.z() * (1.0 + f * (3.0 - 5.0 * z2)));
  const double w2 = kEarthRate_radps * kEarthRate_radps;
  return gamma + Eigen::Vector3d(w2 * r.x(), w2 * r.y(), 0.0);  // Groves Eq. 2.133: g = γ − Ω Ω r
}

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

Eigen::Matrix3d expSo3(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity() + skew(phi);
  return Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
}

Eigen::Vector3d logSo3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

NavState mechanise(const NavState& x, const Eigen::Vector3d& dtheta, const Eigen::Vector3d& dv, double dt) {
  const double w = kEarthRate_radps * dt;
  const Eigen::Matrix3d C_mid = earthTurn(0.5 * w) * x.C_ecef_body * expSo3(0.5 * dtheta);
  NavState out;
  out.C_ecef_body = earthTurn(w) * x.C_ecef_body * expSo3(dtheta);
  const Eigen::Vector3d coriolis = 2.0 * kEarthRate_radps * Eigen::Vector3d(-x.v_ecef_mps.y(), x.v_ecef_mps.x(), 0.0);
  const Eigen::Vector3d g = gravityEcef(x.r_ecef_m + 0.5 * dt * x.v_ecef_mps);
  out.v_ecef_mps = x.v_ecef_mps + C_mid * dv + (g - coriolis) * dt;
  out.r_ecef_m = x.r_ecef_m + 0.5 * dt * (x.v_ecef_mps + out.v_ecef_mps);
  return out;
}

void bodyIncrements(const NavState& from, const NavState& to, double dt, Eigen::Vector3d& dtheta,
                    Eigen::Vector3d& dv) {
  const double w = kEarthRate_radps * dt;
  // C⁺ = R_z(−w) C Exp(Δθ) ⇒ Exp(Δθ) = Cᵀ R_z(w) C⁺.
  dtheta = logSo3(from.C_ecef_body.transpose() * earthTurn(-w) * to.C_ecef_body);
  const Eigen::Matrix3d C_mid = earthTurn(0.5 * w) * from.C_ecef_body * expSo3(0.5 * dtheta);
  const Eigen::Vector3d coriolis = 2.0 * kEarthRate_radps * Eigen::Vector3d(-from.v_ecef_mps.y(), from.v_ecef_mps.x(), 0.0);
  const Eigen::Vector3d g = gravityEcef(from.r_ecef_m + 0.5 * dt * from.v_ecef_mps);
  dv = C_mid.transpose() * (to.v_ecef_mps - from.v_ecef_mps - (g - coriolis) * dt);
}

Eigen::Matrix3d bodyToEnu(double heading_rad, double pitch_rad, double roll_rad) {
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(M_PI / 2.0 - heading_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d Ry = Eigen::AngleAxisd(-pitch_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d Rx = Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return Rz * Ry * Rx;
}

}  // namespace skylane::integrity::ins
