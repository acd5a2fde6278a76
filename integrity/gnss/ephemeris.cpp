#include "integrity/gnss/ephemeris.hpp"

#include <cmath>

namespace skylane::integrity {
namespace {

/// Kepler's equation is solved to this eccentric-anomaly change [rad] (≈ 0.03 mm on the orbit).
constexpr double kKeplerTolerance_rad = 1e-14;
constexpr int kKeplerMaxIterations = 30;

double muOf(Constellation c) { return c == Constellation::kGalileo ? kMuGalileo : kMuGps; }

/// Time difference wrapped to ±half a week (IS-GPS-200 §20.3.3.4.3: "t_k shall be the actual
/// total time difference … accounting for beginning or end of week crossovers").
double wrapWeek(double dt_s) {
  if (dt_s > kSecondsPerWeek / 2) return dt_s - kSecondsPerWeek;
  if (dt_s < -kSecondsPerWeek / 2) return dt_s + kSecondsPerWeek;
  return dt_s;
}

}  // namespace

OrbitState keplerPosition(const KeplerOrbit& o, const GpsTime& t) {
  const double mu = muOf(o.constellation);
  const double a = o.sqrt_a * o.sqrt_a;
  const double n0 = std::sqrt(mu / (a * a * a));  // computed mean motion
  const double tk = t - o.toe;                    // full difference (weeks resolved by caller)
  const double n = n0 + o.delta_n_radps;
  const double mk = o.m0_rad + n * tk;  // mean anomaly
  double ek = mk;                       // Kepler's equation M = E − e sin E, Newton iterations
  for (int i = 0; i < kKeplerMaxIterations; ++i) {
    const double d = (ek - o.e * std::sin(ek) - mk) / (1.0 - o.e * std::cos(ek));
    ek -= d;
    if (std::abs(d) < kKeplerTolerance_rad) break;
  }
  const double sin_e = std::sin(ek), cos_e = std::cos(ek);
  const double nu = std::atan2(std::sqrt(1.0 - o.e * o.e) * sin_e, cos_e - o.e);  // true anomaly
  const double phi = nu + o.omega_rad;  // argument of latitude
  const double s2p = std::sin(2 * phi), c2p = std::cos(2 * phi);
  const double uk = phi + o.cus * s2p + o.cuc * c2p;
  const double rk = a * (1.0 - o.e * cos_e) + o.crs * s2p + o.crc * c2p;
  const double ik = o.i0_rad + o.idot_radps * tk + o.cis * s2p + o.cic * c2p;
  const double xp = rk * std::cos(uk), yp = rk * std::sin(uk);  // orbital plane
  const double omk = o.omega0_rad + (o.omega_dot_radps - kEarthRotation_radps) * tk -
                     kEarthRotation_radps * o.toe.sow;  // corrected longitude of node
  const double co = std::cos(omk), so = std::sin(omk), ci = std::cos(ik), si = std::sin(ik);
  OrbitState out;
  out.p_ecef = {xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si};
  out.eccentric_anomaly_rad = ek;
  return out;
}

double relativisticClock(const KeplerOrbit& orbit, double eccentric_anomaly_rad) {
  const double f = -2.0 * std::sqrt(muOf(orbit.constellation)) /
                   (kSpeedOfLight_mps * kSpeedOfLight_mps);  // F = −4.442807633e−10 s/√m (GPS)
  return f * orbit.e * orbit.sqrt_a * std::sin(eccentric_anomaly_rad);
}

double clockPolynomial(const BroadcastEphemeris& eph, const GpsTime& t) {
  const double dt = wrapWeek(t - eph.toc);
  return eph.af0_s + eph.af1_sps * dt + eph.af2_sps2 * dt * dt;
}

SatelliteState satelliteState(const BroadcastEphemeris& eph, const GpsTime& t) {
  const OrbitState o = keplerPosition(eph.orbit, t);
  SatelliteState s;
  s.sat = eph.sat;
  s.p_ecef = o.p_ecef;
  s.relativistic_s = relativisticClock(eph.orbit, o.eccentric_anomaly_rad);
  s.clock_s = clockPolynomial(eph, t) + s.relativistic_s;
  return s;
}

Eigen::Vector3d earthRotationCorrection(const Eigen::Vector3d& p_ecef_tx, double flight_time_s) {
  const double theta = kEarthRotation_radps * flight_time_s;
  const double c = std::cos(theta), s = std::sin(theta);
  return {c * p_ecef_tx.x() + s * p_ecef_tx.y(), -s * p_ecef_tx.x() + c * p_ecef_tx.y(),
          p_ecef_tx.z()};
}

}  // namespace skylane::integrity
