#pragma once
/// \file
/// \brief Runs simulated flights through the integrated navigator and scores every integrity
/// method against the truth: per-epoch records (CSV), Stanford-diagram histograms and the
/// Monte Carlo batch with fault injection.

#include "integrity/gnss/orbit_source.hpp"
#include "integrity/sim/scenario.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <ostream>
#include <string_view>
#include <vector>

namespace skylane::integrity::sim {

/// \brief The methods compared.
enum class Method {
  kFaultMode,  ///< fault-mode PLs (Zhao & Song 2024) on the system output (filter, or GNSS alone when degraded)
  kThreeHypothesisIns,  ///< three-hypothesis INS PL (US 10,466,362) on the filter position (GNSS alone with RAIM when degraded)
  kRaim,     ///< snapshot RAIM after FDE on its own position
  kAraim,    ///< snapshot ARAIM (MHSS) after solution-separation FDE on its own position
};
inline constexpr int kNumMethods = 4;
/// \brief "fault_mode", "three_hypothesis_ins", "raim", "araim".
[[nodiscard]] std::string_view methodName(Method m);

/// \brief One method at one epoch.
struct MethodSample {
  bool available = false;  ///< a protection level was computed
  double hpe_m = 0.0, vpe_m = 0.0;  ///< |horizontal error|, |vertical error|
  double hpl_m = 0.0, vpl_m = 0.0;
};

/// \brief One GNSS epoch of a simulated flight.
struct EpochRecord {
  double t_s = 0.0;
  Eigen::Vector3d truth_enu_m = Eigen::Vector3d::Zero();   ///< in the origin's frame
  Eigen::Vector3d estimate_enu_m = Eigen::Vector3d::Zero();  ///< the system output
  Eigen::Vector3d error_enu_m = Eigen::Vector3d::Zero();   ///< estimate − truth, local ENU at the truth
  std::array<MethodSample, kNumMethods> methods{};
  std::array<double, 4> mode_hpl_m{}, mode_vpl_m{};  ///< fault-mode FF, GS, I, GSI
  bool outage = false;
  int visible = 0, used = 0;
  std::vector<SatId> excluded;
  bool gnss_fault_detected = false;
  double imu_statistic = 0.0, imu_threshold = 0.0;
  bool imu_fault_detected = false;
  bool degraded = false;
  bool satellite_fault_active = false;
  bool imu_fault_active = false;
};

/// \brief One simulated flight.
struct RunResult {
  std::vector<EpochRecord> epochs;
  double duration_s = 0.0;
  long imu_steps = 0;
};

/// \brief The scenario's orbit files loaded (almanacs by content, RINEX navigation by name).
/// \throws maps::ParseError naming the scenario's field and the file.
[[nodiscard]] OrbitSource loadOrbits(const Scenario& s);

/// \brief Flies the scenario once with the given seed.
[[nodiscard]] RunResult runScenario(const Scenario& s, const OrbitSource& orbits, std::uint64_t seed);

/// \brief Writes one CSV row per epoch (header first).
void writeCsv(std::ostream& os, const RunResult& run);

/// \brief A Stanford diagram: a 2-D histogram of (error, PL) with the region counts.
/// Regions (RTCA DO-229 / Stanford WAAS): normal (error ≤ PL ≤ AL), MI (PL < error ≤ AL, PL ≤ AL),
/// HMI (error > AL ≥ PL), unavailable (PL > AL; "unavailable MI" when also error > PL).
struct StanfordHistogram {
  double alert_limit_m = 0.0;
  double max_m = 0.0;   ///< both axes run 0…max_m
  int bins = 0;
  std::vector<std::uint64_t> counts;  ///< bins × bins, row = PL bin, column = error bin
  std::uint64_t total = 0, normal = 0, mi = 0, hmi = 0, unavailable = 0, unavailable_mi = 0, no_pl = 0;
  std::uint64_t misleading = 0;  ///< error > PL, whatever the region (the "misleading" count of docs/method.md §5.6)

  StanfordHistogram() = default;
  StanfordHistogram(double alert_limit, double max, int num_bins);
  /// \brief Adds one epoch (`available` false: no PL could be formed — counted in no_pl).
  void add(double error_m, double pl_m, bool available);
  /// \brief Adds another histogram of the same shape.
  void merge(const StanfordHistogram& o);
};

/// \brief Horizontal and vertical Stanford histograms per method.
struct MethodStats {
  StanfordHistogram horizontal, vertical;
};

/// \brief The Monte Carlo outcome.
struct MonteCarloResult {
  std::array<MethodStats, kNumMethods> methods{};
  std::uint64_t runs = 0;
  std::uint64_t epochs = 0;
  std::uint64_t faulted_epochs = 0;  ///< epochs with an injected fault active
};

/// \brief Scores one run into the histograms.
void accumulate(const RunResult& run, MonteCarloResult& into);
/// \brief Empty histograms sized for the scenario's alert limits.
[[nodiscard]] MonteCarloResult emptyMonteCarlo(const Scenario& s);

/// \brief The random variations of one Monte Carlo run: start time (geometry), heading and
/// pattern of the flight, and an injected fault drawn around the detection thresholds (file
/// comment of run.cpp). Deterministic in `run_index` and the scenario's seed.
[[nodiscard]] Scenario monteCarloVariant(const Scenario& base, std::uint64_t run_index);

/// \brief Runs `runs` variants on `threads` threads; `progress(done, total)` after every run.
[[nodiscard]] MonteCarloResult monteCarlo(const Scenario& base, const OrbitSource& orbits, std::uint64_t runs,
                                          int threads, const std::function<void(std::uint64_t, std::uint64_t)>& progress);

/// \brief One-sided 95 % upper bound on a rate with k events in n trials (Clopper–Pearson;
/// 3/n for k = 0, the "rule of three").
[[nodiscard]] double upperBound95(std::uint64_t k, std::uint64_t n);

}  // namespace skylane::integrity::sim
