#include "link/plan_file_sink.hpp"

#include "maps/atomic_file.hpp"
#include "planner/report_formats.hpp"

#include <cctype>
#include <filesystem>

namespace skylane::link {

PlanFileSink::PlanFileSink(std::string dir, const planner::Tracker& tracker, Log log)
    : dir_(std::move(dir)), tracker_(tracker), log_(std::move(log)) {
  maps::createOutputFolder(dir_, "");
}

void PlanFileSink::write(const planner::TrackEvent& e, const std::string&) {
  if (!e.is("replan") || e.body.value("decision", "") != "approved" || !e.body.contains("report")) return;
  std::string name = e.flight;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  }
  const std::filesystem::path path =
      std::filesystem::path(dir_) / (name + "-route" + std::to_string(e.body.value("route_version", 0)) + ".plan");
  const planner::ApprovedFlight flight = planner::parseApprovalReport(e.body.at("report"), "replan of " + e.flight);
  maps::writeFileAtomically(path.string(), qgcPlan(flight, tracker_.approver(e.flight)).dump(2) + "\n", "");
  if (log_) log_("wrote " + path.string());
}

}  // namespace skylane::link
