#include "planner/tracking/tracked_flight.hpp"

#include "integrity/ins/filter_tuning.hpp"
#include "integrity/ins/strapdown.hpp"
#include "maps/geodesy.hpp"

#include <cmath>
#include <cstdio>

namespace skylane::planner {

namespace {

/// How far the IMU increments' span may differ from the time between two fixes (+0.1 %).
constexpr double kSpanTolerance_s = 0.02;

}  // namespace

integrity::ins::NavigatorEpoch TrackedFlight::runInsEpoch(integrity::ins::Navigator& n, const TrackFix& fix) const {
  for (const ImuIncrement& i : fix.imu->increments) n.propagate(i.dtheta_rad, i.dv_mps, i.dt_s);
  std::vector<integrity::ins::PseudorangeInput> ranges;
  for (const integrity::LocatedRange& l :
       integrity::rangesAboveMask(fix.ranges, n.filter().nav().r_ecef_m, fix.time, &approver->orbits(), live.elevation_mask_rad)) {
    ranges.push_back({l.sat, l.sat_ecef_m, l.pr_m});
  }
  return n.epoch(fix.time - nav_t0, ranges, fix.baro_h_m, fix.mag_heading_rad);
}

std::optional<integrity::ins::NavigatorEpoch> TrackedFlight::insEpoch(const TrackFix& fix, std::string& note,
                                                                     std::unique_ptr<integrity::ins::Navigator>& before) {
  if (!nav) return std::nullopt;
  const double gap = fix.time - nav_time, span = fix.imu->span_s();
  char buf[160];
  if (fix.imu->grade != nav_grade) {
    std::snprintf(buf, sizeof buf, "GNSS/INS: the IMU grade changed; the filter aligns again");
  } else if (std::abs(span - gap) > kSpanTolerance_s + 0.001 * gap) {
    std::snprintf(buf, sizeof buf, "GNSS/INS: the IMU increments span %.3f s but the fixes are %.3f s apart; the filter aligns again",
                  span, gap);
  } else {
    before = std::make_unique<integrity::ins::Navigator>(*nav);
    integrity::ins::NavigatorEpoch ep = runInsEpoch(*nav, fix);
    nav_time = fix.time;
    return ep;
  }
  nav.reset();
  note = buf;
  return std::nullopt;
}

std::optional<integrity::ins::NavigatorEpoch> TrackedFlight::deeperEpoch(const integrity::ins::Navigator& before,
                                                                        const TrackFix& fix) try {
  auto deeper = std::make_unique<integrity::ins::Navigator>(before);  // (kept off the fix path's stack)
  const int max_exclusions = deeper->config().max_exclusions;
  deeper->setMaxExclusions(max_exclusions + 1);
  integrity::ins::NavigatorEpoch ep = runInsEpoch(*deeper, fix);
  if (!ep.fault_mode_available) return std::nullopt;
  deeper->setMaxExclusions(max_exclusions);
  nav = std::move(deeper);
  return ep;
} catch (const std::exception&) {  // the rerun failed: the first pass stands
  return std::nullopt;
}

void TrackedFlight::align(const TrackFix& fix, const integrity::LiveFix& snap, std::string& note) {
  if (!fix.velocity_enu_mps || !fix.attitude_rad) {
    if (note.empty()) note = "GNSS/INS not aligned: the fix gives no velocity_enu_mps and attitude_deg";
    return;
  }
  integrity::ins::NavState s;
  s.r_ecef_m = snap.p_ecef;
  const Eigen::Matrix3d R_enu_ecef = maps::rotationEcefToEnu(snap.position.lat_rad, snap.position.lon_rad);
  s.v_ecef_mps = R_enu_ecef.transpose() * *fix.velocity_enu_mps;
  const Eigen::Vector3d& a = *fix.attitude_rad;
  s.C_ecef_body = R_enu_ecef.transpose() * integrity::ins::bodyToEnu(a.z(), a.y(), a.x());
  const std::optional<double> clock_m =
      integrity::meanClockResidual_m(fix.ranges, s.r_ecef_m, fix.time, &approver->orbits(), snap.used);
  if (!clock_m) return;
  const auto grade = static_cast<integrity::ins::ImuGrade>(fix.imu->grade);
  nav = std::make_unique<integrity::ins::Navigator>(
      integrity::ins::trackingNavigatorConfig(grade, live.model, live.elevation_mask_rad, integrity::ins::kTrackingAlignPositionSigma_m), s, *clock_m, 0.0);
  nav_grade = fix.imu->grade;
  nav_t0 = nav_time = fix.time;
  if (note.empty()) note = "GNSS/INS aligned at the snapshot position with the fix's velocity and attitude";
}

void TrackedFlight::buildBoxes(const TrackedFlight* same_route) {
  std::vector<Eigen::Vector3d> path;
  for (RoutePoint& p : plan.route) {
    const Eigen::Vector2d xy = approver->frame().toPlane(p.lat_rad, p.lon_rad);
    p.xyz = Eigen::Vector3d(xy.x(), xy.y(), p.h_ell_m);
    path.push_back(p.xyz);
  }
  if (same_route != nullptr) {
    level1 = same_route->level1;
    level2 = same_route->level2;
    return;
  }
  level1 = std::make_shared<const geofence::Corridor>(path, plan.level1);
  level2 = std::make_shared<const geofence::Corridor>(path, plan.level2);
}

std::string TrackedFlight::routeKey() const {
  std::string key;
  const auto add = [&key](double v) { key.append(reinterpret_cast<const char*>(&v), sizeof v); };
  const Approver* a = approver.get();
  key.append(reinterpret_cast<const char*>(&a), sizeof a);
  for (const RoutePoint& p : plan.route) {
    add(p.lat_rad);
    add(p.lon_rad);
    add(p.h_ell_m);
  }
  for (const geofence::AlertLimits& l : {plan.level1, plan.level2}) {
    add(l.hal_m);
    add(l.val_m);
  }
  return key;
}

}  // namespace skylane::planner
