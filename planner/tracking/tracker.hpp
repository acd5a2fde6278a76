#pragma once
/// \file
/// \brief Live corridor tracking (`skylane track`; docs/method.md §7.2): every fix of every
/// approved flight, with its live protection volume, is checked against its corridor (level 1),
/// its airspace (level 2), the active zones and the obstacles; a level-1 violation reruns the
/// integrity monitoring (FDE over the raw pseudoranges, when the fix has them); a persistent
/// violation, or a level-2, zone or obstacle violation, replans from where the vehicle is.
///
/// Per fix:
/// 1. Order: a fix not after the flight's last accepted one (duplicate or out of order), or more
///    than `max_time_jump_s` from it, is rejected (`rejected_input`), as is an unknown flight;
///    after a jump, `jump_confirm` fixes in order on the new timeline make it the flight's.
/// 2. Protection levels: raw pseudoranges with IMU increments, once the filter is aligned →
///    the fault-mode GNSS/INS flow (its FDE, filter and fault-mode PLs; track_fix.hpp); raw
///    pseudoranges → skylane's own position and PLs with the mission's method, first pass
///    detection only (integrity/raim/live_fix.hpp); else the onboard (or NMEA GST) PLs; an INS
///    σ block raises them to the three-hypothesis nominal-INS PL when that is larger.
/// 3. The fence check of the volume at the fix time (geofence::checkVolume).
/// 4. Level 1 not inside and raw pseudoranges → **monitoring rerun**: FDE, the PLs of the
///    remaining geometry, the check again; the fix's verdict is the rerun's. GNSS/INS: after a
///    detection, the epoch again from the filter as it was with one more exclusion allowed.
/// 5. Persistence: a level counts as violated in a fix when its check is not inside
///    (indeterminate counts). Level 1 is persistent when violated in ≥ level1_m of the last
///    level1_n fixes by a cause a replan can mend (step 6); level 2, zones and obstacles with
///    level2_m of level2_n (default 1 of 1: at once). A `violation` event marks a level's first violated fix; `recovered` follows
///    `recover_after` fixes in a row inside it.
/// 6. Replan from the vehicle's estimated position (Approver::replanFrom) when level 2, a zone or
///    an obstacle is persistently violated, or level 1 is persistently violated because of the
///    position — the PLs fit the corridor (HPL ≤ HAL₁, VPL ≤ VAL₁) but the volume is not in it:
///    the vehicle drifted. A level-1 violation by the PLs alone is not replanned unless
///    `replan_on_pl_exceedance`: no corridor of the same width can hold a PL wider than itself.
///    At most one replan per `replan_cooldown_s`. An approved replan replaces both box levels.
/// 7. `stale`: a flight without a fix for `stale_after_s` of stream time (once per gap), unless
///    its last fix was at its goal (it has arrived; nor is an arrived flight replanned). Stream
///    time is the latest accepted fix time on the stream's clock: a flight whose clock jumped
///    (step 1) keeps the jump as an offset, so one vehicle's clock cannot make the others stale.

#include "planner/approval.hpp"
#include "planner/report_formats.hpp"
#include "planner/tracking/flight_state.hpp"
#include "planner/tracking/track_event.hpp"
#include "planner/tracking/track_fix.hpp"

#include <nlohmann/json.hpp>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skylane::planner {

struct TrackedFlight;
struct FixWork;

/// \brief Hysteresis, persistence and timing of the tracker (the file comment's steps).
struct TrackerOptions {
  int level1_m = 3, level1_n = 5;
  int level2_m = 1, level2_n = 1;
  int recover_after = 2;
  bool replan = true;
  bool replan_on_pl_exceedance = false;
  double replan_cooldown_s = 10.0;
  double stale_after_s = 3.0;
  double max_time_jump_s = 300.0;
  int jump_confirm = 3;             ///< fixes in order on a jumped timeline before it is taken
  double waypoint_radius_m = 30.0;  ///< a mission waypoint is passed once a fix comes this close
  double horizon_m = 50.0;          ///< zones and obstacles this near a volume are listed in its fix event
  /// After a replan the next one waits until the vehicle has taken the new route: a link's
  /// acknowledgement (handoff_by_link), then a fix inside the new level-1 corridor — or this long.
  double join_timeout_s = 60.0;
  bool handoff_by_link = false;     ///< a link uploads each new route and reports the vehicle's answer
};

/// \brief Tracks many flights in one process.
class Tracker {
 public:
  explicit Tracker(TrackerOptions options = {});
  ~Tracker();
  Tracker(const Tracker&) = delete;
  Tracker& operator=(const Tracker&) = delete;

  /// \brief Registers a flight under `id` from its approval; `approver` holds the mission's zones,
  /// obstacles, orbits and planner (one may serve several flights of the same mission).
  /// \throws std::invalid_argument for a duplicate id, a rejected approval, or a route the
  /// corridor cannot be built from.
  void addFlight(const std::string& id, const ApprovedFlight& approval, std::shared_ptr<Approver> approver);
  /// \brief Loads an approval report, its mission (the report's `source`, as written or beside
  /// the report) and checks the mission's SHA-256 against the report's; the id is `id` or, when
  /// empty, the mission's name. Approvers are shared by mission file. Returns the id.
  /// \throws maps::ParseError naming the report, the field and what was expected.
  std::string addApprovalFile(const std::string& report_path, const std::string& id = {});
  /// \brief The same from the report's JSON (`report_path` names it in errors and places the
  /// mission beside it) — a restarted tracker takes its approvals from its database.
  std::string addApproval(const nlohmann::json& report, const std::string& report_path, const std::string& id = {});

  /// \brief Processes one fix; returns its events (the `fix` event last but for a replan).
  [[nodiscard]] std::vector<TrackEvent> process(const TrackFix& fix);
  /// \brief The same into `events` (its previous content replaced), whose storage is reused: a
  /// caller that keeps one list makes no allocation per fix once it has grown (but for a flight
  /// id longer than std::string keeps inline, and for events other than the `fix` event).
  void process(const TrackFix& fix, std::vector<TrackEvent>& events);
  /// \brief process() with the events as JSON.
  [[nodiscard]] std::vector<nlohmann::json> processJson(const TrackFix& fix);
  /// \brief A `rejected_input` event for a record that could not be read.
  [[nodiscard]] TrackEvent rejectedInput(const std::string& source, std::size_t line, const std::string& why) const;
  /// \brief `stale` events for flights silent for stale_after_s before `now` (stream time).
  [[nodiscard]] std::vector<TrackEvent> sweepStale(const maps::GpsTime& now);

  /// \brief The vehicle's answer to the upload of route `route_version` (handoff_by_link):
  /// acknowledged, the replan hold waits for it to join the route (join_timeout_s from `t`);
  /// refused or timed out, the hold ends and a persistent violation may replan again. An answer
  /// for another route version than the current one is ignored.
  void handoffResult(const std::string& id, int route_version, bool acknowledged, const maps::GpsTime& t);

  /// \brief The ids of the flights tracked.
  [[nodiscard]] std::vector<std::string> flights() const;
  /// \brief The single flight's id, or empty when there are several.
  [[nodiscard]] std::string onlyFlight() const;
  /// \brief A flight's state and current route (for persistence); restore() puts them back.
  [[nodiscard]] const FlightState& state(const std::string& id) const;
  [[nodiscard]] nlohmann::json routeJson(const std::string& id) const;
  /// \brief The flight's current route as route.geojson (line, points, both box levels).
  [[nodiscard]] nlohmann::json routeGeoJson(const std::string& id) const;
  void restore(const std::string& id, const FlightState& state, const nlohmann::json& route);
  /// \brief The approver (mission, map frame, zones and obstacles) of a flight.
  [[nodiscard]] const Approver& approver(const std::string& id) const;
  /// \brief Reads the zone files of a flight's mission again (Approver::reloadZones): the next
  /// fixes of every flight of that mission are judged against them.
  void reloadZones(const std::string& id);
  /// \brief The latest fix time over all flights (stream time).
  [[nodiscard]] std::optional<maps::GpsTime> streamTime() const { return stream_time_; }
  [[nodiscard]] const TrackerOptions& options() const { return options_; }

 private:
  /// The step that accepts a checked fix: stream time, the stale sweep, the flight's counters.
  void acceptFix(TrackedFlight& f, FixWork& w);
  /// The steps of process() for a known flight (the file comment's 1–6), into w.out.
  void runFixSteps(TrackedFlight& f, FixWork& w);
  TrackerOptions options_;
  std::map<std::string, std::unique_ptr<TrackedFlight>> flights_;
  std::map<std::string, std::shared_ptr<Approver>> approvers_;  ///< by mission file
  std::map<std::string, std::string> same_route_;  ///< TrackedFlight::routeKey → a flight with those boxes
  std::optional<maps::GpsTime> stream_time_;
  std::optional<maps::GpsTime> last_sweep_;
};

/// \brief The mission of an approval: the report's `source` as written, at `source_absolute`, or
/// beside the report, with the SHA-256 the report recorded.
/// \throws maps::ParseError naming the report when it is missing or has changed.
[[nodiscard]] std::string approvedMissionPath(const ApprovedFlight& plan, const std::string& report_path);

}  // namespace skylane::planner
