// Live tracking (issue 8). Scene: 10,000 permanent PROHIBITED zones (star polygons of 4–16
// vertices, 0.1–1 km across) over 100 km × 100 km, kept off west–east lanes 5 km apart; one
// mission (and one shared Approver) for all; 1,000 approved flights of 2–4 points along the lanes
// at 60 m AGL, 12 m/s, limits level 1 {1.44, 1.2} and level 2 {180, 150} m; no replans.
// Fixes: one per flight per second, round-robin over the flights, on the route with 0.15 m of
// horizontal and 0.1 m of vertical noise, onboard HPL 0.5–1.2 m (2 % of fixes 1.5–2 m: level-1
// violations and recoveries), VPL 0.5–1 m. Counters: fixes per second (items/s) and the p50 / p99
// latency of one fix. BM_TrackJsonLine is the same per JSON line (parse, fix, process, dump the
// events); BM_Replan times Approver::replanFrom on the bundled example.
#include "maps/geodesy.hpp"
#include "maps/json_node.hpp"
#include "maps/plane_frame.hpp"
#include "planner/approval.hpp"
#include "planner/rehearsal/flight_sim.hpp"
#include "planner/report_formats.hpp"
#include "planner/tracking/track_fix.hpp"
#include "planner/tracking/tracker.hpp"

#include <benchmark/benchmark.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace skylane;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

const std::string kExample = std::string(SKYLANE_TEST_DATA) + "/../../examples/approve/mission.json";
constexpr double kLat0 = 47.0, kLon0 = 8.0;  // mission start = map-frame origin, centre of the area
constexpr double kHalfArea_m = 50000.0, kLaneStep_m = 5000.0, kSpeed_mps = 12.0, kGround_m = 408.0;
constexpr int kFlights = 1000, kZones = 10000, kRounds = 100;

/// The generated scene: the shared approver, the flights and their fixes (round-major:
/// fixes[r · kFlights + i] is flight i's fix at departure + r s) and the same as JSON lines.
struct TrackCity {
  std::shared_ptr<planner::Approver> approver;
  std::vector<std::string> ids;
  std::vector<planner::ApprovedFlight> flights;
  std::vector<planner::TrackFix> fixes;
  std::vector<std::string> lines;
};

/// Writes the zones and the mission to a temporary folder; returns the mission file.
std::string writeMission(const maps::PlaneFrame& frame) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "skylane-bench-track";
  std::filesystem::create_directories(dir);
  std::mt19937 rng(2027);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto lonLat = [&](double x, double y) {
    const Eigen::Vector2d ll = frame.toLatLon(Eigen::Vector2d(x, y));
    return json::array({maps::rad2deg(ll.y()), maps::rad2deg(ll.x())});
  };
  json zones = json::array();
  while (static_cast<int>(zones.size()) < kZones) {
    const double cx = kHalfArea_m * (2 * u(rng) - 1);
    const double cy = kHalfArea_m * (2 * u(rng) - 1);
    const double radius = 50.0 + 450.0 * u(rng);
    if (std::abs(cy - kLaneStep_m * std::round(cy / kLaneStep_m)) < radius + 100.0) continue;  // lanes stay clear
    const int n = 4 + static_cast<int>(rng() % 13);
    json ring = json::array();
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * (i + 0.1 + 0.8 * u(rng)) / n;
      const double r = radius * (0.3 + 0.7 * u(rng));
      ring.push_back(lonLat(cx + r * std::cos(a), cy + r * std::sin(a)));
    }
    ring.push_back(ring.front());
    const json volume{{"uomDimensions", "M"}, {"lowerLimit", 0}, {"lowerVerticalReference", "AGL"},
                      {"upperLimit", 120 + static_cast<int>(180 * u(rng))}, {"upperVerticalReference", "AGL"},
                      {"horizontalProjection", {{"type", "Polygon"}, {"coordinates", json::array({ring})}}}};
    zones.push_back({{"identifier", "TRK-" + std::to_string(zones.size())}, {"country", "CHE"}, {"name", "generated"},
                     {"type", "COMMON"}, {"restriction", "PROHIBITED"}, {"reason", json::array({"OTHER"})},
                     {"applicability", json::array({{{"permanent", "YES"}}})}, {"geometry", json::array({volume})}});
  }
  const std::string zone_file = (dir / "zones.json").string();
  std::ofstream(zone_file) << json{{"formatVersion", "1.0.0"}, {"UASZoneList", zones}}.dump();
  const json goal = lonLat(10000.0, 0.0);
  const json m{{"name", "generated tracking city"},
               {"vehicle", {{"lateral_m", 1.2}, {"longitudinal_m", 1.0}, {"cruise_speed_mps", kSpeed_mps}}},
               {"k1", 1.2}, {"k2", 150},
               {"start", {{"lat", kLat0}, {"lon", kLon0}}},
               {"goal", {{"lat", goal[1]}, {"lon", goal[0]}}},
               {"altitude", {{"cruise_agl_m", 60}, {"min_agl_m", 30}, {"max_agl_m", 120}}},
               {"departure", "2020-01-01T14:00:00Z"},
               {"zones", json::array({zone_file})},
               {"ground_amsl_m", kGround_m},
               {"orbits", json::array({std::string(SKYLANE_TEST_DATA) + "/gnss/alm01jan2020.txt"})}};
  const std::string path = (dir / "mission.json").string();
  std::ofstream(path) << m.dump(1);
  return path;
}

const TrackCity& trackCity() {
  static const TrackCity city = [] {
    TrackCity c;
    const maps::PlaneFrame frame(maps::deg2rad(kLat0), maps::deg2rad(kLon0));  // = the approver's frame
    const std::string mission_path = writeMission(frame);
    c.approver = std::make_shared<planner::Approver>(planner::loadMission(mission_path));
    const double h_ell = c.approver->missionStops().front().z();  // cruise height over the flat ground
    const maps::GpsTime departure = c.approver->mission().departure_earliest;
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::normal_distribution<double> noise(0.0, 1.0);
    std::vector<std::vector<Eigen::Vector2d>> paths;
    for (int i = 0; i < kFlights; ++i) {
      planner::ApprovedFlight f;
      f.report_source = "generated";
      f.mission_name = "F" + std::to_string(i);
      f.mission_source = mission_path;
      f.approved = true;
      f.departure = departure;
      f.level1 = {1.44, 1.2};
      f.level2 = {180.0, 150.0};
      const double lane = kLaneStep_m * (i % 19 - 9);
      double x = -40000.0 + 80000.0 * u(rng);
      const double heading = x < 0 ? 1.0 : -1.0;  // towards the centre: the route stays in the area
      const int n = 2 + static_cast<int>(rng() % 3);
      std::vector<Eigen::Vector2d> xy;
      double eta = 0.0;
      for (int k = 0; k < n; ++k) {
        if (k > 0) x += heading * (1000.0 + 2000.0 * u(rng));
        xy.emplace_back(x, lane + 50.0 * (2 * u(rng) - 1));
        if (k > 0) eta += (xy[k] - xy[k - 1]).norm() / kSpeed_mps;
        const Eigen::Vector2d ll = frame.toLatLon(xy.back());
        planner::RoutePoint p;
        p.lat_rad = ll.x();
        p.lon_rad = ll.y();
        p.h_ell_m = h_ell;
        p.alt_amsl_m = kGround_m + 60.0;
        p.eta_s = eta;
        f.route.push_back(p);
      }
      c.ids.push_back(f.mission_name);
      c.flights.push_back(std::move(f));
      paths.push_back(std::move(xy));
    }
    c.fixes.reserve(static_cast<std::size_t>(kFlights) * kRounds);
    c.lines.reserve(c.fixes.capacity());
    for (int r = 0; r < kRounds; ++r) {
      for (int i = 0; i < kFlights; ++i) {
        const std::vector<planner::RoutePoint>& route = c.flights[i].route;
        const std::vector<Eigen::Vector2d>& xy = paths[i];
        std::size_t s = 1;
        while (s + 1 < route.size() && route[s].eta_s < r) ++s;
        const double w = std::clamp((r - route[s - 1].eta_s) / (route[s].eta_s - route[s - 1].eta_s), 0.0, 1.0);
        const double ex = 0.15 * noise(rng), ey = 0.15 * noise(rng);
        const Eigen::Vector2d p = xy[s - 1] + w * (xy[s] - xy[s - 1]) + Eigen::Vector2d(ex, ey);
        const Eigen::Vector2d ll = frame.toLatLon(p);
        planner::TrackFix fix;
        fix.flight = c.ids[i];
        fix.time = departure.plus(r);
        fix.lat_rad = ll.x();
        fix.lon_rad = ll.y();
        fix.h_ell_m = h_ell + 0.1 * noise(rng);
        fix.hpl_m = u(rng) < 0.02 ? 1.5 + 0.5 * u(rng) : 0.5 + 0.7 * u(rng);
        fix.vpl_m = 0.5 + 0.5 * u(rng);
        fix.source = "generated";
        fix.line = c.fixes.size() + 1;
        c.lines.push_back(json{{"flight", fix.flight}, {"time", maps::formatRfc3339(fix.time, 3)},
                               {"lat", maps::rad2deg(fix.lat_rad)}, {"lon", maps::rad2deg(fix.lon_rad)},
                               {"h_ell_m", fix.h_ell_m}, {"hpl_m", *fix.hpl_m}, {"vpl_m", *fix.vpl_m}}
                              .dump());
        c.fixes.push_back(std::move(fix));
      }
    }
    return c;
  }();
  return city;
}

std::unique_ptr<planner::Tracker> makeTracker(const TrackCity& c) {
  planner::TrackerOptions options;
  options.replan = false;
  auto t = std::make_unique<planner::Tracker>(options);
  for (std::size_t i = 0; i < c.flights.size(); ++i) t->addFlight(c.ids[i], c.flights[i], c.approver);
  return t;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

/// Runs `one(k)` (the k-th fix or line, through `tracker`) round-robin; after the last fix every
/// flight has had all its times, so a fresh tracker starts over (untimed).
template <class One>
void runTracking(benchmark::State& state, One&& one) {
  const TrackCity& c = trackCity();
  std::unique_ptr<planner::Tracker> tracker = makeTracker(c);
  std::vector<double> latency_us;
  latency_us.reserve(static_cast<std::size_t>(std::min<benchmark::IterationCount>(state.max_iterations, 4000000)));
  std::size_t k = 0, events = 0, rejected = 0;
  for (auto _ : state) {
    if (k == c.fixes.size()) {
      state.PauseTiming();
      tracker = makeTracker(c);
      k = 0;
      state.ResumeTiming();
    }
    const auto t0 = Clock::now();
    const std::vector<planner::TrackEvent>& ev = one(*tracker, c, k++);
    latency_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    events += ev.size();
    for (const planner::TrackEvent& e : ev) rejected += e.is("rejected_input");
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["p50_us"] = percentile(latency_us, 0.50);
  state.counters["p99_us"] = percentile(latency_us, 0.99);
  const double n = std::max<double>(1.0, static_cast<double>(latency_us.size()));
  state.counters["events_per_fix"] = static_cast<double>(events) / n;
  state.counters["rejected_per_fix"] = static_cast<double>(rejected) / n;  // 0 unless the setup is wrong
  state.counters["flights"] = kFlights;
  state.counters["zones"] = kZones;
}

void BM_TrackFixes(benchmark::State& state) {
  runTracking(state, [](planner::Tracker& t, const TrackCity& c, std::size_t k) { return t.process(c.fixes[k]); });
}
BENCHMARK(BM_TrackFixes)->Unit(benchmark::kMicrosecond)->MinTime(2.0);

/// End to end per line: parse, read the fix, process, dump the events (as `skylane track` does:
/// one fix, one list of events and one line kept from line to line, so no allocation per line).
void BM_TrackJsonLine(benchmark::State& state) {
  std::size_t out_bytes = 0;
  std::string line, source;
  planner::TrackFix fix;
  std::vector<planner::TrackEvent> events;
  runTracking(state, [&](planner::Tracker& t, const TrackCity& c, std::size_t k) -> const std::vector<planner::TrackEvent>& {
    source.assign("bench.jsonl:");
    source += std::to_string(k + 1);
    planner::parseTrackFixLine(c.lines[k], source, fix);
    fix.line = k + 1;
    t.process(fix, events);
    for (const planner::TrackEvent& e : events) {
      line.clear();
      e.appendJsonLine(line);
      out_bytes += line.size();
    }
    return events;
  });
  const double lines = std::max<double>(1.0, static_cast<double>(state.iterations()));
  state.counters["out_bytes_per_line"] = static_cast<double>(out_bytes) / lines;
}
BENCHMARK(BM_TrackJsonLine)->Unit(benchmark::kMicrosecond)->MinTime(2.0);

/// The same through the general reading (a JSON document, then parseTrackFixJson): what every
/// line cost before plain lines were read directly, side by side in one run.
void BM_TrackJsonLineGeneral(benchmark::State& state) {
  runTracking(state, [](planner::Tracker& t, const TrackCity& c, std::size_t k) {
    const std::string source = "bench.jsonl:" + std::to_string(k + 1);
    planner::TrackFix fix = planner::parseTrackFixJson(maps::parseJsonLine(c.lines[k], source), source);
    fix.line = k + 1;
    std::vector<planner::TrackEvent> ev = t.process(fix);
    std::size_t bytes = 0;
    for (const planner::TrackEvent& e : ev) bytes += e.jsonLine().size();
    benchmark::DoNotOptimize(bytes);
    return ev;
  });
}
BENCHMARK(BM_TrackJsonLineGeneral)->Unit(benchmark::kMicrosecond)->MinTime(2.0);

/// A replan of the bundled example from 20 m north of where the route is 30 s after departure.
void BM_Replan(benchmark::State& state) {
  planner::Approver approver(planner::loadMission(kExample));
  const planner::ApprovalReport approval = approver.approve();
  if (!approval.approved || approval.route.size() < 2) {
    state.SkipWithError("the bundled example was not approved");
    return;
  }
  const Eigen::Vector3d from = planner::positionAlong(approval.route, 30.0) + Eigen::Vector3d(0.0, 20.0, 0.0);
  const maps::GpsTime now = approval.departure.plus(30.0);
  int approved = 0, n = 0;
  double length = 0.0;
  for (auto _ : state) {
    const planner::ApprovalReport r = approver.replanFrom(from, now, 1);
    approved += r.approved ? 1 : 0;
    length += r.planner.length_m;
    ++n;
  }
  state.counters["approved"] = static_cast<double>(approved) / std::max(n, 1);
  state.counters["route_m"] = length / std::max(n, 1);
}
BENCHMARK(BM_Replan)->Unit(benchmark::kMillisecond)->Iterations(5);

/// The bundled example for a vehicle of `span_m` × `length_m` (so that the PLs of raw fixes fit
/// level 1), its approval as a tracked flight, and the simulator's fixes along it with a 60 m
/// fault on one satellite over the second half; with `imu`, the IMU increments too.
struct RawScene {
  std::shared_ptr<planner::Approver> approver;
  planner::ApprovedFlight flight;
  std::vector<planner::TrackFix> fixes;
};

bool rawScene(benchmark::State& state, double span_m, double length_m, const std::optional<planner::ImuFeed>& imu, RawScene& out) {
  planner::Mission m = planner::loadMission(kExample);
  m.vehicle.lateral_m = span_m;
  m.vehicle.longitudinal_m = length_m;
  m.levels.k2 = 100.0;
  out.approver = std::make_shared<planner::Approver>(m);
  const planner::ApprovalReport r = out.approver->approve();
  if (!r.approved) {
    state.SkipWithError("the example with a larger vehicle was not approved");
    return false;
  }
  out.flight.approved = true;
  out.flight.departure = r.departure;
  out.flight.route = r.route;
  out.flight.level1 = r.limits.level1;
  out.flight.level2 = r.limits.level2;
  integrity::sim::FaultSpec fault;
  fault.target = integrity::sim::FaultTarget::kSatellite;
  fault.pick = 0.5;
  fault.t_start_s = r.route.back().eta_s / 2.0;
  fault.t_end_s = r.route.back().eta_s + 60.0;
  fault.magnitude = 60.0;
  planner::FlightSimOptions sim;
  sim.seed = 3;
  sim.faults = {fault};
  sim.imu = imu;
  for (planner::SimulatedFix& sf : planner::simulateFlight(r, *out.approver, sim)) out.fixes.push_back(std::move(sf.fix));
  return true;
}

/// Replays a scene's fixes (a new tracker each time round) and reports the latencies.
void replayRaw(benchmark::State& state, const RawScene& scene) {
  planner::TrackerOptions options;
  options.replan = false;
  std::unique_ptr<planner::Tracker> tracker;
  const std::vector<planner::TrackFix>& fixes = scene.fixes;
  std::size_t k = fixes.size(), reruns = 0, n = 0, sats = 0, excluded = 0;
  std::vector<double> latency_us;
  for (auto _ : state) {
    if (k == fixes.size()) {
      state.PauseTiming();
      tracker = std::make_unique<planner::Tracker>(options);
      tracker->addFlight("F1", scene.flight, scene.approver);
      k = 0;
      state.ResumeTiming();
    }
    const auto t0 = Clock::now();
    const std::vector<planner::TrackEvent> ev = tracker->process(fixes[k]);
    latency_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    for (const planner::TrackEvent& e : ev) {
      if (!e.fix) continue;
      reruns += e.fix->rerun;
      excluded += !e.fix->excluded.empty();
    }
    sats += fixes[k].ranges.size();
    ++k;
    ++n;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["p50_us"] = percentile(latency_us, 0.50);
  state.counters["p99_us"] = percentile(latency_us, 0.99);
  state.counters["reruns_per_fix"] = static_cast<double>(reruns) / std::max<std::size_t>(n, 1);
  state.counters["excluding_fixes"] = static_cast<double>(excluded) / std::max<std::size_t>(n, 1);
  state.counters["satellites"] = static_cast<double>(sats) / std::max<std::size_t>(n, 1);
}

/// Fixes with raw pseudoranges (skylane's own position and RAIM PLs) on the bundled example:
/// the first pass, and on a detection the FDE rerun and the second check. Vehicle of 20 m span
/// so that the fault-free PLs fit level 1 and a detection is what triggers the rerun.
void BM_TrackRawFixes(benchmark::State& state) {
  RawScene scene;
  if (rawScene(state, 20.0, 25.0, std::nullopt, scene)) replayRaw(state, scene);
}
BENCHMARK(BM_TrackRawFixes)->Unit(benchmark::kMicrosecond)->MinTime(1.0);

/// The same flight with a tactical IMU's increments (100 per fix), barometer and magnetometer:
/// the fault-mode GNSS/INS flow per fix (docs/method.md §5.2) (strapdown, EKF, FDE, IMU test, fault-mode PLs). Vehicle of
/// 40 m span: the fault-mode PLs fit level 1.
void BM_TrackGnssInsFixes(benchmark::State& state) {
  RawScene scene;
  if (rawScene(state, 40.0, 50.0, planner::ImuFeed{}, scene)) replayRaw(state, scene);
}
BENCHMARK(BM_TrackGnssInsFixes)->Unit(benchmark::kMicrosecond)->MinTime(1.0);

}  // namespace
