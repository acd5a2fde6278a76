#pragma once
/// \file
/// \brief The named steps of one fix in the tracking engine (internal to planner/tracking; the
/// order and the rules are tracker.hpp's file comment and docs/method.md §7). Tracker::process
/// is the orchestrator: each step reads and writes the FixWork passed along, and a step that
/// refuses the fix returns false with its `rejected_input` event in `out`.

#include "geofence/fence.hpp"
#include "integrity/ins/navigator.hpp"
#include "integrity/raim/live_fix.hpp"
#include "planner/tracking/track_event.hpp"
#include "planner/tracking/tracked_flight.hpp"

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace skylane::planner {

struct TrackerOptions;

/// \brief What the steps know of one fix so far.
struct FixWork {
  explicit FixWork(const TrackFix& f) : fix(f) {}
  const TrackFix& fix;
  std::vector<TrackEvent> out;  ///< the fix's events, in order
  // Order and time jumps.
  std::string jump_note;
  std::optional<double> new_offset;  ///< the flight's clock offset once a new timeline is taken
  // Protection levels and position.
  maps::Geodetic pos;
  std::optional<double> hpl_m, vpl_m;
  PlSource source = PlSource::kOnboard;
  std::optional<integrity::LiveFix> first;  ///< raw pseudoranges: the first pass (detection only)
  std::optional<integrity::ins::NavigatorEpoch> ins_epoch;  ///< GNSS/INS
  std::unique_ptr<integrity::ins::Navigator> ins_before;     ///< the filter before this epoch
  std::string note;
  std::vector<TrackEvent> pre_events;  ///< written once the fix is accepted
  bool early_rerun = false;            ///< GNSS/INS: rerun at once for a fault it could not exclude
  // Fence.
  geofence::TimedVolume volume;
  geofence::FenceVerdict verdict;
  // Monitoring rerun.
  bool rerun = false;
  std::vector<integrity::SatId> excluded;
  // Persistence.
  std::optional<geofence::Level> trigger;  ///< the level whose persistent violation asks for a replan
};

/// \brief The worst verdict of `level`'s checks (inside when it has none).
[[nodiscard]] geofence::Verdict worstVerdict(const geofence::FenceVerdict& v, geofence::Level level);

/// \brief A `rejected_input` event for `fix` of flight `id`.
[[nodiscard]] TrackEvent rejectedFix(const TrackFix& fix, const std::string& id, const std::string& why);

/// \brief Step 1: duplicates, fixes out of order, time jumps (taken after jump_confirm fixes in
/// order on the new timeline). `stream_time` is the tracker's.
[[nodiscard]] bool checkOrder(const TrackerOptions& o, TrackedFlight& f, FixWork& w,
                              const std::optional<maps::GpsTime>& stream_time);
/// \brief Step 2a: the GNSS/INS epoch of a fix with pseudoranges and IMU increments (with its
/// at-once rerun when a fault is detected and not excluded).
void runGnssInsEpoch(TrackedFlight& f, FixWork& w);
/// \brief Step 2b: skylane's own snapshot position and PLs from raw pseudoranges (first pass:
/// detection only), when the GNSS/INS epoch gave none; else the PLs the fix carries.
void solveSnapshot(TrackedFlight& f, FixWork& w);
/// \brief Step 2c: an onboard INS σ block raises the PLs to the three-hypothesis nominal INS PL.
void applyInsNominalPl(FixWork& w);
/// \brief Step 2d: refuses a fix left without protection levels.
[[nodiscard]] bool requireProtectionLevels(const TrackedFlight& f, FixWork& w);
/// \brief Step 3: the fence check of the protection volume at the fix time.
[[nodiscard]] bool checkFence(const TrackerOptions& o, const TrackedFlight& f, FixWork& w);
/// \brief Step 4: the monitoring rerun when level 1 is not held.
void rerunMonitoring(const TrackerOptions& o, TrackedFlight& f, FixWork& w);
/// \brief Step 5: per-level persistence windows, `violation` and `recovered` events, the trigger.
void updatePersistence(const TrackerOptions& o, TrackedFlight& f, FixWork& w);
/// \brief Step 6: progress along the mission's points and arrival at the goal.
void updateProgress(const TrackerOptions& o, TrackedFlight& f, const FixWork& w);
/// \brief Step 7: the `fix` event.
void writeFixEvent(const TrackedFlight& f, FixWork& w);
/// \brief Step 6b: a persistent violation does not replan while the vehicle has not yet taken
/// the current route (the link's answer awaited, or neither joined nor join_timeout_s over):
/// the fix's note says so. A fix inside the route's level-1 corridor ends the wait.
void holdReplanForHandoff(const TrackerOptions& o, TrackedFlight& f, FixWork& w);
/// \brief Step 8: the replan decision, and the replan from where the vehicle is.
void replanIfPersistent(const TrackerOptions& o, TrackedFlight& f, FixWork& w);

}  // namespace skylane::planner
