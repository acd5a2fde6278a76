#pragma once
/// \file
/// \brief One flight inside the tracking engine (internal to planner/tracking): its approval,
/// both box levels built from its current route, its state, and its GNSS/INS filter.

#include "geofence/corridor.hpp"
#include "integrity/ins/navigator.hpp"
#include "integrity/raim/live_fix.hpp"
#include "planner/approval.hpp"
#include "planner/report_formats.hpp"
#include "planner/tracking/flight_state.hpp"
#include "planner/tracking/track_fix.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace skylane::planner {

/// \brief A tracked flight.
struct TrackedFlight {
  std::string id;
  ApprovedFlight plan;
  std::shared_ptr<Approver> approver;
  /// Shared by the flights of one approval until one of them is replanned (many vehicles may fly
  /// the same approved route: the boxes are built once).
  std::shared_ptr<const geofence::Corridor> level1, level2;
  std::vector<Eigen::Vector3d> stops;  ///< the mission's points (map frame)
  integrity::LiveFixConfig live;
  FlightState st;
  // GNSS/INS (the fault-mode flow) for fixes with IMU increments. Not persisted: a restarted
  // tracker aligns the filter again at the next fix with velocity and attitude.
  std::unique_ptr<integrity::ins::Navigator> nav;
  int nav_grade = -1;
  maps::GpsTime nav_t0, nav_time;

  /// \brief The flight's GNSS/INS epoch for a fix with IMU increments, when the filter is aligned
  /// and the increments continue it (they must span the time since its last epoch; else it
  /// aligns again and `note` says why). `before` keeps the filter as it was, for a rerun.
  std::optional<integrity::ins::NavigatorEpoch> insEpoch(const TrackFix& fix, std::string& note,
                                                         std::unique_ptr<integrity::ins::Navigator>& before);
  /// \brief The fix's epoch again from the filter as it was (`before`), with one more exclusion
  /// allowed (the monitoring rerun of the GNSS/INS flow); when it gives a PL the filter takes it.
  std::optional<integrity::ins::NavigatorEpoch> deeperEpoch(const integrity::ins::Navigator& before, const TrackFix& fix);
  /// \brief Aligns the filter at a snapshot solution with the fix's velocity and attitude.
  void align(const TrackFix& fix, const integrity::LiveFix& snap, std::string& note);
  /// \brief Both box levels around the current route (and each route point's map position);
  /// `same_route`'s boxes when it is given (a flight of the same approver and route).
  void buildBoxes(const TrackedFlight* same_route = nullptr);
  /// \brief What makes two flights' boxes the same: the approver and the route, exactly.
  [[nodiscard]] std::string routeKey() const;

 private:
  /// One epoch of `n`: the fix's IMU increments, then its pseudoranges and aiding.
  integrity::ins::NavigatorEpoch runInsEpoch(integrity::ins::Navigator& n, const TrackFix& fix) const;
};

}  // namespace skylane::planner
