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
