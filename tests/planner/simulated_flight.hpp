#pragma once
// A simulated flight along an approved route (planner/rehearsal/flight_sim.hpp) for the tracking
// tests and bench/bench_track.cpp, from an approval report.

#include "planner/approval.hpp"
#include "planner/rehearsal/flight_sim.hpp"

#include <optional>
#include <string>
#include <vector>

namespace skylane::test {

using planner::ImuFeed;
using planner::SimulatedFix;

/// The report's route flown with `faults` from `seed`; see planner::FlightSimOptions.
inline std::vector<SimulatedFix> simulateRoute(const planner::ApprovalReport& r, const planner::Approver& a,
                                               const std::vector<integrity::sim::FaultSpec>& faults, std::uint64_t seed,
                                               double reported_dh_m = 0.0, const std::string& flight = "F1",
                                               const std::optional<ImuFeed>& imu = std::nullopt) {
  planner::FlightSimOptions o;
  o.flight = flight;
  o.seed = seed;
  o.reported_dh_m = reported_dh_m;
  o.faults = faults;
  o.imu = imu;
  return planner::simulateFlight(r, a, o);
}

}  // namespace skylane::test
