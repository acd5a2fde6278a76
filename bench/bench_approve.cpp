// Preflight approval. Targets (issue 7): the bundled example approved in ≤ 2 s; a city-sized
// case (1,000 zones, 5,000 buildings, 10 km route) in ≤ 10 s; and the planners compared on the
// same cases (route length and time, as counters).
#include "planner/approval.hpp"

#include <benchmark/benchmark.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace {

using namespace skylane;
using nlohmann::json;

const std::string kExample = std::string(SKYLANE_TEST_DATA) + "/../../examples/approve/mission.json";
constexpr double kLat0 = 47.30, kLon0 = 8.45;  // south-west corner of the generated city

/// Degrees of latitude / longitude per metre near the city.
double dLat(double m) { return m / 111195.0; }
double dLon(double m) { return m / (111195.0 * std::cos(kLat0 * M_PI / 180.0)); }

/// Writes the generated city once: 1,000 zones and 5,000 buildings over 12 km × 4 km, with a
/// 10 km west–east mission through the middle; returns the mission file.
std::string cityMission(planner::PlannerKind kind) {
  static bool written = false;
  const std::string dir = "/tmp/skylane-bench-city";
  if (!written) {
    std::filesystem::create_directories(dir);
    std::mt19937_64 rng(2026);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    json zones = json::array();
    auto clearOfEnds = [](double x, double y) {
      return std::hypot(x - 1000, y - 2000) > 400 && std::hypot(x - 11000, y - 2000) > 400;
    };
    for (int i = 0; i < 1000; ++i) {
      double x, y;
      do {
        x = u(rng) * 12000;
        y = u(rng) * 4000;
      } while (!clearOfEnds(x, y));
      const double r = 20 + 60 * u(rng);
      json app = json::array({{{"permanent", "YES"}}});
      if (i % 4 == 0) app = json::array({{{"permanent", "NO"}, {"startDateTime", "2020-01-01T13:00:00Z"}, {"endDateTime", "2020-01-01T18:00:00Z"}}});
      zones.push_back({{"identifier", "CITY-" + std::to_string(i)}, {"country", "CHE"}, {"name", "generated"},
                       {"type", "COMMON"}, {"restriction", "PROHIBITED"}, {"reason", {"OTHER"}}, {"applicability", app},
                       {"geometry", {{{"uomDimensions", "M"}, {"lowerLimit", 0}, {"lowerVerticalReference", "AGL"},
                                       {"upperLimit", 150}, {"upperVerticalReference", "AGL"},
                                       {"horizontalProjection", {{"type", "Circle"},
                                                                 {"center", {kLon0 + dLon(x), kLat0 + dLat(y)}},
                                                                 {"radius", r}}}}}}});
    }
    std::ofstream(dir + "/zones.json") << json{{"formatVersion", "1.0.0"}, {"UASZoneList", zones}}.dump();
    json features = json::array();
    for (int i = 0; i < 5000; ++i) {
      double x, y;
      do {
        x = u(rng) * 12000;
        y = u(rng) * 4000;
      } while (!clearOfEnds(x, y));
      const double w = 10 + 30 * u(rng), h = 10 + 30 * u(rng);
      json ring = json::array();
      for (auto [cx, cy] : {std::pair{0.0, 0.0}, {w, 0.0}, {w, h}, {0.0, h}, {0.0, 0.0}}) {
        ring.push_back({kLon0 + dLon(x + cx), kLat0 + dLat(y + cy)});
      }
      features.push_back({{"type", "Feature"}, {"geometry", {{"type", "Polygon"}, {"coordinates", {ring}}}},
                          {"properties", {{"height", 5 + 55 * u(rng)}}}});
    }
    std::ofstream(dir + "/buildings.geojson") << json{{"type", "FeatureCollection"}, {"features", features}}.dump();
    written = true;
  }
  const std::string path = dir + "/mission_" + std::string(planner::plannerName(kind)) + ".json";
  json m{{"name", "generated city, 10 km"},
         {"vehicle", {{"lateral_m", 1.2}, {"longitudinal_m", 1.0}, {"cruise_speed_mps", 15}}},
         {"k1", 1.2}, {"k2", 150},
         {"start", {{"lat", kLat0 + dLat(2000)}, {"lon", kLon0 + dLon(1000)}}},
         {"goal", {{"lat", kLat0 + dLat(2000)}, {"lon", kLon0 + dLon(11000)}}},
         {"altitude", {{"cruise_agl_m", 60}, {"min_agl_m", 30}, {"max_agl_m", 120}}},
         {"departure", "2020-01-01T14:00:00Z"},
         {"zones", {dir + "/zones.json"}},
         {"ground_amsl_m", 408},
         {"buildings", dir + "/buildings.geojson"},
         {"orbits", {std::string(SKYLANE_TEST_DATA) + "/gnss/alm01jan2020.txt"}},
         {"integrity", {{"sample_s", 1.0}, {"cost_weight", 1.0}, {"cost_cell_m", 100}}},
         {"planner", {{"algorithm", std::string(planner::plannerName(kind))}, {"time_limit_s", 8.0}, {"iterations", 10000}, {"seed", 5},
                      {"resolution_m", 5.0}, {"margin_m", 600}}}};
  std::ofstream(path) << m.dump(1);
  return path;
}

void run(benchmark::State& state, const std::string& mission_path) {
  double length = 0, planning = 0, iterations = 0;
  int approved = 0, n = 0;
  for (auto _ : state) {
    planner::Approver a(planner::loadMission(mission_path));  // loading is part of the job
    const planner::ApprovalReport r = a.approve();
    length += r.planner.length_m;
    planning += r.planner.planning_time_s;
    iterations += static_cast<double>(r.planner.iterations);
    approved += r.approved ? 1 : 0;
    ++n;
  }
  state.counters["route_m"] = length / n;
  state.counters["planning_s"] = planning / n;
  state.counters["approved"] = static_cast<double>(approved) / n;
  state.counters["iterations"] = static_cast<double>(iterations) / n;
}

void BM_ApproveBundledExample(benchmark::State& state) { run(state, kExample); }
BENCHMARK(BM_ApproveBundledExample)->Unit(benchmark::kMillisecond)->Iterations(3);

/// The bundled example with each planner (the mission copied beside it with another algorithm).
void BM_ApproveExamplePlanner(benchmark::State& state) {
  const auto kind = static_cast<planner::PlannerKind>(state.range(0));
  state.SetLabel(std::string(planner::plannerName(kind)));
  json m;
  std::ifstream(kExample) >> m;
  m["planner"]["algorithm"] = std::string(planner::plannerName(kind));
  const std::string path = std::string(SKYLANE_TEST_DATA) + "/../../examples/approve/.bench_" +
                           std::string(planner::plannerName(kind)) + ".json";
  std::ofstream(path) << m.dump(1);
  run(state, path);
  std::filesystem::remove(path);
}
BENCHMARK(BM_ApproveExamplePlanner)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_ApproveCity(benchmark::State& state) {
  const auto kind = static_cast<planner::PlannerKind>(state.range(0));
  state.SetLabel(std::string(planner::plannerName(kind)));
  run(state, cityMission(kind));
}
BENCHMARK(BM_ApproveCity)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
