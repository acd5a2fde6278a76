#include "integrity/ins/navigator.hpp"

#include "integrity/araim/fde.hpp"
#include "integrity/raim/wls.hpp"
#include "integrity/stats.hpp"

#include "maps/geodesy.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace skylane::integrity::ins {

namespace {

/// \brief Step 1's linearisation point: the INS prediction, the local frame there, the
/// snapshot geometry seen from it and the pre-fit residuals against the filter's ranges.
struct Snapshot {
  Eigen::Vector3d r_pred;
  Eigen::Matrix3d R_enu_ecef;
  Geometry g;
  Eigen::VectorXd prefit;
};

/// \brief The epoch's snapshot, linearised at the filter's predicted position.
Snapshot linearisedSnapshot(const std::vector<PseudorangeInput>& ranges, const InsEkf& ekf, const ErrorModel& model) {
  Snapshot s;
  s.r_pred = ekf.nav().r_ecef_m;
  const maps::Geodetic here = maps::ecefToGeodetic(s.r_pred);
  s.R_enu_ecef = maps::rotationEcefToEnu(here.lat_rad, here.lon_rad);
  std::vector<SatLook> looks;
  looks.reserve(ranges.size());
  s.prefit.resize(static_cast<Eigen::Index>(ranges.size()));
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    // Look angles in the local frame at the prediction (one geodetic conversion for all).
    const Eigen::Vector3d los = s.R_enu_ecef * (ranges[i].sat_ecef_m - s.r_pred).normalized();
    looks.push_back({ranges[i].sat, {std::atan2(los.x(), los.y()), std::asin(std::clamp(los.z(), -1.0, 1.0))}});
    s.prefit(static_cast<Eigen::Index>(i)) = ranges[i].pseudorange_m - ekf.predictedRange_m(ranges[i].sat_ecef_m);
  }
  s.g = buildGeometry(looks, model, model.iono_tau_vert_m.value_or(9.0));
  return s;
}

/// \brief Step 1's RAIM settings for `n` satellites: the GNSS false-alert probability and the
/// class-1 (GNSS-alone) allocation of the fault-mode integrity risk.
RaimConfig gnssAloneRaimConfig(int n, const NavigatorConfig& cfg) {
  RaimConfig rc;
  rc.pfa = cfg.fault_modes.pfa_gnss;
  rc.max_exclusions = cfg.max_exclusions;
  // The plain PL after an exclusion: this step's risk is allocated by the fault-mode tree of
  // docs/method.md §5.3 (Zhao & Song 2024), whose GNSS single-fault class carries P_md; the
  // split over FDE outcomes of §3.2a is not part of that tree (its PL feeds the
  // three-hypothesis INS PL of §5.5).
  rc.exclusion_pl = ExclusionPl::kRemainingGeometry;
  const RiskAllocation a_h = allocateRisk(std::max(n, 1), DetectionClass::kGnssAlone, false, cfg.fault_modes.risk);
  const RiskAllocation a_v = allocateRisk(std::max(n, 1), DetectionClass::kGnssAlone, true, cfg.fault_modes.risk);
  rc.pmd = std::min(a_h.of(InsFaultMode::kGnssSingle).conditional, a_v.of(InsFaultMode::kGnssSingle).conditional);
  rc.phmi_hor = a_h.of(InsFaultMode::kFaultFree).budget;
  rc.phmi_vert = a_v.of(InsFaultMode::kFaultFree).budget;
  return rc;
}

/// \brief Step 1: LSR fault detection and exclusion on the snapshot; the detection, the
/// excluded satellites and the snapshot RAIM solution go to `out`.
RaimFdeResult snapshotRaimFde(const Snapshot& s, const NavigatorConfig& cfg, NavigatorEpoch& out) {
  RaimFdeResult fde = raimFde(s.g, s.prefit, gnssAloneRaimConfig(s.g.numSats(), cfg));
  out.gnss_fault_detected = fde.fault_detected;
  for (int idx : fde.excluded) out.excluded.push_back(s.g.sats[static_cast<std::size_t>(idx)]);
  if (fde.solution_ok) {
    out.raim.r_ecef_m = s.r_pred + s.R_enu_ecef.transpose() * fde.dx.head<3>();
    out.raim.available = fde.pl.available && !(fde.fault_detected && !fde.fault_excluded);
    out.raim.hpl_m = fde.pl.hpl_m;
    out.raim.vpl_m = fde.pl.vpl_m;
  }
  return fde;
}

/// \brief The snapshot ARAIM solution beside step 1 (solution-separation FDE), into `out`.
void snapshotAraimFde(const Snapshot& s, const NavigatorConfig& cfg, NavigatorEpoch& out) {
  const AraimFdeResult ar = araimFde(s.g, s.prefit, cfg.model, cfg.araim);
  if (ar.solution_ok) {
    out.araim.available = ar.pl.pl_computed && !(ar.fault_detected && !ar.fault_excluded);
    out.araim.r_ecef_m = s.r_pred + s.R_enu_ecef.transpose() * ar.dx.head<3>();
    out.araim.hpl_m = ar.pl.hpl_m;
    out.araim.vpl_m = ar.pl.vpl_m;
  }
}

/// \brief Step 2's input: the ranges the FDE kept (none when a fault was detected but not
/// excluded), with their integrity σ and nominal bias.
std::vector<RangeInput> keptRanges(const std::vector<PseudorangeInput>& ranges, const Geometry& g,
                                   const RaimFdeResult& fde) {
  const bool unresolved = fde.fault_detected && !fde.fault_excluded;
  std::vector<RangeInput> kept;
  if (!unresolved) {
    for (int i = 0; i < g.numSats(); ++i) {
      if (std::find(fde.excluded.begin(), fde.excluded.end(), i) != fde.excluded.end()) continue;
      const std::size_t k = static_cast<std::size_t>(i);
      kept.push_back({ranges[k].sat, ranges[k].sat_ecef_m, ranges[k].pseudorange_m, g.sigma_int(i), g.bnom(i)});
    }
  }
  return kept;
}

/// \brief Step 3: the IMU fault test, a χ²(4·N) over the last `imu_test_window` innovation
/// statistics (`window`); thresholds are kept by degrees of freedom in `thresholds`.
void imuInnovationTest(const GnssUpdateRecord& rec, const NavigatorConfig& cfg, std::deque<double>& window,
                       std::map<int, double>& thresholds, NavigatorEpoch& out) {
  const double stat = imuInnovationStatistic(rec);
  if (stat >= 0.0) {
    window.push_back(stat);
    while (static_cast<int>(window.size()) > cfg.imu_test_window) window.pop_front();
  }
  if (!window.empty()) {
    out.imu_statistic = std::accumulate(window.begin(), window.end(), 0.0);
    const int dof = 4 * static_cast<int>(window.size());
    auto [it, fresh] = thresholds.try_emplace(dof, 0.0);
    if (fresh) it->second = chiSquareUpperQuantile(dof, cfg.pfa_imu);
    out.imu_threshold = it->second;
    out.imu_fault_detected = out.imu_statistic > out.imu_threshold;
  }
}

/// \brief An IMU fault enters the GNSS-alone mode; it is left after `recover_s` without one.
void updateGnssAloneMode(bool imu_fault_detected, double t_s, double recover_s, bool& degraded,
                         double& consistent_since_s) {
  if (imu_fault_detected) {
    degraded = true;
    consistent_since_s = t_s;
  } else if (degraded && t_s - consistent_since_s >= recover_s) {
    degraded = false;
  }
}

/// \brief Step 4's output: the filter and the fault-mode PLs, or, in the GNSS-alone mode, the
/// snapshot RAIM solution and its PLs.
void selectSystemOutput(bool degraded, NavigatorEpoch& out) {
  if (degraded) {
    out.r_ecef_m = out.raim.r_ecef_m;
    out.fault_mode_available = out.raim.available;
    out.fault_mode_hpl_m = out.raim.hpl_m;
    out.fault_mode_vpl_m = out.raim.vpl_m;
  } else {
    out.r_ecef_m = out.ekf_r_ecef_m;
    out.fault_mode_available = out.fault_modes.available;
    out.fault_mode_hpl_m = out.fault_modes.hpl_m;
    out.fault_mode_vpl_m = out.fault_modes.vpl_m;
  }
}

}  // namespace

Navigator::Navigator(const NavigatorConfig& cfg, const NavState& initial, double clock_m, double drift_mps)
    : cfg_(cfg), ekf_(cfg.ekf, initial, clock_m, drift_mps), three_hypothesis_ins_(cfg.three_hypothesis_ins) {}

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
  const Snapshot snapshot = linearisedSnapshot(ranges, ekf_, cfg_.model);
  const RaimFdeResult fde = snapshotRaimFde(snapshot, cfg_, out);
  if (cfg_.compute_araim) snapshotAraimFde(snapshot, cfg_, out);
  // 2. Fuse what the FDE kept.
  const std::vector<RangeInput> kept = keptRanges(ranges, snapshot.g, fde);
  out.used = static_cast<int>(kept.size());
  const GnssUpdateRecord rec = ekf_.updateGnss(kept);
  out.ekf_r_ecef_m = ekf_.nav().r_ecef_m;
  // 3. IMU fault test from the innovations.
  imuInnovationTest(rec, cfg_, imu_stats_, imu_thresholds_, out);
  updateGnssAloneMode(out.imu_fault_detected, t_s, cfg_.recover_s, degraded_, consistent_since_s_);
  out.degraded = degraded_;
  // 4. Protection levels.
  if (rec.ok) {
    out.fault_modes = faultModeProtectionLevels(rec, cfg_.fault_modes);
    out.three_hypothesis_ins = three_hypothesis_ins_.push(rec, fde.pl);
  }
  selectSystemOutput(degraded_, out);
  return out;
}

}  // namespace skylane::integrity::ins
