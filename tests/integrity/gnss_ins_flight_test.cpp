// Whole simulated flights through the GNSS/INS navigator: the fault-mode experiments (Zhao & Song
// 2024, §4.2), fault injection, outages, reproducibility and a small Monte Carlo. The truth is
// the simulator's; every number asserted is measured against it.
#include "integrity/sim/run.hpp"

#include "tests/test_util.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace skylane::integrity::sim {
namespace {

std::string examplePath(const std::string& name) {
  return std::string(SKYLANE_TEST_DATA) + "/../../examples/simulate/" + name;
}

const OrbitSource& orbits() {
  static const OrbitSource o = loadOrbits(loadScenario(examplePath("gnss_ins_no_fault.json")));
  return o;
}

struct Flight {
  Scenario scenario;
  RunResult run;
};

Flight fly(const std::string& example, const std::vector<FaultSpec>& faults = {}, bool replace_faults = false) {
  Flight f{loadScenario(examplePath(example)), {}};
  if (replace_faults) f.scenario.faults = faults;
  f.run = runScenario(f.scenario, orbits(), f.scenario.seed);
  return f;
}

const MethodSample& of(const EpochRecord& e, Method m) { return e.methods[static_cast<int>(m)]; }

/// Every epoch with a PL: error ≤ PL, horizontally and vertically.
void expectBounded(const RunResult& run, Method m) {
  int with_pl = 0;
  for (const EpochRecord& e : run.epochs) {
    const MethodSample& s = of(e, m);
    if (!s.available) continue;
    ++with_pl;
    EXPECT_LE(s.hpe_m, s.hpl_m) << methodName(m) << " at t = " << e.t_s;
    EXPECT_LE(s.vpe_m, s.vpl_m) << methodName(m) << " at t = " << e.t_s;
  }
  EXPECT_GT(with_pl, 0) << methodName(m);
}

double meanAbsUp(const RunResult& run, double t0, double t1) {
  double sum = 0;
  int n = 0;
  for (const EpochRecord& e : run.epochs) {
    if (e.t_s < t0 || e.t_s >= t1) continue;
    sum += std::abs(e.error_enu_m.z());
    ++n;
  }
  return n ? sum / n : NAN;
}

// Zhao & Song 2024 Fig. 6: the survey flight without faults; every method's PL bounds the error.
TEST(GnssInsFlight, NoFaultSurveyIsBoundedByEveryMethod) {
  const Flight f = fly("gnss_ins_no_fault.json");
  EXPECT_GE(f.run.duration_s, 750.0);  // Zhao & Song's 750 s survey
  ASSERT_GE(f.run.epochs.size(), 740u);
  for (int m = 0; m < kNumMethods; ++m) expectBounded(f.run, static_cast<Method>(m));
  // Accuracy of the filter: dual-frequency pseudoranges, consumer IMU, baro and heading aiding.
  double h2 = 0, v2 = 0;
  for (const EpochRecord& e : f.run.epochs) {
    h2 += e.error_enu_m.head<2>().squaredNorm();
    v2 += e.error_enu_m.z() * e.error_enu_m.z();
  }
  const double n = static_cast<double>(f.run.epochs.size());
  EXPECT_LT(std::sqrt(h2 / n), 1.5);
  EXPECT_LT(std::sqrt(v2 / n), 1.5);
  for (const EpochRecord& e : f.run.epochs) {
    EXPECT_FALSE(e.imu_fault_detected) << "false IMU alert at t = " << e.t_s;
    EXPECT_FALSE(e.degraded);
  }
}

// Zhao & Song 2024 Fig. 7: 20×10⁻⁴ g on the vertical accelerometer, 200–250 s. The paper's detector
// does not see it; the vertical error grows while it acts and the PL still bounds it.
TEST(GnssInsFlight, VerticalAccelerometerFaultRaisesTheErrorAndStaysBounded) {
  const Flight clean = fly("gnss_ins_no_fault.json");
  const Flight faulty = fly("gnss_ins_accel_fault.json");
  ASSERT_EQ(faulty.scenario.faults.size(), 1u);
  EXPECT_NEAR(faulty.scenario.faults[0].magnitude, 20e-4 * 9.80665, 1e-12);
  EXPECT_GT(meanAbsUp(faulty.run, 205, 250), meanAbsUp(clean.run, 205, 250) + 0.15);
  EXPECT_NEAR(meanAbsUp(faulty.run, 100, 190), meanAbsUp(clean.run, 100, 190), 1e-9);  // same draws before
  expectBounded(faulty.run, Method::kFaultMode);
  expectBounded(faulty.run, Method::kThreeHypothesisIns);
  for (const EpochRecord& e : faulty.run.epochs) EXPECT_FALSE(e.imu_fault_detected) << e.t_s;
}

// Zhao & Song 2024 Fig. 9: 20σ₀ on G19, 200–250 s: the LSR test detects and excludes it at every
// epoch, so the fault never reaches the filter.
TEST(GnssInsFlight, TwentySigmaSatelliteFaultIsExcludedBeforeFusion) {
  const Flight f = fly("gnss_ins_sat_20sigma.json");
  const SatId g19{Constellation::kGps, 19};
  int fault_epochs = 0, excluded = 0, false_exclusions = 0;
  for (const EpochRecord& e : f.run.epochs) {
    const bool has = std::find(e.excluded.begin(), e.excluded.end(), g19) != e.excluded.end();
    if (e.satellite_fault_active) {
      ++fault_epochs;
      excluded += has ? 1 : 0;
      EXPECT_LT(e.error_enu_m.norm(), 3.0) << e.t_s;
    } else if (!e.excluded.empty()) {
      ++false_exclusions;
    }
  }
  EXPECT_EQ(fault_epochs, 50);
  EXPECT_EQ(excluded, fault_epochs);
  EXPECT_LE(false_exclusions, 2);
  expectBounded(f.run, Method::kFaultMode);
  expectBounded(f.run, Method::kRaim);
}

// Zhao & Song 2024 Fig. 12: accelerometer 200–250 s, G19 10σ₀ 500–550 s; the final PL bounds both.
TEST(GnssInsFlight, CombinedFaultsAreBoundedByTheFinalProtectionLevel) {
  const Flight f = fly("gnss_ins_combined.json");
  int sat = 0, imu = 0;
  for (const EpochRecord& e : f.run.epochs) {
    sat += e.satellite_fault_active ? 1 : 0;
    imu += e.imu_fault_active ? 1 : 0;
  }
  EXPECT_EQ(sat, 50);
  EXPECT_EQ(imu, 50);
  for (int m = 0; m < kNumMethods; ++m) expectBounded(f.run, static_cast<Method>(m));
}

// A gyro fault far above the IMU's figures: the innovation test flags it, the system degrades
// to GNSS alone (RAIM position and PLs) and comes back once the innovations are consistent.
TEST(GnssInsFlight, LargeGyroFaultIsDetectedAndTheSystemDegradesToGnss) {
  FaultSpec gyro;
  gyro.target = FaultTarget::kGyro;
  gyro.axis = 2;
  gyro.t_start_s = 200;
  gyro.t_end_s = 260;
  gyro.magnitude = 0.05;  // rad/s, 100× the consumer bias σ
  const Flight f = fly("gnss_ins_no_fault.json", {gyro}, true);
  double first_detection = -1, last_degraded = -1;
  for (const EpochRecord& e : f.run.epochs) {
    if (e.imu_fault_detected && first_detection < 0) first_detection = e.t_s;
    if (e.degraded) {
      last_degraded = e.t_s;
      const MethodSample& s = of(e, Method::kFaultMode);
      const MethodSample& r = of(e, Method::kRaim);
      EXPECT_EQ(s.hpl_m, r.hpl_m);
      EXPECT_EQ(s.hpe_m, r.hpe_m);
    }
  }
  EXPECT_GE(first_detection, 200.0);
  EXPECT_LE(first_detection, 215.0);
  // Held while the innovations stay inconsistent (a 3 rad heading error takes the filter minutes
  // to re-converge), then `recover_s` more; back to the integrated solution before the end.
  EXPECT_GT(last_degraded, 260.0);
  EXPECT_FALSE(f.run.epochs.back().degraded);
  expectBounded(f.run, Method::kFaultMode);
}

// Dead reckoning (docs/method.md §5.1; Electronics and Control Systems 2012) through a GNSS outage; no integrity is claimed there.
TEST(GnssInsFlight, OutageIsBridgedByDeadReckoningAndReportedUnavailable) {
  FaultSpec outage;
  outage.target = FaultTarget::kGnssOutage;
  outage.t_start_s = 300;
  outage.t_end_s = 330;
  outage.magnitude = 1;
  const Flight f = fly("gnss_ins_no_fault.json", {outage}, true);
  int outage_epochs = 0;
  double error_at_end = 0;
  for (const EpochRecord& e : f.run.epochs) {
    if (e.t_s >= 300 && e.t_s < 330) {
      ++outage_epochs;
      EXPECT_TRUE(e.outage);
      EXPECT_EQ(e.visible, 0);
      EXPECT_FALSE(of(e, Method::kFaultMode).available);
      error_at_end = e.error_enu_m.norm();
    }
    if (e.t_s >= 360) {
      EXPECT_LT(e.error_enu_m.norm(), 3.0) << e.t_s;
    }
  }
  EXPECT_EQ(outage_epochs, 30);
  EXPECT_LT(error_at_end, 50.0);  // 30 s of consumer-grade dead reckoning with baro and heading
  expectBounded(f.run, Method::kFaultMode);
}

TEST(GnssInsFlight, SameSeedSameFlightOtherSeedOtherNoise) {
  const Scenario s = loadScenario(examplePath("gnss_ins_sat_10sigma.json"));
  const RunResult a = runScenario(s, orbits(), 7);
  const RunResult b = runScenario(s, orbits(), 7);
  const RunResult c = runScenario(s, orbits(), 8);
  std::ostringstream csv_a, csv_b, csv_c;
  writeCsv(csv_a, a);
  writeCsv(csv_b, b);
  writeCsv(csv_c, c);
  const std::string text_a = csv_a.str();
  EXPECT_EQ(text_a, csv_b.str());
  EXPECT_NE(text_a, csv_c.str());
  EXPECT_EQ(std::count(text_a.begin(), text_a.end(), '\n'), static_cast<long>(a.epochs.size()) + 1);
}

// A small Monte Carlo (the full ≥ 10⁶-epoch run is `skylane simulate --monte-carlo`, see the
// README): random geometry, flight and injected faults; the fault-mode PL is never exceeded.
TEST(GnssInsFlight, MonteCarloBatchHasNoMisleadingFaultModeEpoch) {
  const Scenario base = loadScenario(examplePath("gnss_ins_no_fault.json"));
  std::uint64_t last = 0;
  const MonteCarloResult r = monteCarlo(base, orbits(), 24, 2, [&last](std::uint64_t d, std::uint64_t) { last = std::max(last, d); });
  EXPECT_EQ(r.runs, 24u);
  EXPECT_EQ(last, 24u);
  EXPECT_GT(r.epochs, 5000u);
  EXPECT_GT(r.faulted_epochs, 500u);
  const MethodStats& s = r.methods[static_cast<int>(Method::kFaultMode)];
  EXPECT_EQ(s.horizontal.misleading, 0u);
  EXPECT_EQ(s.vertical.misleading, 0u);
  for (const MethodStats& m : r.methods) {
    EXPECT_EQ(m.horizontal.hmi, 0u);
    EXPECT_EQ(m.vertical.hmi, 0u);
    EXPECT_EQ(m.horizontal.total, r.epochs);
  }
  // Same batch again: the variants are a function of the run index alone (threads do not matter).
  const MonteCarloResult again = monteCarlo(base, orbits(), 24, 1, {});
  EXPECT_EQ(again.epochs, r.epochs);
  EXPECT_EQ(again.methods[0].horizontal.counts, s.horizontal.counts);
}

}  // namespace
}  // namespace skylane::integrity::sim
