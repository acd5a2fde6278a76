// The worldwide availability map at 5° / 24 h / 10 min (373 248 user-epochs), GPS + Galileo
// ED-259 almanacs, ARAIM, all cores. Target (issue 3): ≤ 60 s on the 2-core machine.
#include "integrity/availability.hpp"

#include <benchmark/benchmark.h>

namespace {

using namespace skylane::integrity;

void BM_AvailabilityMap5deg24h(benchmark::State& state) {
  OrbitSource orbits;
  orbits.addAlmanac(loadAlmanac(SKYLANE_TEST_DATA "/gnss/alm_gps_ed259.txt"));
  orbits.addAlmanac(loadAlmanac(SKYLANE_TEST_DATA "/gnss/alm_gal_ed259.txt"));
  AvailabilityRequest req;
  req.start = *parseRfc3339("2017-01-01T00:00:00Z");
  for (auto _ : state) benchmark::DoNotOptimize(computeAvailability(orbits, req));
  state.SetItemsProcessed(state.iterations() * 373248);
}
BENCHMARK(BM_AvailabilityMap5deg24h)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
