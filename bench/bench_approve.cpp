// Preflight approval. Targets (issue 7): the bundled example approved in ≤ 2 s; a city-sized
// case (1,000 zones, 5,000 buildings, 10 km route) in ≤ 10 s; and the planners compared on the
// same cases (route length and time, as counters).
#include "planner/approval.hpp"
#include "tests/planner/disc_field_proof.hpp"

#include <benchmark/benchmark.h>

#include <nlohmann/json.hpp>

#include "geofence/corridor.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
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
  double length = 0, planning = 0, iterations = 0, lattice_checks = 0;
  int approved = 0, n = 0;
  for (auto _ : state) {
    planner::Approver a(planner::loadMission(mission_path));  // loading is part of the job
    const planner::ApprovalReport r = a.approve();
    length += r.planner.length_m;
    planning += r.planner.planning_time_s;
    iterations += static_cast<double>(r.planner.iterations);
    lattice_checks += static_cast<double>(r.planner.lattice_state_checks);
    approved += r.approved ? 1 : 0;
    ++n;
  }
  state.counters["route_m"] = length / n;
  state.counters["planning_s"] = planning / n;
  state.counters["approved"] = static_cast<double>(approved) / n;
  state.counters["iterations"] = static_cast<double>(iterations) / n;
  if (lattice_checks > 0) state.counters["lattice_checks"] = lattice_checks / n;
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

// --- clutter (issue 22): 10,000 zones in 48 km² ------------------------------------------------

/// The clutter field: 10,000 prohibited circles (radius 15–40 m, uniform) scattered uniformly
/// over 8 km × 6 km, none within 150 m of the start (1 km, 1 km) or the goal (7 km, 5 km); the
/// search box (the two points ± 1 km) is exactly the field. Circles: centre x, y and radius [m].
struct ClutterField {
  std::vector<Eigen::Vector3d> circles;
  Eigen::Vector2d start{1000, 1000}, goal{7000, 5000};
};

const ClutterField& clutterField() {
  static const ClutterField field = [] {
    ClutterField f;
    std::mt19937_64 rng(22);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    while (f.circles.size() < 10000) {
      const Eigen::Vector2d c(u(rng) * 8000, u(rng) * 6000);
      const double r = 15 + 25 * u(rng);
      if ((c - f.start).norm() < 150 + r || (c - f.goal).norm() < 150 + r) continue;
      f.circles.emplace_back(c.x(), c.y(), r);
    }
    return f;
  }();
  return field;
}

/// Independently of the planner (tests/planner/disc_field_proof.hpp, on a 2 m grid): the
/// fraction of the field within `grow_m` of a circle, and whether a route exists.
/// Each proof once per run (12 M cells: the two benchmark arguments ask the same two).
std::pair<double, bool> clutterProof(const ClutterField& f, double grow_m) {
  static std::map<double, std::pair<double, bool>> done;
  if (const auto it = done.find(grow_m); it != done.end()) return it->second;
  const test::DiscFieldProof proof =
      test::proveRouteThroughDiscs(f.circles, Eigen::Vector4d(0, 8000, 0, 6000), 2.0, grow_m, f.start, f.goal);
  return done[grow_m] = {proof.blocked_fraction, proof.route};
}

/// Writes the clutter field's zones once and a mission through it with `algorithm` (the
/// receiver declares HPL 4 m / VPL 6 m, so the planning volume is known: the level-1 box, or
/// 1.2 × the PLs where larger); returns the mission file.
std::string clutterMission(const std::string& algorithm) {
  const std::string dir = "/tmp/skylane-bench-clutter";
  const ClutterField& f = clutterField();
  static bool zones_written = false;  // this run's field, not a file an older build left
  if (!zones_written) {
    zones_written = true;
    std::filesystem::create_directories(dir);
    json zones = json::array();
    for (std::size_t i = 0; i < f.circles.size(); ++i) {
      const Eigen::Vector3d& c = f.circles[i];
      zones.push_back({{"identifier", "CLUTTER-" + std::to_string(i)}, {"country", "CHE"}, {"name", "generated"},
                       {"type", "COMMON"}, {"restriction", "PROHIBITED"}, {"reason", {"OTHER"}},
                       {"applicability", json::array({{{"permanent", "YES"}}})},
                       {"geometry", {{{"uomDimensions", "M"}, {"lowerLimit", 0}, {"lowerVerticalReference", "AGL"},
                                       {"upperLimit", 150}, {"upperVerticalReference", "AGL"},
                                       {"horizontalProjection", {{"type", "Circle"},
                                                                 {"center", {kLon0 + dLon(c.x()), kLat0 + dLat(c.y())}},
                                                                 {"radius", c.z()}}}}}}});
    }
    std::ofstream(dir + "/zones.json") << json{{"formatVersion", "1.0.0"}, {"UASZoneList", zones}}.dump();
  }
  const std::string path = dir + "/mission_" + algorithm + ".json";
  json m{{"name", "10,000 zones in 48 km²"},
         {"vehicle", {{"lateral_m", 1.2}, {"longitudinal_m", 1.0}, {"cruise_speed_mps", 15}}},
         {"k1", 1.2}, {"k2", 150},
         {"start", {{"lat", kLat0 + dLat(f.start.y())}, {"lon", kLon0 + dLon(f.start.x())}}},
         {"goal", {{"lat", kLat0 + dLat(f.goal.y())}, {"lon", kLon0 + dLon(f.goal.x())}}},
         {"altitude", {{"cruise_agl_m", 60}, {"min_agl_m", 30}, {"max_agl_m", 120}}},
         {"departure", "2020-01-01T14:00:00Z"},
         {"zones", {dir + "/zones.json"}},
         {"ground_amsl_m", 408},
         {"orbits", {std::string(SKYLANE_TEST_DATA) + "/gnss/alm01jan2020.txt"}},
         {"navigation", {{"kind", "receiver"}, {"hpl_m", 4.0}, {"vpl_m", 6.0}}},
         {"integrity", {{"sample_s", 1.0}, {"cost_weight", 0.0}}},
         {"planner", {{"algorithm", algorithm}, {"time_limit_s", 30.0}, {"iterations", 10000}, {"seed", 5},
                      {"resolution_m", 5.0}, {"margin_m", 1000}}}};
  std::ofstream(path) << m.dump(1);
  return path;
}

/// The clutter case with RRT* (its lattice fallback engages when it finds no route) and with
/// the lattice seed at once. Counters: the blocked fraction (zones grown by the planning
/// volume) and whether the independent grid search proves a route exists.
void BM_ApproveClutter(benchmark::State& state) {
  const std::string algorithm = state.range(0) == 0 ? "rrtstar" : "lattice";
  state.SetLabel(algorithm);
  const std::string path = clutterMission(algorithm);
  const planner::Mission mission = planner::loadMission(path);
  const geofence::LevelLimits limits = geofence::alertLimits(mission.vehicle, mission.levels);
  const double grow_m = std::max(limits.level1.hal_m, 1.2 * mission.navigation.hpl_m);
  const double bare = clutterProof(clutterField(), 0.0).first;
  const auto [grown, exists] = clutterProof(clutterField(), grow_m + 1.0);
  run(state, path);
  state.counters["blocked_bare"] = bare;
  state.counters["blocked_grown"] = grown;
  state.counters["route_exists"] = exists ? 1.0 : 0.0;
}
BENCHMARK(BM_ApproveClutter)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
