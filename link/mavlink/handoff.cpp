#include "link/mavlink/handoff.hpp"

#include "planner/report_formats.hpp"

namespace skylane::link::mavlink {

MavlinkHandoff::MavlinkHandoff(MavlinkFixSource& source, planner::Tracker& tracker, HandoffOptions options)
    : source_(source), tracker_(tracker), options_(options) {}

double MavlinkHandoff::now() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }

void MavlinkHandoff::write(const planner::TrackEvent& e, const std::string&) {
  if (!e.is("replan") || e.body.value("decision", "") != "approved" || !e.body.contains("report")) return;
  // The new route as a plan: its mission items and its fence (the same file `plan export` writes).
  const planner::ApprovedFlight flight = planner::parseApprovalReport(e.body.at("report"), "replan of " + e.flight);
  const nlohmann::json plan = qgcPlan(flight, tracker_.approver(e.flight), options_.vehicle);
  LinkIds ids = options_.ids;
  if (source_.vehicle().sysid) {
    ids.target_system = *source_.vehicle().sysid;
    ids.target_component = source_.vehicle().compid;
  }
  Job job;
  job.flight = e.flight;
  job.route_version = e.body.value("route_version", 0);
  job.uploads.emplace_back(MissionType::kMission, missionItemsOfPlan(plan), ids, options_.timing);
  job.uploads.emplace_back(MissionType::kFence, fenceItemsOfPlan(plan), ids, options_.timing);
  job_ = std::move(job);  // a newer route supersedes an upload still running
  job_started_ = false;
}

void MavlinkHandoff::send(const std::vector<std::vector<std::uint8_t>>& frames) {
  for (const std::vector<std::uint8_t>& f : frames) (void)source_.link().write(f.data(), f.size());
}

planner::TrackEvent MavlinkHandoff::event(const Job& job, const MissionUpload& up, const char* state) const {
  planner::TrackEvent e = planner::trackEvent("handoff", job.flight, tracker_.streamTime().value_or(maps::GpsTime{}));
  e["route_version"] = job.route_version;
  e["mission_type"] = missionTypeName(up.type());
  e["state"] = state;
  e["items"] = up.items();
  return e;
}

planner::TrackEvent MavlinkHandoff::startCurrent(Job& job, double now_s) {
  MissionUpload& up = job.uploads[job.current];
  send(up.start(now_s, seq_));
  return event(job, up, "sent");
}

planner::TrackEvent MavlinkHandoff::finished(const Job& job, const MissionUpload& up) {
  const bool accepted = up.state() == MissionUpload::State::kAccepted;
  planner::TrackEvent e =
      event(job, up, accepted ? "acknowledged" : (up.state() == MissionUpload::State::kRefused ? "refused" : "timed_out"));
  if (up.state() != MissionUpload::State::kTimedOut) e["result"] = missionResultName(up.result());
  e["resends"] = up.resends();
  if (up.type() == MissionType::kMission) {
    tracker_.handoffResult(job.flight, job.route_version, accepted, tracker_.streamTime().value_or(maps::GpsTime{}));
  }
  return e;
}

std::vector<planner::TrackEvent> MavlinkHandoff::tick() {
  std::vector<planner::TrackEvent> out;
  std::deque<Frame> frames = source_.takeOtherFrames();
  if (!job_) return out;
  const double t = now();
  if (!job_started_) {
    job_started_ = true;
    out.push_back(startCurrent(*job_, t));
  }
  MissionUpload* up = &job_->uploads[job_->current];
  for (const Frame& fr : frames) send(up->onFrame(fr, t, seq_));
  send(up->poll(t, seq_));
  if (!up->done()) return out;
  out.push_back(finished(*job_, *up));
  // The fence follows an accepted route; a refused or lost route ends the hand-off.
  if (up->state() == MissionUpload::State::kAccepted && job_->current + 1 < job_->uploads.size()) {
    ++job_->current;
    out.push_back(startCurrent(*job_, t));
  } else {
    job_.reset();
  }
  return out;
}

}  // namespace skylane::link::mavlink
