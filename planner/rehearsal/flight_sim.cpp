#include "planner/rehearsal/flight_sim.hpp"

#include "integrity/sim/trajectory.hpp"
#include "maps/geodesy.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <random>

namespace skylane::planner {

using nlohmann::json;

std::vector<SimulatedFix> simulateFlight(const ApprovedFlight& flight, const Approver& approver, const FlightSimOptions& o,
                                         const std::function<void(double)>& progress) {
  if (flight.route.size() < 2) throw std::invalid_argument("simulateFlight: a route of at least 2 points is needed");
  const maps::Geodetic origin{flight.route.front().lat_rad, flight.route.front().lon_rad, flight.route.front().h_ell_m};
  const maps::LocalFrame enu(origin);
  std::vector<integrity::sim::Waypoint> wps;
  for (const RoutePoint& p : flight.route) {
    wps.push_back({enu.toEnu({p.lat_rad, p.lon_rad, p.h_ell_m}), approver.mission().cruise_speed_mps});
  }
  const integrity::sim::Trajectory traj(origin, wps, o.turn_radius_m);
  integrity::sim::SensorSpec spec;
  spec.model = approver.mission().model;
  spec.elevation_mask_rad = maps::deg2rad(approver.mission().mask_deg);
  if (o.imu) spec.imu = integrity::sim::imuSpec(o.imu->grade);
  integrity::sim::SensorSimulator sim(traj, approver.orbits(), flight.departure, spec, o.faults, o.seed);
  std::mt19937_64 onboard_rng(o.seed ^ 0x5eedULL);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto noise3 = [&] { return Eigen::Vector3d(n01(onboard_rng), n01(onboard_rng), n01(onboard_rng)); };
  std::vector<SimulatedFix> out;
  std::vector<ImuIncrement> increments;
  double reported = 0.0;
  while (sim.running()) {
    const integrity::sim::ImuSample is = sim.stepImu();
    increments.push_back({is.dt_s, is.dtheta_rad, is.dv_mps});
    if (!sim.gnssDue()) continue;
    const integrity::sim::GnssEpoch ep = sim.gnss();
    const integrity::sim::TruthState& x = sim.truth();
    SimulatedFix s;
    s.t_s = ep.t_s;
    s.truth = x.geodetic;
    s.fix.flight = o.flight;
    s.fix.time = ep.time;
    s.fix.lat_rad = x.geodetic.lat_rad;
    s.fix.lon_rad = x.geodetic.lon_rad;
    s.fix.h_ell_m = x.geodetic.h_ell_m + o.reported_dh_m;
    for (const integrity::sim::Pseudorange& pr : ep.ranges) {
      s.fix.ranges.push_back({pr.sat, pr.pseudorange_m, pr.sat_ecef_m});
      if (pr.injected_m != 0.0) s.faulty = pr.sat;
    }
    s.fix.pl_source = PlSource::kRaw;
    if (o.imu) {
      ImuRecord rec;
      rec.grade = static_cast<int>(o.imu->grade);
      rec.increments = std::move(increments);
      s.fix.imu = std::move(rec);
      s.fix.velocity_enu_mps = x.v_enu_mps + o.imu->velocity_sigma_mps * noise3();
      s.fix.attitude_rad = Eigen::Vector3d(x.roll_rad, x.pitch_rad, x.heading_rad) + o.imu->attitude_sigma_rad * noise3();
      if (o.imu->aiding) {
        const integrity::sim::AidingSample aid = sim.aiding();
        s.fix.baro_h_m = aid.baro_h_m;
        s.fix.mag_heading_rad = aid.heading_rad;
      }
    }
    increments.clear();
    s.fix.line = out.size() + 1;
    s.fix.source = "simulated:" + std::to_string(s.fix.line);
    out.push_back(std::move(s));
    if (progress && ep.t_s - reported >= 10.0) {
      reported = ep.t_s;
      progress(ep.t_s / traj.duration_s());
    }
  }
  if (progress) progress(1.0);
  return out;
}

std::vector<SimulatedFix> simulateFlight(const ApprovalReport& r, const Approver& approver, const FlightSimOptions& o,
                                         const std::function<void(double)>& progress) {
  ApprovedFlight f;
  f.approved = true;
  f.departure = r.departure;
  f.route = r.route;
  return simulateFlight(f, approver, o, progress);
}

}  // namespace skylane::planner
