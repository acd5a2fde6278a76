// RAIM protection levels for one epoch. Target (issue 2): ≤ 5 µs median for 12 satellites.
#include "integrity/raim/raim.hpp"

#include <benchmark/benchmark.h>

#include <cmath>

namespace {

using namespace skylane::integrity;

std::vector<SatLook> sky(int n) {
  std::vector<SatLook> out;
  for (int i = 0; i < n; ++i) {
    const double el = 10.0 + 75.0 * ((i * 37) % n) / n;
    out.push_back({{i % 3 == 2 ? Constellation::kGalileo : Constellation::kGps, i + 1},
                   {2 * M_PI * i / n, el * M_PI / 180}});
  }
  return out;
}

/// Geometry from look angles to HPL/VPL, as `skylane integrity pl` and prediction do per epoch.
void BM_RaimPlFromLookAngles(benchmark::State& state) {
  const auto looks = sky(static_cast<int>(state.range(0)));
  const ErrorModel model;
  const RaimConfig cfg;
  (void)raimProtectionLevels(buildGeometry(looks, model, 9.0), cfg);  // warm the threshold cache
  for (auto _ : state) {
    const Geometry g = buildGeometry(looks, model, 9.0);
    benchmark::DoNotOptimize(raimProtectionLevels(g, cfg));
  }
}
BENCHMARK(BM_RaimPlFromLookAngles)->Arg(8)->Arg(12)->Arg(20)->Repetitions(5)->ReportAggregatesOnly(true);

/// The PL alone on a prepared geometry.
void BM_RaimPlOnGeometry(benchmark::State& state) {
  const Geometry g = buildGeometry(sky(static_cast<int>(state.range(0))), ErrorModel{}, 9.0);
  const RaimConfig cfg;
  (void)raimProtectionLevels(g, cfg);
  for (auto _ : state) benchmark::DoNotOptimize(raimProtectionLevels(g, cfg));
}
BENCHMARK(BM_RaimPlOnGeometry)->Arg(12)->Repetitions(5)->ReportAggregatesOnly(true);

/// Detection + exclusion on measurements with a 50 m fault.
void BM_RaimFdeWithFault(benchmark::State& state) {
  const Geometry g = buildGeometry(sky(12), ErrorModel{}, 9.0);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(12);
  y[3] = 50.0;
  const RaimConfig cfg;
  (void)raimFde(g, y, cfg);
  for (auto _ : state) benchmark::DoNotOptimize(raimFde(g, y, cfg));
}
BENCHMARK(BM_RaimFdeWithFault)->Repetitions(5)->ReportAggregatesOnly(true);

}  // namespace

// ARAIM MHSS for one epoch, GPS + Galileo from the shared ED-259 almanacs (~18–22 satellites).
// Target (issue 3): ≤ 50 µs median on one core.
#include "integrity/araim/exclusion.hpp"
#include "integrity/araim/mhss.hpp"
#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/orbit_source.hpp"

namespace {

/// Skies with 18 … 22 satellites above 5° over a grid of places and a day (the ARAIM benchmark case of the README).
std::vector<Geometry> almanacSkies() {
  OrbitSource orbits;
  orbits.addAlmanac(loadAlmanac(SKYLANE_TEST_DATA "/gnss/alm_gps_ed259.txt"));
  orbits.addAlmanac(loadAlmanac(SKYLANE_TEST_DATA "/gnss/alm_gal_ed259.txt"));
  std::vector<Geometry> out;
  for (double lat = -60; lat <= 60; lat += 30) {
    const Eigen::Vector3d site = skylane::maps::geodeticToEcef({lat * M_PI / 180, 0.2, 0.0});
    for (double t = 0; t < 86400; t += 1800) {
      std::vector<SatLook> looks;
      for (const auto& v : orbits.visible(site, GpsTime{1930, t}, 5 * M_PI / 180)) looks.push_back({v.sat, v.look});
      if (looks.size() >= 18 && looks.size() <= 22) out.push_back(buildGeometry(looks, ErrorModel{}, 9.0));
    }
  }
  return out;
}

/// Arg 0: the default fault-mode rule (adds_until_threshold); 1: joint_events, side by side.
void BM_AraimPlGpsGalileo(benchmark::State& state) {
  const auto skies = almanacSkies();
  const ErrorModel model;
  AraimConfig cfg;
  if (state.range(0) == 1) cfg.rule = FaultModeRule::kJointEvents;
  std::size_t k = 0, sats = 0, modes = 0;
  for (auto _ : state) {
    const Geometry& g = skies[k++ % skies.size()];
    const AraimResult r = araimProtectionLevels(g, model, cfg);
    sats += g.numSats();
    modes += r.fault_modes;
    benchmark::DoNotOptimize(r);
  }
  state.counters["sats"] = benchmark::Counter(static_cast<double>(sats), benchmark::Counter::kAvgIterations);
  state.counters["modes"] = benchmark::Counter(static_cast<double>(modes), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_AraimPlGpsGalileo)->Arg(0)->Arg(1)->Repetitions(5)->ReportAggregatesOnly(true);

/// The predicted PL of a user who excludes (docs/method.md §4.3 step 5): the no-exclusion
/// outcome and one outcome per satellite, each at ρ = 1/(N_exc + 1).
void BM_AraimFdePredictionGpsGalileo(benchmark::State& state) {
  const auto skies = almanacSkies();
  const ErrorModel model;
  const AraimConfig cfg;
  std::size_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(araimFdeProtectionLevels(skies[k++ % skies.size()], model, cfg));
}
BENCHMARK(BM_AraimFdePredictionGpsGalileo)->Repetitions(3)->ReportAggregatesOnly(true);

}  // namespace
