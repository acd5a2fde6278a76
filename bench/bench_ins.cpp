// GNSS/INS: one navigator epoch and a whole simulated survey. Targets (issue 5): one EKF epoch
// with 20 satellites including all protection levels ≤ 50 µs; a 750 s scenario at 100 Hz IMU /
// 1 Hz GNSS simulated ≥ 1,000× faster than real time.
#include "integrity/gnss/almanac.hpp"
#include "integrity/ins/navigator.hpp"
#include "integrity/sim/run.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace {

using namespace skylane::integrity;

/// Twenty GPS + Galileo satellites over Zurich from the ED-259 almanacs, ranges from the truth.
struct EpochSetup {
  ins::NavState truth;
  std::vector<ins::PseudorangeInput> ranges;
};

EpochSetup twentySatellites() {
  OrbitSource orbits;
  orbits.addAlmanac(loadAlmanac(std::string(SKYLANE_TEST_DATA) + "/gnss/alm_gps_ed259.txt"));
  orbits.addAlmanac(loadAlmanac(std::string(SKYLANE_TEST_DATA) + "/gnss/alm_gal_ed259.txt"));
  EpochSetup s;
  s.truth.r_ecef_m = skylane::maps::geodeticToEcef({0.8269, 0.1491, 520.0});
  // The first instant of the almanacs' day with at least 20 satellites above 5°.
  std::vector<VisibleSatellite> vis;
  for (double sow = 0.0; sow < 86400.0 && vis.size() < 20; sow += 600.0) {
    vis = orbits.visible(s.truth.r_ecef_m, GpsTime{1930, sow}, 5.0 * M_PI / 180.0);
  }
  if (vis.size() < 20) throw std::runtime_error("fewer than 20 satellites in view for the benchmark");
  vis.resize(20);
  for (const VisibleSatellite& v : vis) s.ranges.push_back({v.sat, v.p_ecef, v.range_m + 30.0});
  return s;
}

void BM_NavigatorEpoch20Sats(benchmark::State& state) {
  const EpochSetup s = twentySatellites();
  ins::NavigatorConfig cfg;
  cfg.compute_araim = state.range(0) != 0;
  ins::Navigator nav(cfg, s.truth, 30.0, 0.0);
  for (auto _ : state) {
    nav.propagate(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81), 1e-3);  // keeps P from collapsing
    benchmark::DoNotOptimize(nav.epoch(0.0, s.ranges, 520.0, 0.0));
  }
  state.SetLabel(cfg.compute_araim ? "with snapshot RAIM + ARAIM FDE" : "filter, FDE, fault-mode + three-hypothesis INS PLs, RAIM");
}
BENCHMARK(BM_NavigatorEpoch20Sats)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly(true);

/// Zhao & Song's 750 s survey (the bundled example): simulation + navigation + every method.
void BM_SimulateSurvey(benchmark::State& state) {
  const sim::Scenario sc =
      sim::loadScenario(std::string(SKYLANE_TEST_DATA) + "/../../examples/simulate/gnss_ins_combined.json");
  const OrbitSource orbits = sim::loadOrbits(sc);
  double flown = 0, spent = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const sim::RunResult r = sim::runScenario(sc, orbits, sc.seed);
    spent += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    flown += r.duration_s;
    benchmark::DoNotOptimize(r.epochs.data());
  }
  state.counters["x_real_time"] = flown / spent;
}
BENCHMARK(BM_SimulateSurvey)->Unit(benchmark::kMillisecond)->Iterations(5)->Repetitions(3)->ReportAggregatesOnly(true);

}  // namespace
