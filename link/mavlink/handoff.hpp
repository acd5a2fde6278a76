#pragma once
/// \file
/// \brief The hand-off of a replanned route to a MAVLink vehicle (docs/vehicle_link.md §2.4).
/// Every accepted `replan` event of the tracked flight starts one: the new route (MISSION) and
/// then its geofence (FENCE) are uploaded with the mission protocol over the link the telemetry
/// comes in on, and `handoff` events say what happened:
///
///   {"event": "handoff", "flight", "time", "route_version", "mission_type": "mission"|"fence",
///    "state": "sent"|"acknowledged"|"refused"|"timed_out", "items", ["result"], ["resends"]}
///
/// The vehicle's answer to the MISSION upload goes to the tracker (Tracker::handoffResult): an
/// acknowledgement starts the wait for the vehicle to join the route; a refusal or a timeout
/// ends the replan hold. A newer replan supersedes an upload still running.

#include "link/mavlink/fix_source.hpp"
#include "link/mavlink/mission_upload.hpp"
#include "link/qgc_plan.hpp"
#include "planner/tracking/event_sink.hpp"
#include "planner/tracking/tracker.hpp"

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace skylane::link::mavlink {

struct HandoffOptions {
  LinkIds ids;           ///< target_system is taken from the vehicle's HEARTBEAT when it has sent one
  UploadTiming timing;
  PlanVehicle vehicle;   ///< the plan's firmware and vehicle type
};

class MavlinkHandoff final : public planner::EventSink {
 public:
  MavlinkHandoff(MavlinkFixSource& source, planner::Tracker& tracker, HandoffOptions options = {});
  /// \brief Sees the session's events: an accepted replan starts a hand-off.
  void write(const planner::TrackEvent& event, const std::string& json_line) override;
  /// \brief The session's ticker: the vehicle's mission frames in, timers, the events out.
  [[nodiscard]] std::vector<planner::TrackEvent> tick();

 private:
  struct Job {
    std::string flight;
    int route_version = 0;
    std::vector<MissionUpload> uploads;  ///< MISSION, then FENCE
    std::size_t current = 0;
  };
  /// Starts the job's current upload; its `sent` event.
  planner::TrackEvent startCurrent(Job& job, double now_s);
  /// The event of an upload that has ended, and the tracker told of a MISSION answer.
  planner::TrackEvent finished(const Job& job, const MissionUpload& up);
  planner::TrackEvent event(const Job& job, const MissionUpload& up, const char* state) const;
  void send(const std::vector<std::vector<std::uint8_t>>& frames);
  [[nodiscard]] double now() const;

  MavlinkFixSource& source_;
  planner::Tracker& tracker_;
  HandoffOptions options_;
  std::optional<Job> job_;
  bool job_started_ = false;
  std::uint8_t seq_ = 0;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

}  // namespace skylane::link::mavlink
