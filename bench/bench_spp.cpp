// SPP with RAIM FDE and PLs over the station-3040 hour (120 epochs), parsing excluded and included.
#include "integrity/raim/spp.hpp"

#include <benchmark/benchmark.h>

namespace {

using namespace skylane::integrity;

void BM_SppStation3040Solve(benchmark::State& state) {
  const ObservationData obs = loadRinexObs(SKYLANE_TEST_DATA "/gnss/30400920.05o");
  const NavigationData nav = loadRinexNav(SKYLANE_TEST_DATA "/gnss/30400920.05n");
  for (auto _ : state) benchmark::DoNotOptimize(solveSpp(obs, nav, SppConfig{}));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(obs.epochs.size()));
}
BENCHMARK(BM_SppStation3040Solve)->Unit(benchmark::kMillisecond);

void BM_SppStation3040ParseAndSolve(benchmark::State& state) {
  for (auto _ : state) {
    const ObservationData obs = loadRinexObs(SKYLANE_TEST_DATA "/gnss/30400920.05o");
    const NavigationData nav = loadRinexNav(SKYLANE_TEST_DATA "/gnss/30400920.05n");
    benchmark::DoNotOptimize(solveSpp(obs, nav, SppConfig{}));
  }
}
BENCHMARK(BM_SppStation3040ParseAndSolve)->Unit(benchmark::kMillisecond);

}  // namespace
