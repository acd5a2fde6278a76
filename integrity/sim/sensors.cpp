#include "integrity/sim/sensors.hpp"

#include "integrity/gnss/ephemeris.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace skylane::integrity::sim {

double FaultSpec::valueAt(double t_s) const {
  if (t_s < t_start_s || t_s >= t_end_s) return 0.0;
  return ramp ? magnitude * (t_s - t_start_s) : magnitude;
}

namespace {

ins::NavState navOf(const TruthState& x) {
  ins::NavState n;
  n.r_ecef_m = x.p_ecef_m;
  n.v_ecef_mps = x.v_ecef_mps;
  n.C_ecef_body = x.C_ecef_body;
  return n;
}

}  // namespace

SensorSimulator::SensorSimulator(const Trajectory& trajectory, const OrbitSource& orbits, const GpsTime& start,
                                 SensorSpec spec, std::vector<FaultSpec> faults, std::uint64_t seed)
    : trajectory_(trajectory), orbits_(orbits), start_(start), spec_(std::move(spec)), faults_(std::move(faults)),
      rng_(seed) {
  if (!(spec_.imu.rate_hz > 0.0) || !(spec_.gnss_rate_hz > 0.0)) {
    throw std::invalid_argument("sensor simulator: IMU and GNSS rates must be > 0 Hz");
  }
  const double ratio = spec_.imu.rate_hz / spec_.gnss_rate_hz;
  imu_per_gnss_ = static_cast<int>(std::lround(ratio));
  if (imu_per_gnss_ < 1 || std::abs(ratio - imu_per_gnss_) > 1e-9) {
    throw std::invalid_argument("sensor simulator: the IMU rate must be a whole multiple of the GNSS rate");
  }
  truth_ = trajectory_.at(0.0);
  truth_nav_ = navOf(truth_);
  for (int i = 0; i < 3; ++i) {
    accel_bias_[i] = spec_.imu.accel_bias_mps2 * normal();
    gyro_bias_[i] = spec_.imu.gyro_bias_radps * normal();
  }
  clock_m_ = 100.0 * normal();  // an arbitrary start: the filter learns it from the first fix
  clock_drift_mps_ = 0.1 * normal();
  baro_bias_m_ = spec_.baro_bias_m * normal();
}

ImuSample SensorSimulator::stepImu() {
  const double dt = 1.0 / spec_.imu.rate_hz;
  const ins::NavState from = truth_nav_;
  ++step_;
  truth_ = trajectory_.at(static_cast<double>(step_) * dt);
  truth_nav_ = navOf(truth_);
  ImuSample s;
  s.t_s = truth_.t_s;
  s.dt_s = dt;
  ins::bodyIncrements(from, truth_nav_, dt, s.dtheta_rad, s.dv_mps);

  // Errors over the interval: bias (turn-on + random walk) + faults, white noise.
  const double t_mid = truth_.t_s - 0.5 * dt;
  Eigen::Vector3d accel_fault = Eigen::Vector3d::Zero(), gyro_fault = Eigen::Vector3d::Zero();
  for (const FaultSpec& f : faults_) {
    if (f.target == FaultTarget::kAccelerometer) accel_fault[f.axis] += f.valueAt(t_mid);
    if (f.target == FaultTarget::kGyro) gyro_fault[f.axis] += f.valueAt(t_mid);
  }
  const double rt = std::sqrt(dt);
  for (int i = 0; i < 3; ++i) {
    s.dv_mps[i] += (accel_bias_[i] + accel_fault[i]) * dt + spec_.imu.accel_noise_mps_rts * rt * normal();
    s.dtheta_rad[i] += (gyro_bias_[i] + gyro_fault[i]) * dt + spec_.imu.gyro_noise_rad_rts * rt * normal();
    accel_bias_[i] += spec_.imu.accel_bias_rw_mps2_rts * rt * normal();
    gyro_bias_[i] += spec_.imu.gyro_bias_rw_radps_rts * rt * normal();
  }
  // Receiver clock (two-state random walk, Brown & Hwang §9.3).
  const double c = kSpeedOfLight_mps;
  const double q_b = c * c * spec_.clock_h0 / 2.0;
  const double q_d = 2.0 * M_PI * M_PI * c * c * spec_.clock_hm2;
  clock_m_ += clock_drift_mps_ * dt + std::sqrt(q_b * dt) * normal();
  clock_drift_mps_ += std::sqrt(q_d * dt) * normal();
  baro_bias_m_ += spec_.baro_bias_rw_m_rts * rt * normal();
  return s;
}

bool SensorSimulator::gnssDue() const { return step_ % imu_per_gnss_ == 0; }

GnssEpoch SensorSimulator::gnss() {
  GnssEpoch e;
  e.t_s = truth_.t_s;
  e.time = start_.plus(truth_.t_s);
  for (const FaultSpec& f : faults_) {
    if (f.target == FaultTarget::kGnssOutage && f.valueAt(e.t_s) != 0.0) e.outage = true;
  }
  if (e.outage) return e;
  const double tau = spec_.model.iono_tau_vert_m.value_or(9.0);
  const std::vector<VisibleSatellite> in_view = orbits_.visible(truth_.p_ecef_m, e.time, spec_.elevation_mask_rad);
  for (FaultSpec& f : faults_) {
    if (f.target == FaultTarget::kSatellite && f.sats.empty() && f.pick >= 0.0 && f.valueAt(e.t_s) != 0.0 &&
        !in_view.empty()) {
      std::vector<SatId> ids;
      for (const VisibleSatellite& v : in_view) ids.push_back(v.sat);
      std::sort(ids.begin(), ids.end());
      const auto k = std::min(ids.size() - 1, static_cast<std::size_t>(f.pick * static_cast<double>(ids.size())));
      f.sats.push_back(ids[k]);
    }
  }
  for (const VisibleSatellite& v : in_view) {
    const RangeSigma sig = rangeSigma(spec_.model, v.sat.constellation, v.look.elevation_rad, tau);
    auto [it, fresh] = nominal_bias_m_.try_emplace(v.sat, 0.0);
    if (fresh) it->second = sig.bnom_m * (2.0 * std::uniform_real_distribution<double>(0.0, 1.0)(rng_) - 1.0);
    Pseudorange p;
    p.sat = v.sat;
    p.sat_ecef_m = v.p_ecef;
    p.elevation_rad = v.look.elevation_rad;
    p.azimuth_rad = v.look.azimuth_rad;
    for (const FaultSpec& f : faults_) {
      if (f.target != FaultTarget::kSatellite) continue;
      for (const SatId& s : f.sats) {
        if (s == v.sat) p.injected_m += f.valueAt(e.t_s) * (f.in_sigma ? sig.sigma_int_m : 1.0);
      }
    }
    p.pseudorange_m = v.range_m + clock_m_ + it->second + sig.sigma_acc_m * normal() + p.injected_m;
    e.ranges.push_back(p);
  }
  return e;
}

AidingSample SensorSimulator::aiding() {
  AidingSample a;
  a.baro_h_m = truth_.geodetic.h_ell_m + baro_bias_m_ + spec_.baro_noise_m * normal();
  a.heading_rad = std::remainder(truth_.heading_rad + spec_.heading_noise_rad * normal(), 2.0 * M_PI);
  return a;
}

}  // namespace skylane::integrity::sim
