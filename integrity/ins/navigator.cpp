#include "integrity/ins/navigator.hpp"

#include "integrity/araim/fde.hpp"
#include "integrity/raim/wls.hpp"
#include "integrity/stats.hpp"

#include "maps/geodesy.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace skylane::integrity::ins {

Navigator::Navigator(const NavigatorConfig& cfg, const NavState& initial, double clock_m, double drift_mps)
    : cfg_(cfg), ekf_(cfg.ekf, initial, clock_m, drift_mps), seed000_(cfg.seed000) {}

NavigatorEpoch Navigator::epoch(double t_s, const std::vector<PseudorangeInput>& ranges, std::optional<double> baro_h_m,
                                std::optional<double> heading_rad) {
  NavigatorEpoch out;
  out.t_s = t_s;
  if (cfg_.use_baro && baro_h_m) out.baro_refused = !ekf_.updateBaro(*baro_h_m);
  if (cfg_.use_heading && heading_rad) out.heading_refused = !ekf_.updateHeading(*heading_rad);
  out.visible = static_cast<int>(ranges.size());
  if (ranges.empty()) {
    out.outage = true;
    out.r_ecef_m = out.ekf_r_ecef_m = ekf_.nav().r_ecef_m;
    out.degraded = degraded_;
    return out;
  }

  // 1. LSR fault detection and exclusion on the snapshot, linearised at the INS prediction.
  const Eigen::Vector3d r_pred = ekf_.nav().r_ecef_m;
  const maps::Geodetic here = maps::ecefToGeodetic(r_pred);
  const Eigen::Matrix3d R_enu_ecef = maps::rotationEcefToEnu(here.lat_rad, here.lon_rad);
  std::vector<SatLook> looks;
  looks.reserve(ranges.size());
  Eigen::VectorXd prefit(static_cast<Eigen::Index>(ranges.size()));
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    // Look angles in the local frame at the prediction (one geodetic conversion for all).
    const Eigen::Vector3d los = R_enu_ecef * (ranges[i].sat_ecef_m - r_pred).normalized();
    looks.push_back({ranges[i].sat, {std::atan2(los.x(), los.y()), std::asin(std::clamp(los.z(), -1.0, 1.0))}});
    prefit(static_cast<Eigen::Index>(i)) = ranges[i].pseudorange_m - ekf_.predictedRange_m(ranges[i].sat_ecef_m);
  }
  const Geometry g = buildGeometry(looks, cfg_.model, cfg_.model.iono_tau_vert_m.value_or(9.0));
  const int n = g.numSats();
  RaimConfig rc;
  rc.pfa = cfg_.fault_modes.pfa_gnss;
  rc.max_exclusions = cfg_.max_exclusions;
  {
    const RiskAllocation a_h = allocateRisk(std::max(n, 1), DetectionClass::kGnssAlone, false, cfg_.fault_modes.risk);
    const RiskAllocation a_v = allocateRisk(std::max(n, 1), DetectionClass::kGnssAlone, true, cfg_.fault_modes.risk);
    rc.pmd = std::min(a_h.of(InsFaultMode::kGnssSingle).conditional, a_v.of(InsFaultMode::kGnssSingle).conditional);
    rc.phmi_hor = a_h.of(InsFaultMode::kFaultFree).budget;
    rc.phmi_vert = a_v.of(InsFaultMode::kFaultFree).budget;
  }
  const RaimFdeResult fde = raimFde(g, prefit, rc);
  out.gnss_fault_detected = fde.fault_detected;
  for (int idx : fde.excluded) out.excluded.push_back(g.sats[static_cast<std::size_t>(idx)]);
  if (fde.solution_ok) {
    out.raim.r_ecef_m = r_pred + R_enu_ecef.transpose() * fde.dx.head<3>();
    out.raim.available = fde.pl.available && !(fde.fault_detected && !fde.fault_excluded);
    out.raim.hpl_m = fde.pl.hpl_m;
    out.raim.vpl_m = fde.pl.vpl_m;
  }
  if (cfg_.compute_araim) {
    const AraimFdeResult ar = araimFde(g, prefit, cfg_.model, cfg_.araim);
    if (ar.solution_ok) {
      out.araim.available = ar.pl.pl_computed && !(ar.fault_detected && !ar.fault_excluded);
      out.araim.r_ecef_m = r_pred + R_enu_ecef.transpose() * ar.dx.head<3>();
      out.araim.hpl_m = ar.pl.hpl_m;
      out.araim.vpl_m = ar.pl.vpl_m;
    }
  }

  // 2. Fuse what the FDE kept (nothing when a fault was detected but not excluded).
  const bool unresolved = fde.fault_detected && !fde.fault_excluded;
  std::vector<RangeInput> kept;
  if (!unresolved) {
    for (int i = 0; i < n; ++i) {
      if (std::find(fde.excluded.begin(), fde.excluded.end(), i) != fde.excluded.end()) continue;
      const std::size_t k = static_cast<std::size_t>(i);
      kept.push_back({ranges[k].sat, ranges[k].sat_ecef_m, ranges[k].pseudorange_m, g.sigma_int(i), g.bnom(i)});
    }
  }
  out.used = static_cast<int>(kept.size());
  const GnssUpdateRecord rec = ekf_.updateGnss(kept);
  out.ekf_r_ecef_m = ekf_.nav().r_ecef_m;

  // 3. IMU fault test from the innovations (windowed χ²(4·N)).
  const double stat = imuInnovationStatistic(rec);
  if (stat >= 0.0) {
    imu_stats_.push_back(stat);
    while (static_cast<int>(imu_stats_.size()) > cfg_.imu_test_window) imu_stats_.pop_front();
  }
  if (!imu_stats_.empty()) {
    out.imu_statistic = std::accumulate(imu_stats_.begin(), imu_stats_.end(), 0.0);
    const int dof = 4 * static_cast<int>(imu_stats_.size());
    auto [it, fresh] = imu_thresholds_.try_emplace(dof, 0.0);
    if (fresh) it->second = chiSquareUpperQuantile(dof, cfg_.pfa_imu);
    out.imu_threshold = it->second;
    out.imu_fault_detected = out.imu_statistic > out.imu_threshold;
  }
  if (out.imu_fault_detected) {
    degraded_ = true;
    consistent_since_s_ = t_s;
  } else if (degraded_ && t_s - consistent_since_s_ >= cfg_.recover_s) {
    degraded_ = false;
  }
  out.degraded = degraded_;

  // 4. Protection levels.
  if (rec.ok) {
    out.fault_modes = faultModeProtectionLevels(rec, cfg_.fault_modes);
    out.seed000 = seed000_.push(rec, fde.pl);
  }
  if (degraded_) {
    out.r_ecef_m = out.raim.r_ecef_m;
    out.seed001_available = out.raim.available;
    out.seed001_hpl_m = out.raim.hpl_m;
    out.seed001_vpl_m = out.raim.vpl_m;
  } else {
    out.r_ecef_m = out.ekf_r_ecef_m;
    out.seed001_available = out.fault_modes.available;
    out.seed001_hpl_m = out.fault_modes.hpl_m;
    out.seed001_vpl_m = out.fault_modes.vpl_m;
  }
  return out;
}

}  // namespace skylane::integrity::ins
