// Sky mask at a street-level point among 5,000 buildings (issue 4 target: ≤ 1 ms).
//
// The city: 2 km × 2 km, 5,000 buildings at uniformly random places (about 1,250 per km²,
// a dense European centre), footprints star-shaped with 4–12 vertices and 4–20 m radius,
// heights 5–60 m, on flat ground. Queries at street level (1.5 m) at random points of the
// central 1 km × 1 km that are not inside a building, 1° bins.
#include "maps/sky_mask.hpp"

#include <benchmark/benchmark.h>

#include <random>

namespace {

using namespace skylane;

const maps::Geodetic kCentre{maps::deg2rad(47.3769), maps::deg2rad(8.5417), 450.0};

std::vector<maps::Building> city(int n, double side_m, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-side_m / 2, side_m / 2), radius(4, 20), height(5, 60), jitter(0.6, 1.0);
  std::uniform_int_distribution<int> verts(4, 12);
  const maps::LocalFrame frame(kCentre);
  std::vector<maps::Building> out;
  for (int i = 0; i < n; ++i) {
    const double ce = pos(rng), cn = pos(rng), r = radius(rng);
    const int m = verts(rng);
    maps::Building b;
    for (int k = 0; k < m; ++k) {
      const double a = 2 * M_PI * k / m, rr = r * jitter(rng);
      const maps::Geodetic g = frame.fromEnu({ce + rr * std::cos(a), cn + rr * std::sin(a), 0.0});
      b.ring_lat_lon_rad.emplace_back(g.lat_rad, g.lon_rad);
    }
    b.base_h_ell_m = kCentre.h_ell_m;
    b.top_h_ell_m = kCentre.h_ell_m + height(rng);
    out.push_back(std::move(b));
  }
  return out;
}

/// Street-level points (not inside a building: the mask there is trivially 90°).
std::vector<maps::Geodetic> streetPoints(const maps::BuildingIndex& index, int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-500, 500);
  const maps::LocalFrame frame(kCentre);
  std::vector<maps::Geodetic> out;
  while (static_cast<int>(out.size()) < n) {
    maps::Geodetic p = frame.fromEnu({pos(rng), pos(rng), 0.0});
    p.h_ell_m = kCentre.h_ell_m + 1.5;
    maps::SkyMask m;
    index.raiseMask(m, p);
    if (m.binBlocked_rad(0) < M_PI / 2) out.push_back(p);
  }
  return out;
}

void BM_SkyMask5000Buildings(benchmark::State& state) {
  const std::vector<maps::Building> buildings = city(5000, 2000.0, 42);
  const maps::BuildingIndex index(buildings, kCentre);
  const std::vector<maps::Geodetic> points = streetPoints(index, 64);
  maps::SkyMaskOptions opt;
  opt.cull = state.range(0) != 0;
  std::size_t i = 0;
  double sum = 0;
  for (auto _ : state) {
    const maps::SkyMask m = maps::computeSkyMask(points[i++ % points.size()], &index, nullptr, opt);
    sum += m.binBlocked_rad(0);
    benchmark::DoNotOptimize(sum);
  }
  state.SetLabel(opt.cull ? "indexed, culled" : "brute force (every building)");
}
BENCHMARK(BM_SkyMask5000Buildings)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

void BM_BuildingIndex5000(benchmark::State& state) {
  const std::vector<maps::Building> buildings = city(5000, 2000.0, 42);
  for (auto _ : state) {
    const maps::BuildingIndex index(buildings, kCentre);
    benchmark::DoNotOptimize(index.size());
  }
}
BENCHMARK(BM_BuildingIndex5000)->Unit(benchmark::kMillisecond);

}  // namespace
