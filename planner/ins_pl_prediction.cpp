// The GNSS/INS prediction of ins_pl_prediction.hpp: the tracker's navigator run along the route
// on measurements equal to its own predictions (every innovation zero).
#include "planner/ins_pl_prediction.hpp"

#include "integrity/ins/strapdown.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace skylane::planner {

namespace {

/// Below this horizontal speed the heading is kept (hover, vertical climb) [m/s].
constexpr double kMinHeadingSpeed_mps = 0.05;
/// Two epoch times closer than this are one epoch (a sample on a whole second) [s].
constexpr double kSameEpoch_s = 1e-6;

/// \brief The truth along the route at one instant (file comment of the header, step 1).
struct RouteTruth {
  const InsPredictionInput& in;
  double half_step_s;
  mutable double heading_rad = 0.0;  ///< kept while the vehicle does not move horizontally

  /// The navigation state at t: position, central-difference velocity, level attitude along track.
  [[nodiscard]] integrity::ins::NavState at(double t_s) const {
    const double t0 = std::max(0.0, t_s - half_step_s), t1 = std::min(in.duration_s, t_s + half_step_s);
    const maps::Geodetic g = in.where(t_s);
    integrity::ins::NavState x;
    x.r_ecef_m = maps::geodeticToEcef(g);
    if (t1 > t0) x.v_ecef_mps = (maps::geodeticToEcef(in.where(t1)) - maps::geodeticToEcef(in.where(t0))) / (t1 - t0);
    const Eigen::Matrix3d R_enu_ecef = maps::rotationEcefToEnu(g.lat_rad, g.lon_rad);
    const Eigen::Vector3d v_enu = R_enu_ecef * x.v_ecef_mps;
    if (v_enu.head<2>().norm() > kMinHeadingSpeed_mps) heading_rad = std::atan2(v_enu.x(), v_enu.y());
    x.C_ecef_body = R_enu_ecef.transpose() * integrity::ins::bodyToEnu(heading_rad, 0.0, 0.0);
    return x;
  }
};

void requireValidInput(const InsPredictionInput& in) {
  if (!(std::isfinite(in.duration_s) && in.duration_s >= 0.0)) {
    throw std::invalid_argument("GNSS/INS prediction: the route's duration is not a finite number ≥ 0");
  }
  if (!in.where) throw std::invalid_argument("GNSS/INS prediction: no route position function");
  if (!(in.imu_rate_hz > 0.0)) throw std::invalid_argument("GNSS/INS prediction: the IMU rate must be > 0 Hz");
  double last = 0.0;
  for (double t : in.sample_t_s) {
    if (!(t >= last && t <= in.duration_s + kSameEpoch_s)) {
      throw std::invalid_argument("GNSS/INS prediction: sample times must ascend within [0, " +
                                  std::to_string(in.duration_s) + "] s");
    }
    last = t;
  }
}

/// \brief The epochs: every kGnssEpoch_s and every sample time, ascending and distinct; for
/// each, the samples at it and the sample whose sky mask it uses (its own, else the last before).
struct EpochPlan {
  std::vector<double> t_s;
  std::vector<std::vector<std::size_t>> samples_at;
  std::vector<std::size_t> mask_sample;
};

EpochPlan planEpochs(const InsPredictionInput& in) {
  std::vector<std::pair<double, std::optional<std::size_t>>> times;
  for (int i = 0; i * kGnssEpoch_s <= in.duration_s + kSameEpoch_s; ++i) times.emplace_back(i * kGnssEpoch_s, std::nullopt);
  for (std::size_t k = 0; k < in.sample_t_s.size(); ++k) times.emplace_back(in.sample_t_s[k], k);
  std::stable_sort(times.begin(), times.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  EpochPlan plan;
  std::size_t last_sample = 0;
  for (const auto& [t, sample] : times) {
    if (plan.t_s.empty() || t - plan.t_s.back() >= kSameEpoch_s) {
      plan.t_s.push_back(t);
      plan.samples_at.emplace_back();
      plan.mask_sample.push_back(last_sample);
    }
    if (sample) {
      plan.samples_at.back().push_back(*sample);
      plan.mask_sample.back() = last_sample = *sample;
    }
  }
  return plan;
}

/// \brief Step 3: IMU increments from the filter's state to the truth, up to t_to.
void flyTo(integrity::ins::Navigator& nav, const RouteTruth& truth, double t_from, double t_to, double imu_rate_hz) {
  const int steps = static_cast<int>(std::ceil((t_to - t_from) * imu_rate_hz - kSameEpoch_s));
  if (steps <= 0) return;
  const double dt = (t_to - t_from) / steps;
  for (int i = 1; i <= steps; ++i) {
    const integrity::ins::NavState to = truth.at(t_from + i * dt);
    Eigen::Vector3d dtheta, dv;
    integrity::ins::bodyIncrements(nav.filter().nav(), to, dt, dtheta, dv);
    nav.propagate(dtheta, dv, dt);
  }
}

/// \brief Step 4: the satellites in view at the filter's place, each ranged as the filter
/// predicts it; the count of those behind the sample's sky mask goes to `blocked`.
std::vector<integrity::ins::PseudorangeInput> errorFreeRanges(const integrity::OrbitSource& orbits,
                                                              const InsPredictionInput& in, const integrity::ins::InsEkf& ekf,
                                                              const maps::GpsTime& t, std::size_t k, int& blocked) {
  std::vector<integrity::ins::PseudorangeInput> ranges;
  blocked = 0;
  for (const integrity::VisibleSatellite& v : orbits.visible(ekf.nav().r_ecef_m, t, in.config.elevation_mask_rad)) {
    if (in.outside_sky_mask && !in.outside_sky_mask(k, v.look)) {
      ++blocked;
      continue;
    }
    ranges.push_back({v.sat, v.p_ecef, ekf.predictedRange_m(v.p_ecef)});
  }
  return ranges;
}

/// \brief Step 5: what a sample keeps of its epoch.
InsPredictedPl samplePl(const integrity::ins::NavigatorEpoch& ep, int blocked) {
  InsPredictedPl pl;
  pl.available = ep.fault_mode_available;
  pl.hpl_m = ep.fault_mode_hpl_m;
  pl.vpl_m = ep.fault_mode_vpl_m;
  pl.three_hypothesis_available = ep.three_hypothesis_ins.available;
  pl.three_hypothesis_hpl_m = ep.three_hypothesis_ins.hpl_m;
  pl.three_hypothesis_vpl_m = ep.three_hypothesis_ins.vpl_m;
  pl.satellites = ep.used;
  pl.blocked = blocked;
  return pl;
}

}  // namespace

std::vector<InsPredictedPl> predictInsProtectionLevels(const integrity::OrbitSource& orbits,
                                                       const InsPredictionInput& in) {
  requireValidInput(in);
  const RouteTruth truth{in, 0.5 / in.imu_rate_hz};
  integrity::ins::Navigator nav(in.config, truth.at(0.0), 0.0, 0.0);
  const EpochPlan plan = planEpochs(in);
  std::vector<InsPredictedPl> out(in.sample_t_s.size());
  double t_prev = 0.0;
  for (std::size_t e = 0; e < plan.t_s.size(); ++e) {
    flyTo(nav, truth, t_prev, plan.t_s[e], in.imu_rate_hz);
    t_prev = plan.t_s[e];
    int blocked = 0;
    const std::vector<integrity::ins::PseudorangeInput> ranges =
        errorFreeRanges(orbits, in, nav.filter(), in.departure.plus(t_prev), plan.mask_sample[e], blocked);
    const integrity::ins::InsEkf& ekf = nav.filter();
    const double baro_h_m = maps::ecefToGeodetic(ekf.nav().r_ecef_m).h_ell_m + ekf.baroBias_m();
    const integrity::ins::NavigatorEpoch ep = nav.epoch(t_prev, ranges, baro_h_m, ekf.heading_rad());
    for (std::size_t k : plan.samples_at[e]) out[k] = samplePl(ep, blocked);
  }
  return out;
}

}  // namespace skylane::planner
