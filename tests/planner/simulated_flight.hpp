#pragma once
// A simulated flight along an approved route (seed 001's sensor simulator: real orbits, the
// ARAIM error model, fault injection) turned into tracker fixes with raw pseudoranges — for the
// tracking tests and bench/bench_track.cpp.

#include "integrity/sim/sensors.hpp"
#include "integrity/sim/trajectory.hpp"
#include "planner/approval.hpp"
#include "planner/tracking/track_fix.hpp"

#include <optional>
#include <vector>

namespace skylane::test {

/// One GNSS epoch of the flight as a fix, with what the simulator injected.
struct SimulatedFix {
  planner::TrackFix fix;
  std::optional<integrity::SatId> faulty;  ///< the satellite carrying an injected bias, if any
  double t_s = 0.0;                        ///< after departure
};

/// The approved route flown at the mission's cruise speed (30 m turn radius), one fix per GNSS
/// epoch named `flight`, the reported position the truth raised by `reported_dh_m` (it only
/// starts skylane's own solution), every pseudorange with its satellite position.
inline std::vector<SimulatedFix> simulateRoute(const planner::ApprovalReport& r, const planner::Approver& a,
                                               const std::vector<integrity::sim::FaultSpec>& faults, std::uint64_t seed,
                                               double reported_dh_m = 0.0, const std::string& flight = "F1") {
  const maps::Geodetic origin{r.route.front().lat_rad, r.route.front().lon_rad, r.route.front().h_ell_m};
  const maps::LocalFrame enu(origin);
  std::vector<integrity::sim::Waypoint> wps;
  for (const planner::RoutePoint& p : r.route) wps.push_back({enu.toEnu({p.lat_rad, p.lon_rad, p.h_ell_m}), a.mission().cruise_speed_mps});
  const integrity::sim::Trajectory traj(origin, wps, 30.0);
  integrity::sim::SensorSpec spec;
  spec.model = a.mission().model;
  integrity::sim::SensorSimulator sim(traj, a.orbits(), r.departure, spec, faults, seed);
  std::vector<SimulatedFix> out;
  while (sim.running()) {
    (void)sim.stepImu();
    if (!sim.gnssDue()) continue;
    const integrity::sim::GnssEpoch ep = sim.gnss();
    SimulatedFix s;
    s.t_s = ep.t_s;
    s.fix.flight = flight;
    s.fix.time = ep.time;
    s.fix.lat_rad = sim.truth().geodetic.lat_rad;
    s.fix.lon_rad = sim.truth().geodetic.lon_rad;
    s.fix.h_ell_m = sim.truth().geodetic.h_ell_m + reported_dh_m;
    for (const integrity::sim::Pseudorange& pr : ep.ranges) {
      s.fix.ranges.push_back({pr.sat, pr.pseudorange_m, pr.sat_ecef_m});
      if (pr.injected_m != 0.0) s.faulty = pr.sat;
    }
    s.fix.pl_source = planner::PlSource::kRaw;
    s.fix.line = out.size() + 1;
    s.fix.source = "simulated:" + std::to_string(s.fix.line);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace skylane::test
