#pragma once
// A simulated flight along an approved route (seed 001's sensor simulator: real orbits, the
// ARAIM error model, fault injection) turned into tracker fixes with raw pseudoranges — for the
// tracking tests and bench/bench_track.cpp.

#include "integrity/sim/sensors.hpp"
#include "integrity/sim/trajectory.hpp"
#include "planner/approval.hpp"
#include "planner/tracking/track_fix.hpp"

#include <optional>
#include <random>
#include <vector>

namespace skylane::test {

/// What the IMU side of a simulated flight gives the tracker (GNSS/INS fixes).
struct ImuFeed {
  integrity::sim::ImuGrade grade = integrity::sim::ImuGrade::kTactical;
  bool aiding = true;  ///< barometer and magnetometer in every fix
  /// The onboard navigation's velocity and attitude in each fix (the filter aligns with them):
  /// the truth perturbed with the σ's the filter assumes at alignment (EkfConfig defaults).
  double velocity_sigma_mps = 0.5;
  double attitude_sigma_rad = 2.0 * M_PI / 180.0;
};

/// One GNSS epoch of the flight as a fix, with what the simulator injected.
struct SimulatedFix {
  planner::TrackFix fix;
  std::optional<integrity::SatId> faulty;  ///< the satellite carrying an injected bias, if any
  double t_s = 0.0;                        ///< after departure
  maps::Geodetic truth;                    ///< where the vehicle is
};

/// The approved route flown at the mission's cruise speed (30 m turn radius), one fix per GNSS
/// epoch named `flight`, the reported position the truth raised by `reported_dh_m` (it only
/// starts skylane's own solution), every pseudorange with its satellite position; with `imu`,
/// the IMU increments since the previous fix, velocity, attitude and (optionally) aiding.
inline std::vector<SimulatedFix> simulateRoute(const planner::ApprovalReport& r, const planner::Approver& a,
                                               const std::vector<integrity::sim::FaultSpec>& faults, std::uint64_t seed,
                                               double reported_dh_m = 0.0, const std::string& flight = "F1",
                                               const std::optional<ImuFeed>& imu = std::nullopt) {
  const maps::Geodetic origin{r.route.front().lat_rad, r.route.front().lon_rad, r.route.front().h_ell_m};
  const maps::LocalFrame enu(origin);
  std::vector<integrity::sim::Waypoint> wps;
  for (const planner::RoutePoint& p : r.route) wps.push_back({enu.toEnu({p.lat_rad, p.lon_rad, p.h_ell_m}), a.mission().cruise_speed_mps});
  const integrity::sim::Trajectory traj(origin, wps, 30.0);
  integrity::sim::SensorSpec spec;
  spec.model = a.mission().model;
  if (imu) spec.imu = integrity::sim::imuSpec(imu->grade);
  integrity::sim::SensorSimulator sim(traj, a.orbits(), r.departure, spec, faults, seed);
  std::mt19937_64 onboard_rng(seed ^ 0x5eedULL);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<SimulatedFix> out;
  std::vector<planner::ImuIncrement> increments;
  while (sim.running()) {
    const integrity::sim::ImuSample is = sim.stepImu();
    increments.push_back({is.dt_s, is.dtheta_rad, is.dv_mps});
    if (!sim.gnssDue()) continue;
    const integrity::sim::GnssEpoch ep = sim.gnss();
    SimulatedFix s;
    s.t_s = ep.t_s;
    s.fix.flight = flight;
    s.fix.time = ep.time;
    s.fix.lat_rad = sim.truth().geodetic.lat_rad;
    s.fix.lon_rad = sim.truth().geodetic.lon_rad;
    s.fix.h_ell_m = sim.truth().geodetic.h_ell_m + reported_dh_m;
    s.truth = sim.truth().geodetic;
    if (imu) {
      planner::ImuRecord rec;
      rec.grade = static_cast<int>(imu->grade);
      rec.increments = std::move(increments);
      s.fix.imu = std::move(rec);
      const integrity::sim::TruthState& x = sim.truth();
      s.fix.velocity_enu_mps = x.v_enu_mps + imu->velocity_sigma_mps * Eigen::Vector3d(n01(onboard_rng), n01(onboard_rng), n01(onboard_rng));
      s.fix.attitude_rad = Eigen::Vector3d(x.roll_rad, x.pitch_rad, x.heading_rad) +
                           imu->attitude_sigma_rad * Eigen::Vector3d(n01(onboard_rng), n01(onboard_rng), n01(onboard_rng));
      if (imu->aiding) {
        const integrity::sim::AidingSample aid = sim.aiding();
        s.fix.baro_h_m = aid.baro_h_m;
        s.fix.mag_heading_rad = aid.heading_rad;
      }
    }
    increments.clear();
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
