#include "cli/plan_commands.hpp"

#include "link/qgc_plan.hpp"
#include "maps/atomic_file.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"
#include "planner/report_formats.hpp"
#include "planner/tracking/tracker.hpp"

#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>
#include <string>

namespace skylane::cli {
namespace {

using maps::ParseError;
using nlohmann::json;

struct PlanExportOptions {
  std::string report;
  std::string out;
  std::string firmware = "generic";
};

/// MAVLink MAV_AUTOPILOT of a firmware name.
int firmwareType(const std::string& name) {
  if (name == "generic") return 0;   // MAV_AUTOPILOT_GENERIC
  if (name == "ardupilot") return 3;  // MAV_AUTOPILOT_ARDUPILOTMEGA
  if (name == "px4") return 12;       // MAV_AUTOPILOT_PX4
  throw ParseError("--firmware", 0, "--firmware", name, "generic, ardupilot or px4");
}

/// The report of a report file, or of a replan event (its `report` member).
json reportDocument(const std::string& path) {
  json doc = maps::readJsonFile(path);
  if (doc.is_object() && doc.value("event", "") == "replan") {
    if (!doc.contains("report")) throw ParseError(path, 0, "$.report", "", "the replan's approval report");
    return doc.at("report");
  }
  return doc;
}

void runPlanExport(const PlanExportOptions& o) {
  const json doc = reportDocument(o.report);
  // A rejected report has no route to fly: said before its (empty) route is read.
  if (doc.is_object() && doc.value("decision", "") == "rejected") {
    throw ParseError(o.report, 0, "$.decision", "rejected", "an approved route");
  }
  const planner::ApprovedFlight flight = planner::parseApprovalReport(doc, o.report);
  const planner::Approver approver(planner::loadMission(planner::approvedMissionPath(flight, o.report)));
  link::PlanVehicle vehicle;
  vehicle.firmware_type = firmwareType(o.firmware);
  const std::string text = link::qgcPlan(flight, approver, vehicle).dump(2) + "\n";
  if (o.out.empty()) {
    std::cout << text;
    return;
  }
  maps::writeFileAtomically(o.out, text, "--out");
  std::cerr << "skylane: plan export: wrote " << o.out << " (" << flight.route.size() << " route points)\n";
}

}  // namespace

void addPlanCommands(CLI::App& app) {
  CLI::App* plan = app.add_subcommand("plan", "route files for ground stations and autopilots");
  plan->require_subcommand(1);
  auto o = std::make_shared<PlanExportOptions>();
  CLI::App* c = plan->add_subcommand(
      "export", "write an approved route (report.json, or a replan event) as a QGroundControl plan: mission and geofence");
  c->add_option("report", o->report, "approval report JSON, or a replan event (JSON) from skylane track")
      ->required()
      ->check(CLI::ExistingFile);
  c->add_option("-o,--out", o->out, "the .plan file to write (default: stdout)");
  c->add_option("--firmware", o->firmware, "the plan's firmwareType: generic, ardupilot or px4 (default generic)");
  c->callback([o]() { runPlanExport(*o); });
}

}  // namespace skylane::cli
