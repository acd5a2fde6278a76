// Zones: load, validate and decompose. Target (issue 4): 10,000 generated ED-269 zones
// (polygons of 4–64 vertices) loaded from file, validated and cut into convex pieces ≤ 2 s.
// And the map frame's projection of a fix, exact (PlaneFrame) and interpolated (PlaneGrid),
// side by side over the same 100 km × 100 km of fixes.
#include "airspace/validation.hpp"
#include "airspace/zone_geometry.hpp"
#include "maps/geodesy.hpp"
#include "maps/plane_frame.hpp"
#include "maps/plane_grid.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace skylane;

/// An ED-269 file of `count` star-shaped zones (4–64 vertices, 0.2–5 km across) over central
/// Europe, with closing vertices repeated as the format writes them.
std::string writeGeneratedZones(int count) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::ostringstream out;
  out.precision(10);
  out << R"({"UASZoneList":[)";
  for (int z = 0; z < count; ++z) {
    const int n = 4 + static_cast<int>(rng() % 61);
    const double lat0 = 44.0 + 10.0 * u(rng), lon0 = 2.0 + 20.0 * u(rng);
    const double radius_deg = (0.1 + 2.4 * u(rng)) / 111.0;
    out << (z ? "," : "") << R"({"identifier":"GEN)" << z << R"(","country":"CHE","name":"generated","type":"COMMON",)"
        << R"("restriction":"PROHIBITED","reason":["OTHER"],"applicability":[{"permanent":"YES"}],"geometry":[{)"
        << R"("uomDimensions":"M","lowerLimit":0,"lowerVerticalReference":"AGL","upperLimit":120,)"
        << R"("upperVerticalReference":"AGL","horizontalProjection":{"type":"Polygon","coordinates":[[)";
    std::ostringstream first;
    first.precision(10);
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * (i + 0.1 + 0.8 * u(rng)) / n;
      const double r = radius_deg * (0.3 + 0.7 * u(rng));
      std::ostringstream v;
      v.precision(10);
      v << "[" << lon0 + r * std::cos(a) / std::cos(maps::deg2rad(lat0)) << "," << lat0 + r * std::sin(a) << "]";
      if (i == 0) first << v.str();
      out << (i ? "," : "") << v.str();
    }
    out << "," << first.str() << "]]}}]}";
  }
  out << "]}";
  const std::string path = "/tmp/skylane_bench_zones_" + std::to_string(count) + ".json";
  std::ofstream(path) << out.str();
  return path;
}

void BM_LoadValidateDecomposeZones(benchmark::State& state) {
  const int count = static_cast<int>(state.range(0));
  const std::string path = writeGeneratedZones(count);
  std::size_t pieces = 0;
  for (auto _ : state) {
    const std::vector<airspace::Zone> zones = airspace::loadZones(path);  // parse + validate (throws if invalid)
    pieces = 0;
    for (const airspace::Zone& z : zones) {
      for (const airspace::Volume& v : z.volumes) {
        const maps::PlaneFrame frame(v.outline.ring[0].lat_rad, v.outline.ring[0].lon_rad);
        pieces += airspace::convexPieces(airspace::projectOutline(v.outline, frame, 1.0, airspace::safeSideOf(z))).size();
      }
    }
    benchmark::DoNotOptimize(pieces);
  }
  state.counters["pieces"] = static_cast<double>(pieces);
  std::remove(path.c_str());
}
BENCHMARK(BM_LoadValidateDecomposeZones)->Arg(10000)->Unit(benchmark::kMillisecond)->Iterations(3);

/// 65,536 fixes spread over ±0.45° around the origin (47° N, 8° E), projected in turn.
template <class Projection>
void projectFixes(benchmark::State& state, const Projection& projection) {
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> u(-0.45, 0.45);
  std::vector<std::pair<double, double>> fixes(1 << 16);
  for (auto& f : fixes) f = {maps::deg2rad(47.0 + u(rng)), maps::deg2rad(8.0 + u(rng))};
  for (const auto& f : fixes) benchmark::DoNotOptimize(projection.toPlane(f.first, f.second));  // cells built
  std::size_t k = 0;
  for (auto _ : state) {
    const auto& f = fixes[k++ & (fixes.size() - 1)];
    benchmark::DoNotOptimize(projection.toPlane(f.first, f.second));
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_ProjectFixExact(benchmark::State& state) {
  projectFixes(state, maps::PlaneFrame(maps::deg2rad(47.0), maps::deg2rad(8.0)));
}
BENCHMARK(BM_ProjectFixExact)->Unit(benchmark::kNanosecond);

void BM_ProjectFixGrid(benchmark::State& state) {
  const maps::PlaneGrid grid(maps::PlaneFrame(maps::deg2rad(47.0), maps::deg2rad(8.0)));
  projectFixes(state, grid);
}
BENCHMARK(BM_ProjectFixGrid)->Unit(benchmark::kNanosecond);

}  // namespace
