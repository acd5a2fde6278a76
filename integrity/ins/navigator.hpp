#pragma once
/// \file
/// \brief The fault-mode integrity monitoring flow around the GNSS/INS filter (docs/method.md §5.2; Zhao & Song 2024,
/// §1.1, Fig. 1), with the three-hypothesis INS PL (US 10,466,362) and snapshot RAIM/ARAIM beside it:
/// 1. before fusion, LSR fault detection and w-test exclusion on the epoch's pseudoranges;
/// 2. the kept pseudoranges update the filter; the innovations test the IMU (a windowed χ² of the
///    position/clock bias they reveal, see imuInnovationStatistic);
/// 3. no IMU fault: the fault-mode protection levels (class 2); IMU fault: the system degrades
///    to GNSS alone — snapshot position and RAIM protection levels with the class-1 allocation —
///    until the innovations have been consistent for `recover_s`;
/// 4. the caller compares the protection levels with the alert limits.
/// GNSS outages: the filter dead-reckons (prediction only); no integrity is claimed for those
/// epochs (no innovations to test the IMU with), and they are reported unavailable.

#include "integrity/araim/mhss.hpp"
#include "integrity/gnss/error_model.hpp"
#include "integrity/ins/ekf.hpp"
#include "integrity/ins/protection_levels.hpp"
#include "integrity/raim/raim.hpp"

#include <Eigen/Core>

#include <deque>
#include <map>
#include <optional>
#include <vector>

namespace skylane::integrity::ins {

/// \brief Settings of the whole flow.
struct NavigatorConfig {
  EkfConfig ekf;
  ErrorModel model;
  double elevation_mask_rad = 5.0 * M_PI / 180.0;
  FaultModeConfig fault_modes;
  ThreeHypothesisInsConfig three_hypothesis_ins;
  AraimConfig araim;
  int max_exclusions = 1;
  int imu_test_window = 10;    ///< epochs summed in the IMU innovation test
  double pfa_imu = 1e-5;       ///< false-alert probability of that test
  double recover_s = 30.0;     ///< consistent time before leaving the GNSS-alone mode
  bool use_baro = true;
  bool use_heading = true;
  bool compute_araim = true;   ///< snapshot ARAIM beside (the slowest part of an epoch)
};

/// \brief One pseudorange handed to the navigator.
struct PseudorangeInput {
  SatId sat;
  Eigen::Vector3d sat_ecef_m = Eigen::Vector3d::Zero();
  double pseudorange_m = 0.0;
};

/// \brief A snapshot solution with its protection levels.
struct SnapshotSolution {
  bool available = false;
  Eigen::Vector3d r_ecef_m = Eigen::Vector3d::Zero();
  double hpl_m = 0.0, vpl_m = 0.0;
};

/// \brief What the navigator did at one GNSS epoch.
struct NavigatorEpoch {
  double t_s = 0.0;
  bool outage = false;
  bool baro_refused = false, heading_refused = false;  ///< aiding refused by the innovation gate
  int visible = 0;
  int used = 0;
  std::vector<SatId> excluded;
  bool gnss_fault_detected = false;
  double imu_statistic = 0.0;  ///< windowed χ² of the IMU innovation test
  double imu_threshold = 0.0;
  bool imu_fault_detected = false;
  bool degraded = false;       ///< GNSS alone (fault-mode class 1, docs/method.md §5.3)
  /// \brief The system's output: the filter (or the snapshot when degraded) and its fault-mode PLs.
  Eigen::Vector3d r_ecef_m = Eigen::Vector3d::Zero();
  bool fault_mode_available = false;
  double fault_mode_hpl_m = 0.0, fault_mode_vpl_m = 0.0;
  FaultModePls fault_modes;    ///< class-2 details (also computed while degraded)
  Eigen::Vector3d ekf_r_ecef_m = Eigen::Vector3d::Zero();
  ThreeHypothesisInsPl three_hypothesis_ins;           ///< bounds the filter position
  SnapshotSolution raim;       ///< after FDE
  SnapshotSolution araim;      ///< after ARAIM solution-separation FDE
};

/// \brief The integrated navigator.
class Navigator {
 public:
  Navigator(const NavigatorConfig& cfg, const NavState& initial, double clock_m, double drift_mps);

  /// \brief One IMU interval.
  void propagate(const Eigen::Vector3d& dtheta_rad, const Eigen::Vector3d& dv_mps, double dt_s) {
    ekf_.propagate(dtheta_rad, dv_mps, dt_s);
  }
  /// \brief One GNSS epoch (empty `ranges` = outage), with optional baro height and heading.
  NavigatorEpoch epoch(double t_s, const std::vector<PseudorangeInput>& ranges, std::optional<double> baro_h_m,
                       std::optional<double> heading_rad);

  [[nodiscard]] const InsEkf& filter() const { return ekf_; }
  [[nodiscard]] const NavigatorConfig& config() const { return cfg_; }
  /// \brief How many satellites step 1 may exclude from the next epochs on (a deeper FDE rerun).
  void setMaxExclusions(int n) { cfg_.max_exclusions = n; }
  /// \brief Whether the flow is in the fault-mode flow's GNSS-alone mode after an IMU fault.
  [[nodiscard]] bool degraded() const { return degraded_; }

 private:
  NavigatorConfig cfg_;
  InsEkf ekf_;
  ThreeHypothesisInsMonitor three_hypothesis_ins_;
  std::deque<double> imu_stats_;
  std::map<int, double> imu_thresholds_;  ///< χ² thresholds by degrees of freedom
  bool degraded_ = false;
  double consistent_since_s_ = 0.0;
};

}  // namespace skylane::integrity::ins
