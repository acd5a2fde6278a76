#include "cli/approve_commands.hpp"

#include "cli/svg_plot.hpp"
#include "cli/zones_commands.hpp"
#include "maps/atomic_file.hpp"
#include "maps/file_digest.hpp"
#include "planner/approval.hpp"
#include "link/qgc_plan.hpp"
#include "planner/operational_intent.hpp"
#include "planner/report_formats.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
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

}  // namespace

std::vector<MapShape> obstructionShapes(const geofence::Obstructions& ob, const maps::PlaneFrame& frame) {
  std::vector<MapShape> shapes;
  for (std::size_t i = 0; i < ob.zones().size(); ++i) {
    const airspace::Zone& z = ob.zones()[i];
    const bool counted = ob.zoneCounts(i);
    const bool timed = std::any_of(z.applicability.begin(), z.applicability.end(), [](const airspace::Applicability& ap) {
      return !ap.permanent || ap.start || ap.end || !ap.schedule.empty();
    });
    for (const airspace::Volume& v : z.volumes) {
      MapShape sh;
      if (v.outline.kind == airspace::Outline::Kind::kCircle) {
        const Eigen::Vector2d c = frame.toPlane(v.outline.centre.lat_rad, v.outline.centre.lon_rad);
        for (int k = 0; k < 72; ++k) {
          const double t = 2.0 * M_PI * k / 72.0;
          sh.xy.emplace_back(c.x() + v.outline.radius_m * std::cos(t), c.y() + v.outline.radius_m * std::sin(t));
        }
      } else {
        for (const airspace::LatLon& p : v.outline.ring) {
          const Eigen::Vector2d q = frame.toPlane(p.lat_rad, p.lon_rad);
          sh.xy.emplace_back(q.x(), q.y());
        }
      }
      sh.fill = counted ? (timed ? "#ff7f0e" : "#d62728") : "#2ca02c";
      sh.stroke = sh.fill;
      sh.fill_opacity = 0.18;
      sh.dashed = timed;
      sh.legend = counted ? (timed ? "zone, time-limited" : "zone, prohibited / not authorised") : "zone, authorised or open";
      if (z.keep_in) {  // a boundary to stay within: an outline, not an area to avoid
        sh.fill = "none";
        sh.stroke = "#6a3d9a";
        sh.stroke_width_px = 2.5;
        sh.legend = timed ? "keep-in fence, time-limited (stay inside)" : "keep-in fence (stay inside)";
      }
      shapes.push_back(std::move(sh));
    }
  }
  for (const maps::Building& b : ob.buildings()) {
    MapShape sh;
    for (const auto& [lat, lon] : b.ring_lat_lon_rad) {
      const Eigen::Vector2d q = frame.toPlane(lat, lon);
      sh.xy.emplace_back(q.x(), q.y());
    }
    sh.fill = "#7f7f7f";
    sh.stroke = "#555555";
    sh.fill_opacity = 0.5;
    sh.legend = "building";
    shapes.push_back(std::move(sh));
  }
  return shapes;
}

namespace {

std::string mapSvg(const planner::ApprovalReport& r, const planner::Approver& a) {
  const maps::PlaneFrame& frame = a.frame();
  std::vector<MapShape> shapes = obstructionShapes(a.obstructions(), frame);
  for (int level : {2, 1}) {
    const double hal = level == 1 ? r.limits.level1.hal_m : r.limits.level2.hal_m;
    for (std::size_t i = 1; i < r.route.size(); ++i) {
      MapShape sh;
      for (const Eigen::Vector2d& v : planner::segmentOutline(r.route[i - 1].xyz, r.route[i].xyz, hal)) {
        sh.xy.emplace_back(v.x(), v.y());
      }
      sh.fill = level == 1 ? "#1f77b4" : "#aec7e8";
      sh.stroke = sh.fill;
      sh.fill_opacity = level == 1 ? 0.5 : 0.15;
      sh.legend = level == 1 ? "corridor (level 1)" : "airspace (level 2)";
      shapes.push_back(std::move(sh));
    }
  }
  std::vector<MapLine> lines;
  MapLine route;
  route.stroke = "#000000";
  route.legend = "route";
  for (const planner::RoutePoint& p : r.route) route.xy.emplace_back(p.xyz.x(), p.xyz.y());
  if (!route.xy.empty()) lines.push_back(route);
  std::vector<MapMarker> markers;
  const auto& pts = a.mission().points;
  const Eigen::Vector2d s0 = frame.toPlane(pts.front().lat_rad, pts.front().lon_rad);
  const Eigen::Vector2d g0 = frame.toPlane(pts.back().lat_rad, pts.back().lon_rad);
  markers.push_back({s0.x(), s0.y(), "start", "#2ca02c"});
  markers.push_back({g0.x(), g0.y(), "goal", "#d62728"});
  for (const planner::Reason& x : r.reasons) {
    if (!x.lat_rad || !x.lon_rad) continue;
    const Eigen::Vector2d q = frame.toPlane(*x.lat_rad, *x.lon_rad);
    markers.push_back({q.x(), q.y(), x.kind + ": " + x.subject, "#9467bd"});
  }
  std::vector<std::string> footer{
      std::string(r.approved ? "APPROVED" : "REJECTED") + ", departure " + maps::formatRfc3339(r.departure) + ", route " +
      std::to_string(static_cast<int>(std::round(r.planner.length_m))) + " m, planner " + r.planner.algorithm};
  for (const planner::Reason& x : r.reasons) footer.push_back(x.message);
  return renderPlanMapSvg("skylane approve: " + (a.mission().name.empty() ? a.mission().source : a.mission().name), shapes,
                          lines, markers, 250.0, footer);
}

/// How far above the larger level-1 limit the level-1 panel reaches before PLs are drawn on
/// its top edge: the limits stay a third of the panel high however large the PLs are.
constexpr double kLevel1PanelCap = 3.0;

/// One level's panel: HPL and VPL against that level's HAL and VAL.
Panel levelPanel(const planner::ApprovalReport& r, int level) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const geofence::AlertLimits& lim = level == 1 ? r.limits.level1 : r.limits.level2;
  const std::string n = level == 1 ? "₁" : "₂";
  Series hpl{"HPL", "#d62728", {}, false, false}, vpl{"VPL", "#1f77b4", {}, false, false};
  Series hal{"HAL" + n + " (level " + std::to_string(level) + ")", "#ff7f0e", {}, true, false};
  Series val{"VAL" + n + " (level " + std::to_string(level) + ")", "#17becf", {}, true, false};
  for (const planner::PredictedSample& s : r.predicted) {
    hpl.y.push_back(s.pl_available ? s.hpl_m : nan);
    vpl.y.push_back(s.pl_available ? s.vpl_m : nan);
    hal.y.push_back(lim.hal_m);
    val.y.push_back(lim.val_m);
  }
  const planner::LevelAvailability& a = level == 1 ? r.level1_availability : r.level2_availability;
  Panel p{"level " + std::to_string(level) + ": PL [m], held " + planner::availabilityPercent(a.fraction), {hpl, vpl, hal, val},
          level == 1 ? 240.0 : 200.0};
  if (level == 1) p.y_cap = kLevel1PanelCap * std::max(lim.hal_m, lim.val_m);
  return p;
}

/// pl.svg: level 1 (the corridor, PLs above 3 × its limits on the top edge), level 2 (the
/// airspace), and the satellites; the title names the mission, the decision and the departure.
std::string plSvg(const planner::ApprovalReport& r, const planner::Mission& m) {
  std::vector<double> t;
  Series sats{"satellites", "#2ca02c", {}, false, true}, blocked{"hidden by buildings/terrain", "#7f7f7f", {}, false, true};
  for (const planner::PredictedSample& s : r.predicted) {
    t.push_back(s.t_s);
    sats.y.push_back(s.satellites);
    blocked.y.push_back(s.blocked);
  }
  Panel sv{"satellites", {sats, blocked}, 140};
  return renderTimeSeriesSvg("skylane approve: " + (m.name.empty() ? m.source : m.name) + " — " +
                                 (r.approved ? "approved" : "rejected") + ", departure " + maps::formatRfc3339(r.departure) +
                                 ", navigation " + planner::navigationKindName(m.navigation.kind),
                             "time after departure", t, {levelPanel(r, 1), levelPanel(r, 2), sv});
}

/// The --out folder's files into the staged outputs (report.json, pl.svg, map.svg,
/// route.geojson added before the approval, in that order), committed together.
void writeApprovalFiles(maps::OutputSet& outputs, const std::filesystem::path& dir, const planner::ApprovalReport& r,
                        const json& j, const planner::Approver& approver) {
  outputs.stream(0) << j.dump(2) << "\n";
  outputs.stream(1) << plSvg(r, approver.mission());
  outputs.stream(2) << mapSvg(r, approver);
  outputs.stream(3) << planner::routeGeoJson(r, approver.mission(), approver.frame()).dump(1) << "\n";
  // An operational intent is only for an approved route (F3548 state "Accepted"); a rejection
  // deletes those of an earlier approval.
  if (r.approved) {
    outputs.add((dir / "operational_intent.json").string(), "--out")
        << json(planner::operationalIntent(r, approver.frame())).dump(1) << "\n";
    // The route and its fence for a ground station (QGroundControl) to upload to the vehicle,
    // made from the report as written (so that `plan export report.json` gives the same file).
    outputs.add((dir / "mission.plan").string(), "--out") << link::qgcPlan(j.get<planner::ApprovedFlight>(), approver).dump(2) << "\n";
  } else {
    outputs.removeOnCommit((dir / "operational_intent.json").string());
    outputs.removeOnCommit((dir / "mission.plan").string());
  }
  outputs.commit();
}

void runApprove(const ApproveOptions& o) {
  planner::Approver approver(planner::loadMission(o.mission));
  // The outputs are staged before the approval (a folder that cannot be written fails at once)
  // and replace earlier ones only once every file is written (maps/atomic_file.hpp).
  maps::OutputSet outputs;
  const std::filesystem::path dir(o.out_dir);
  if (!o.out_dir.empty()) {
    maps::createOutputFolder(o.out_dir, "--out");
    for (const char* name : {"report.json", "pl.svg", "map.svg", "route.geojson"}) outputs.add((dir / name).string(), "--out");
  }
  const bool show = o.progress || isatty(STDERR_FILENO);
  const planner::ApprovalReport r = approver.approve([show](const std::string& s) {
    if (show) std::cerr << "skylane: approve: " << s << "\n";
  });
  const json j = r;
  if (!o.out_dir.empty()) writeApprovalFiles(outputs, dir, r, j, approver);
  std::cout << j.dump(2) << "\n";
  for (const std::string& w : r.warnings) std::cerr << "skylane: warning: " << w << "\n";
  char elapsed[32];
  std::snprintf(elapsed, sizeof elapsed, "%.2f", r.elapsed_s);
  std::cerr << "skylane: approve: " << planner::approvalSummary(r) << " (in " << elapsed << " s)";
  if (r.planner.stopped_by_time) {
    std::cerr << " (the planner's time limit ended a search before its iteration budget: this route is not reproducible)";
  }
  std::cerr << "\n";
  if (!r.approved) throw ExitStatus(1);
}

}  // namespace

void addApproveCommands(CLI::App& app) {
  auto o = std::make_shared<ApproveOptions>();
  CLI::App* c = app.add_subcommand("approve",
                                   "plan a route around active zones, predict its protection levels and approve or reject it");
  c->add_option("mission", o->mission, "mission JSON file")->required()->check(CLI::ExistingFile);
  c->add_option("--out", o->out_dir,
                 "also write report.json, route.geojson, map.svg and pl.svg into this directory, and for an approved "
                 "route operational_intent.json (ASTM F3548 Volume4D) and mission.plan (QGroundControl plan)");
  c->add_flag("--progress", o->progress, "print the steps even when stderr is not a terminal");
  c->callback([o]() { runApprove(*o); });
}

}  // namespace skylane::cli
