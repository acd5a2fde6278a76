#include "cli/approve_commands.hpp"

#include "cli/json_numbers.hpp"
#include "cli/svg_plot.hpp"
#include "cli/zones_commands.hpp"
#include "planner/approval.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>

namespace skylane::cli {
namespace {

using nlohmann::json;

struct ApproveOptions {
  std::string mission;
  std::string out_dir;
  bool progress = false;
};

double deg(double rad) { return std::round(maps::rad2deg(rad) * 1e7) / 1e7; }

json reasonJson(const planner::Reason& r, const maps::GpsTime& dep) {
  json j;
  j["kind"] = r.kind;
  j["subject"] = r.subject;
  j["message"] = r.message;
  if (r.t_s) j["time"] = maps::formatRfc3339(dep.plus(*r.t_s), 1);
  if (r.lat_rad) j["lat"] = deg(*r.lat_rad);
  if (r.lon_rad) j["lon"] = deg(*r.lon_rad);
  if (r.h_ell_m) j["h_ell_m"] = roundToMm(*r.h_ell_m);
  if (r.value_m) j["value_m"] = roundToMm(*r.value_m);
  if (r.limit_m) j["limit_m"] = roundToMm(*r.limit_m);
  return j;
}

json reportJson(const planner::ApprovalReport& r, const planner::Mission& m) {
  json j;
  j["mission"] = m.name;
  j["source"] = m.source;
  j["decision"] = r.approved ? "approved" : "rejected";
  j["reasons"] = json::array();
  for (const planner::Reason& x : r.reasons) j["reasons"].push_back(reasonJson(x, r.departure));
  j["departure"] = maps::formatRfc3339(r.departure);
  if (r.earliest_passing_departure) j["earliest_passing_departure"] = maps::formatRfc3339(*r.earliest_passing_departure);
  json route = json::array();
  for (const planner::RoutePoint& p : r.route) {
    route.push_back({{"lat", deg(p.lat_rad)},
                     {"lon", deg(p.lon_rad)},
                     {"h_ell_m", roundToMm(p.h_ell_m)},
                     {"alt_amsl_m", roundToMm(p.alt_amsl_m)},
                     {"eta", maps::formatRfc3339(r.departure.plus(p.eta_s), 1)},
                     {"eta_s", roundToMm(p.eta_s)}});
  }
  j["route"] = route;
  j["corridor"] = {{"level", 1}, {"hal_m", roundToMm(r.limits.level1.hal_m)}, {"val_m", roundToMm(r.limits.level1.val_m)},
                   {"k", m.levels.k1}, {"centre_line", "route"}};
  j["airspace"] = {{"level", 2}, {"hal_m", roundToMm(r.limits.level2.hal_m)}, {"val_m", roundToMm(r.limits.level2.val_m)},
                   {"k", m.levels.k2}, {"centre_line", "route"}};
  json predicted = json::array();
  for (const planner::PredictedSample& s : r.predicted) {
    json p{{"time", maps::formatRfc3339(r.departure.plus(s.t_s), 1)},
           {"lat", deg(s.lat_rad)},
           {"lon", deg(s.lon_rad)},
           {"h_ell_m", roundToMm(s.h_ell_m)},
           {"satellites", s.satellites},
           {"blocked", s.blocked},
           {"hpl_m", s.pl_available ? json(roundToMm(s.hpl_m)) : json(nullptr)},
           {"vpl_m", s.pl_available ? json(roundToMm(s.vpl_m)) : json(nullptr)},
           {"hal1_m", roundToMm(r.limits.level1.hal_m)},
           {"val1_m", roundToMm(r.limits.level1.val_m)},
           {"hal2_m", roundToMm(r.limits.level2.hal_m)},
           {"val2_m", roundToMm(r.limits.level2.val_m)}};
    for (const geofence::Check& c : s.fence.checks) {
      if (c.level == geofence::Level::kAirspace) {
        p["margin_h_m"] = roundToMm(c.margin_h_m);
        p["margin_v_m"] = roundToMm(c.margin_v_m);
      }
    }
    predicted.push_back(p);
  }
  j["predicted"] = predicted;
  j["level1_exceedances"] = r.level1_exceedances;
  json zones = json::array();
  for (const planner::ZoneApproach& z : r.zones) {
    zones.push_back({{"id", z.identifier}, {"restriction", z.restriction}, {"counted", z.counted},
                     {"min_clearance_m", roundToMm(z.min_clearance_m)}});
  }
  j["zones"] = zones;
  j["planner"] = {{"algorithm", r.planner.algorithm},
                  {"status", r.planner.status},
                  {"straight_line", r.planner.straight_line},
                  {"planning_time_s", std::round(r.planner.planning_time_s * 1e4) / 1e4},
                  {"length_m", roundToMm(r.planner.length_m)},
                  {"attempts", r.planner.attempts},
                  {"departures_tried", r.planner.departures_tried},
                  {"seed", m.seed}};
  j["elapsed_s"] = std::round(r.elapsed_s * 1e3) / 1e3;
  return j;
}

std::string plSvg(const planner::ApprovalReport& r, const planner::Mission& m) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> t;
  Series hpl{"HPL", "#d62728", {}, false, false}, vpl{"VPL", "#1f77b4", {}, false, false};
  Series hal2{"HAL₂ (level 2)", "#d62728", {}, true, false}, val2{"VAL₂ (level 2)", "#1f77b4", {}, true, false};
  Series hal1{"HAL₁ (level 1)", "#ff9896", {}, true, false}, val1{"VAL₁ (level 1)", "#aec7e8", {}, true, false};
  Series sats{"satellites", "#2ca02c", {}, false, true}, blocked{"hidden by buildings/terrain", "#7f7f7f", {}, false, true};
  for (const planner::PredictedSample& s : r.predicted) {
    t.push_back(s.t_s);
    hpl.y.push_back(s.pl_available ? s.hpl_m : nan);
    vpl.y.push_back(s.pl_available ? s.vpl_m : nan);
    hal2.y.push_back(r.limits.level2.hal_m);
    val2.y.push_back(r.limits.level2.val_m);
    hal1.y.push_back(r.limits.level1.hal_m);
    val1.y.push_back(r.limits.level1.val_m);
    sats.y.push_back(s.satellites);
    blocked.y.push_back(s.blocked);
  }
  Panel pl{"protection level [m]", {hpl, vpl, hal2, val2, hal1, val1}, 300};
  Panel sv{"satellites", {sats, blocked}, 160};
  return renderTimeSeriesSvg("skylane approve: " + (m.name.empty() ? m.source : m.name) + " — " +
                                 (r.approved ? "approved" : "rejected") + ", departure " + maps::formatRfc3339(r.departure),
                             "time after departure", t, {pl, sv});
}

void runApprove(const ApproveOptions& o) {
  planner::Approver approver(planner::loadMission(o.mission));
  const bool show = o.progress || isatty(STDERR_FILENO);
  const planner::ApprovalReport r = approver.approve([show](const std::string& s) {
    if (show) std::cerr << "skylane: approve: " << s << "\n";
  });
  const json j = reportJson(r, approver.mission());
  if (!o.out_dir.empty()) {
    std::filesystem::create_directories(o.out_dir);
    std::ofstream(std::filesystem::path(o.out_dir) / "report.json") << j.dump(2) << "\n";
    std::ofstream(std::filesystem::path(o.out_dir) / "pl.svg") << plSvg(r, approver.mission());
  }
  std::cout << j.dump(2) << "\n";
  std::cerr << "skylane: approve: " << (r.approved ? "APPROVED" : "REJECTED") << " in " << r.elapsed_s << " s";
  if (!r.reasons.empty()) std::cerr << ": " << r.reasons.front().message;
  std::cerr << "\n";
  if (!r.approved) throw ExitStatus(1);
}

}  // namespace

void addApproveCommands(CLI::App& app) {
  auto o = std::make_shared<ApproveOptions>();
  CLI::App* c = app.add_subcommand("approve",
                                   "plan a route around active zones, predict its protection levels and approve or reject it");
  c->add_option("mission", o->mission, "mission JSON file")->required()->check(CLI::ExistingFile);
  c->add_option("--out", o->out_dir, "also write report.json and pl.svg into this directory");
  c->add_flag("--progress", o->progress, "print the steps even when stderr is not a terminal");
  c->callback([o]() { runApprove(*o); });
}

}  // namespace skylane::cli
