#include "cli/simulate_commands.hpp"

#include "cli/json_numbers.hpp"
#include "cli/progress.hpp"
#include "cli/svg_plot.hpp"
#include "integrity/sim/run.hpp"
#include "maps/atomic_file.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <thread>

namespace skylane::cli {
namespace {

using integrity::sim::Method;
using integrity::sim::kNumMethods;
using nlohmann::json;

struct SimulateOptions {
  std::string scenario;
  std::string out_dir;
  std::optional<std::uint64_t> seed;
  std::uint64_t monte_carlo = 0;
  int threads = 0;
  bool progress = false;
  bool no_plots = false;
};

/// A file of the output folder, staged: written in place when the run has succeeded.
void writeFile(maps::OutputSet& outputs, const std::filesystem::path& path, const std::string& text) {
  outputs.add(path.string(), "--out") << text;
}

std::vector<std::string> regionLines(const integrity::sim::StanfordHistogram& h) {
  char b[160];
  std::vector<std::string> out;
  std::snprintf(b, sizeof b, "epochs %llu, no PL %llu; normal %llu, MI %llu, HMI %llu",
                static_cast<unsigned long long>(h.total), static_cast<unsigned long long>(h.no_pl),
                static_cast<unsigned long long>(h.normal), static_cast<unsigned long long>(h.mi),
                static_cast<unsigned long long>(h.hmi));
  out.emplace_back(b);
  std::snprintf(b, sizeof b, "unavailable %llu (of which error > PL %llu); error > PL in all: %llu",
                static_cast<unsigned long long>(h.unavailable), static_cast<unsigned long long>(h.unavailable_mi),
                static_cast<unsigned long long>(h.misleading));
  out.emplace_back(b);
  return out;
}

std::string stanfordSvg(const integrity::sim::MonteCarloResult& r, bool horizontal, const std::string& title) {
  std::vector<StanfordPanel> panels;
  for (int m = 0; m < kNumMethods; ++m) {
    const auto& h = horizontal ? r.methods[m].horizontal : r.methods[m].vertical;
    StanfordPanel p;
    p.title = std::string(integrity::sim::methodName(static_cast<Method>(m)));
    p.error_label = horizontal ? "horizontal position error [m]" : "vertical position error [m]";
    p.pl_label = horizontal ? "HPL [m]" : "VPL [m]";
    p.alert_limit_m = h.alert_limit_m;
    p.max_m = h.max_m;
    p.bins = h.bins;
    p.counts = h.counts;
    p.footer = regionLines(h);
    panels.push_back(std::move(p));
  }
  return renderStanfordSvg(title, panels);
}

json countsJson(const integrity::sim::MonteCarloResult& r) {
  json j;
  j["runs"] = r.runs;
  j["epochs"] = r.epochs;
  j["faulted_epochs"] = r.faulted_epochs;
  for (int m = 0; m < kNumMethods; ++m) {
    json mj;
    for (int dir = 0; dir < 2; ++dir) {
      const auto& h = dir == 0 ? r.methods[m].horizontal : r.methods[m].vertical;
      const std::uint64_t with_pl = h.total - h.no_pl;
      json d;
      d["epochs"] = h.total;
      d["no_pl"] = h.no_pl;
      d["normal"] = h.normal;
      d["mi"] = h.mi;
      d["hmi"] = h.hmi;
      d["unavailable"] = h.unavailable;
      d["misleading"] = h.misleading;
      d["misleading_rate"] = with_pl ? static_cast<double>(h.misleading) / static_cast<double>(with_pl) : 0.0;
      d["hmi_rate_upper_95"] = integrity::sim::upperBound95(h.hmi, with_pl);
      d["misleading_rate_upper_95"] = integrity::sim::upperBound95(h.misleading, with_pl);
      mj[dir == 0 ? "horizontal" : "vertical"] = d;
    }
    j["methods"][std::string(integrity::sim::methodName(static_cast<Method>(m)))] = mj;
  }
  return j;
}

void printCounts(const integrity::sim::MonteCarloResult& r, std::ostream& os) {
  char b[256];
  std::snprintf(b, sizeof b, "%-20s %-4s %10s %9s %9s %6s %11s %12s %12s\n", "method", "dir", "with PL", "unavail",
                "error>PL", "HMI", "MI rate", "MI rate 95%", "HMI rate 95%");
  os << b;
  for (int m = 0; m < kNumMethods; ++m) {
    for (int dir = 0; dir < 2; ++dir) {
      const auto& h = dir == 0 ? r.methods[m].horizontal : r.methods[m].vertical;
      const std::uint64_t with_pl = h.total - h.no_pl;
      std::snprintf(b, sizeof b, "%-20s %-4s %10llu %9llu %9llu %6llu %11.3g %12.3g %12.3g\n",
                    std::string(integrity::sim::methodName(static_cast<Method>(m))).c_str(), dir == 0 ? "H" : "V",
                    static_cast<unsigned long long>(with_pl), static_cast<unsigned long long>(h.unavailable),
                    static_cast<unsigned long long>(h.misleading), static_cast<unsigned long long>(h.hmi),
                    with_pl ? static_cast<double>(h.misleading) / static_cast<double>(with_pl) : 0.0,
                    integrity::sim::upperBound95(h.misleading, with_pl), integrity::sim::upperBound95(h.hmi, with_pl));
      os << b;
    }
  }
}

std::string curvesSvg(const integrity::sim::RunResult& run, const integrity::sim::Scenario& s) {
  std::vector<double> t;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Line {
    const char* label;
    const char* colour;
    Method method;
  };
  const Line lines[] = {{"fault-mode PL", "#d62728", Method::kFaultMode},
                        {"three-hypothesis INS PL", "#ff7f0e", Method::kThreeHypothesisIns},
                        {"RAIM PL", "#2ca02c", Method::kRaim},
                        {"ARAIM PL", "#9467bd", Method::kAraim}};
  std::vector<Panel> panels(2);
  for (int dir = 0; dir < 2; ++dir) {
    Panel& p = panels[static_cast<std::size_t>(dir)];
    p.y_label = dir == 0 ? "horizontal [m]" : "vertical [m]";
    Series err{dir == 0 ? "error (system)" : "|error| (system)", "#000000", {}, false, false};
    Series al{dir == 0 ? "HAL" : "VAL", "#7f7f7f", {}, true, false};
    std::vector<Series> pls;
    for (const Line& l : lines) pls.push_back({l.label, l.colour, {}, false, false});
    Series ekf_err{"error (filter)", "#1f77b4", {}, true, false};
    Series raim_err{"error (snapshot)", "#2ca02c", {}, true, false};
    for (const auto& e : run.epochs) {
      if (dir == 0) t.push_back(e.t_s);
      const auto& sys = e.methods[static_cast<int>(Method::kFaultMode)];
      err.y.push_back(dir == 0 ? sys.hpe_m : sys.vpe_m);
      const auto& f = e.methods[static_cast<int>(Method::kThreeHypothesisIns)];
      ekf_err.y.push_back(dir == 0 ? f.hpe_m : f.vpe_m);
      const auto& sn = e.methods[static_cast<int>(Method::kRaim)];
      raim_err.y.push_back(dir == 0 ? sn.hpe_m : sn.vpe_m);
      al.y.push_back(dir == 0 ? s.hal_m : s.val_m);
      for (std::size_t k = 0; k < pls.size(); ++k) {
        const auto& m = e.methods[static_cast<int>(lines[k].method)];
        pls[k].y.push_back(m.available ? (dir == 0 ? m.hpl_m : m.vpl_m) : nan);
      }
    }
    p.series.push_back(err);
    p.series.push_back(ekf_err);
    p.series.push_back(raim_err);
    for (Series& se : pls) p.series.push_back(std::move(se));
    p.series.push_back(al);
  }
  // The fault modes (Zhao & Song 2024 Figs. 6–11): each mode's PL against the system error.
  const char* const mode_names[4] = {"FF", "GS", "I", "GSI"};
  const char* const mode_colours[4] = {"#2ca02c", "#d62728", "#1f77b4", "#9467bd"};
  for (int dir = 0; dir < 2; ++dir) {
    Panel p;
    p.y_label = dir == 0 ? "fault-mode PLs, H [m]" : "fault-mode PLs, V [m]";
    p.height_px = 200;
    Series err{"error (system)", "#000000", {}, false, false};
    std::vector<Series> modes;
    for (int k = 0; k < 4; ++k) modes.push_back({std::string(mode_names[k]) + (dir == 0 ? " HPL" : " VPL"), mode_colours[k], {}, k == 0, false});
    for (const auto& e : run.epochs) {
      const auto& sys = e.methods[static_cast<int>(Method::kFaultMode)];
      err.y.push_back(dir == 0 ? sys.hpe_m : sys.vpe_m);
      for (int k = 0; k < 4; ++k) {
        const double v = dir == 0 ? e.mode_hpl_m[static_cast<std::size_t>(k)] : e.mode_vpl_m[static_cast<std::size_t>(k)];
        modes[static_cast<std::size_t>(k)].y.push_back(e.degraded || v <= 0.0 ? nan : v);
      }
    }
    p.series.push_back(err);
    for (Series& m : modes) p.series.push_back(std::move(m));
    panels.push_back(p);
  }
  Panel imu;
  imu.y_label = "IMU test";
  imu.height_px = 160;
  Series stat{"innovation χ²", "#1f77b4", {}, false, false}, thr{"threshold", "#d62728", {}, true, false};
  Series sats{"satellites used", "#2ca02c", {}, false, true};
  for (const auto& e : run.epochs) {
    stat.y.push_back(e.imu_statistic);
    thr.y.push_back(e.imu_threshold);
    sats.y.push_back(e.used);
  }
  imu.series = {stat, thr, sats};
  panels.push_back(imu);
  return renderTimeSeriesSvg("skylane simulate: " + s.source + " — position error and protection levels",
                             "time", t, panels);
}

void runSimulate(const SimulateOptions& o) {
  integrity::sim::Scenario s = integrity::sim::loadScenario(o.scenario);
  if (o.seed) s.seed = *o.seed;
  const integrity::OrbitSource orbits = integrity::sim::loadOrbits(s);
  std::filesystem::path out = o.out_dir.empty()
                                  ? std::filesystem::path(o.scenario).parent_path() /
                                        (std::filesystem::path(o.scenario).stem().string() + "_out")
                                  : std::filesystem::path(o.out_dir);
  maps::createOutputFolder(out.string(), "--out");
  maps::OutputSet outputs;
  const auto t0 = std::chrono::steady_clock::now();

  if (o.monte_carlo > 0) {
    const int threads = o.threads > 0 ? o.threads : std::max(1u, std::thread::hardware_concurrency());
    Progress bar("monte carlo", o.progress);
    const auto result = integrity::sim::monteCarlo(s, orbits, o.monte_carlo, threads,
                                                   [&bar](std::uint64_t d, std::uint64_t n) { bar(d, n); });
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("skylane: simulate: monte carlo: %llu runs, %llu epochs (%llu with a fault injected), %.1f s on %d threads\n",
                static_cast<unsigned long long>(result.runs), static_cast<unsigned long long>(result.epochs),
                static_cast<unsigned long long>(result.faulted_epochs), secs, threads);
    printCounts(result, std::cout);
    json j = countsJson(result);
    j["scenario"] = o.scenario;
    j["seed"] = s.seed;
    j["hal_m"] = s.hal_m;
    j["val_m"] = s.val_m;
    writeFile(outputs, out / "monte_carlo.json", j.dump(2) + "\n");
    if (!o.no_plots) {
      writeFile(outputs, out / "stanford_horizontal.svg", stanfordSvg(result, true, "Stanford diagram, horizontal — Monte Carlo"));
      writeFile(outputs, out / "stanford_vertical.svg", stanfordSvg(result, false, "Stanford diagram, vertical — Monte Carlo"));
    }
    outputs.commit();
    std::printf("skylane: simulate: wrote %s\n", out.string().c_str());
    return;
  }

  const integrity::sim::RunResult run = integrity::sim::runScenario(s, orbits, s.seed);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  integrity::sim::writeCsv(outputs.add((out / "epochs.csv").string(), "--out"), run);
  integrity::sim::MonteCarloResult single = integrity::sim::emptyMonteCarlo(s);
  integrity::sim::accumulate(run, single);
  std::printf("skylane: simulate: %s: %.0f s of flight, %zu GNSS epochs, %ld IMU samples in %.2f s (%.0f× real time)\n",
              o.scenario.c_str(), run.duration_s, run.epochs.size(), run.imu_steps, secs, run.duration_s / secs);
  // Whether each method's PL bounded the error at every epoch with a PL.
  for (int m = 0; m < kNumMethods; ++m) {
    double worst_h = 0, worst_v = 0;
    for (const auto& e : run.epochs) {
      const auto& x = e.methods[m];
      if (!x.available) continue;
      worst_h = std::max(worst_h, x.hpl_m > 0 ? x.hpe_m / x.hpl_m : 0.0);
      worst_v = std::max(worst_v, x.vpl_m > 0 ? x.vpe_m / x.vpl_m : 0.0);
    }
    const auto& h = single.methods[m].horizontal;
    const auto& v = single.methods[m].vertical;
    std::printf("  %-20s H: %s (max error/PL %.2f, %llu epochs without PL)  V: %s (max error/PL %.2f)\n",
                std::string(integrity::sim::methodName(static_cast<Method>(m))).c_str(),
                h.misleading == 0 ? "bounded" : "NOT bounded", worst_h, static_cast<unsigned long long>(h.no_pl),
                v.misleading == 0 ? "bounded" : "NOT bounded", worst_v);
  }
  if (!o.no_plots) {
    writeFile(outputs, out / "errors_and_pls.svg", curvesSvg(run, s));
    writeFile(outputs, out / "stanford_horizontal.svg", stanfordSvg(single, true, "Stanford diagram, horizontal — " + s.source));
    writeFile(outputs, out / "stanford_vertical.svg", stanfordSvg(single, false, "Stanford diagram, vertical — " + s.source));
  }
  outputs.commit();
  std::printf("skylane: simulate: wrote %s\n", out.string().c_str());
}

}  // namespace

void addSimulateCommands(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* c = app.add_subcommand(
      "simulate", "fly a GNSS/INS scenario with fault injection and score every integrity method against the truth");
  c->add_option("scenario", o->scenario, "scenario JSON file")->required()->check(CLI::ExistingFile);
  c->add_option("--out", o->out_dir, "output directory (default: <scenario>_out beside the scenario)");
  c->add_option("--seed", o->seed, "random seed (overrides the scenario's)");
  c->add_option("--monte-carlo", o->monte_carlo, "run this many randomised flights and print the counts");
  c->add_option("--threads", o->threads, "threads for --monte-carlo (default: all cores)");
  c->add_flag("--progress", o->progress, "show a progress bar even when stderr is not a terminal");
  c->add_flag("--no-plots", o->no_plots, "write no SVG files");
  c->callback([o]() { runSimulate(*o); });
}

}  // namespace skylane::cli
