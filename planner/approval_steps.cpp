// The approval of approval.hpp as named steps: Approver::Impl::run lists them, each is defined
// below in the order it runs. The state they pass along is in approval_impl.hpp.
#include "planner/approval_impl.hpp"

#include "maps/geoid.hpp"
#include "maps/time.hpp"

#include <algorithm>
#include <chrono>
#include <sstream>

namespace skylane::planner {

using approval_steps::ApprovalSetup;
using approval_steps::AttemptHistory;
using approval_steps::AttemptOutcome;
using approval_steps::LegPlan;
using approval_steps::Penalty;
using approval_steps::ReasonTally;
using approval_steps::RouteCorridors;
using approval_steps::RouteSamples;
using approval_steps::SampleChecks;
using approval_steps::Say;
using approval_steps::StopTiming;

namespace {

/// Least radius round a replan's start within which only the vehicle's point must be clear [m].
constexpr double kMinExempt_m = 10.0;
/// What the activity window allows beyond twice the direct flight time (climb, descent,
/// detours) [s].
constexpr double kFlightAllowance_s = 120.0;
/// How far ahead a rejected route's later departures are tried [s]: one day.
constexpr double kLaterDepartureHorizon_s = 86400.0;
/// The penalty round a sample without a protection level [m].
constexpr double kNoPlPenalty_m = 50.0;
/// Bounds of the penalty round a sample that broke level 2, a zone or an obstacle (its HPL,
/// clamped) [m]: wide enough to move the route, narrow enough to leave it room.
constexpr double kMinPenalty_m = 20.0, kMaxPenalty_m = 300.0;

double secondsSince(std::chrono::steady_clock::time_point started) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

std::string fmtMetres(double v) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << v << " m";
  return s.str();
}

std::string fmtTime(double t_s) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(0);
  s << "t+" << t_s << " s";
  return s.str();
}

/// Adds the instants each hover starts and ends to sorted sample times (so a hover shorter than
/// the sample step is still checked), keeping them sorted and distinct.
void addHoverEdges(const std::vector<RoutePoint>& route, std::vector<double>& t_s) {
  const std::size_t regular = t_s.size();
  for (const RoutePoint& p : route) {
    if (p.hover_s <= 0.0) continue;
    t_s.push_back(p.eta_s);
    t_s.push_back(p.eta_s + p.hover_s);
  }
  if (t_s.size() == regular) return;
  std::sort(t_s.begin(), t_s.end());
  t_s.erase(std::unique(t_s.begin(), t_s.end()), t_s.end());
}

/// The penalty round a sample whose protection volume broke a rule.
double violationRadius(const PredictedSample& ps) { return std::min(kMaxPenalty_m, std::max(ps.hpl_m, kMinPenalty_m)); }

Reason noPlReason(const PredictedSample& ps) {
  Reason r;
  r.kind = "integrity";
  r.subject = "PL";
  r.message = "no protection level: " + std::to_string(ps.satellites) + " satellites usable (" +
              std::to_string(ps.blocked) + " hidden by buildings or terrain)";
  return r;
}

/// Level 2 broken: by the PL whose margin is smaller.
Reason airspaceReason(const geofence::Check& c, const PredictedSample& ps, const geofence::AlertLimits& level2) {
  Reason r;
  r.kind = "airspace";
  const bool horizontal = c.margin_h_m < c.margin_v_m;
  r.subject = horizontal ? "HPL" : "VPL";
  r.value_m = horizontal ? ps.hpl_m : ps.vpl_m;
  r.limit_m = horizontal ? level2.hal_m : level2.val_m;
  r.message = std::string(horizontal ? "HPL " : "VPL ") + fmtMetres(*r.value_m) + " exceeds the level-2 limit " +
              fmtMetres(*r.limit_m) + " by " + fmtMetres(*r.value_m - *r.limit_m);
  return r;
}

/// "zone X (PROHIBITED, "name")", "keep-in zone X", "obstacle X".
std::string describeCheck(const geofence::Check& c) {
  if (c.level == geofence::Level::kObstacle) return "obstacle " + c.subject;
  if (c.level == geofence::Level::kKeepIn) return "keep-in zone " + c.subject + (c.name.empty() ? "" : " (\"" + c.name + "\")");
  return "zone " + c.subject + " (" + c.restriction + (c.name.empty() ? "" : ", \"" + c.name + "\"") + ")";
}

/// A zone or an obstacle met by the protection volume, or a keep-in zone it leaves.
Reason obstructionReason(const geofence::Check& c, const PredictedSample& ps) {
  Reason r;
  const bool keep_in = c.level == geofence::Level::kKeepIn;
  r.kind = geofence::levelName(c.level);
  r.subject = c.subject;
  r.value_m = keep_in ? -std::min(c.margin_h_m, c.margin_v_m) : -std::max(c.margin_h_m, c.margin_v_m);
  r.message = std::string("the protection volume (HPL ") + fmtMetres(ps.hpl_m) + ", VPL " + fmtMetres(ps.vpl_m) + ") " +
              (keep_in ? "leaves " : "meets ") + describeCheck(c) + " at " + fmtTime(ps.t_s) + "; it must shrink by " +
              fmtMetres(*r.value_m);
  return r;
}

/// What would lift a zone that makes a place unflyable: an authorisation, met conditions, or nothing.
std::string liftedBy(const geofence::Check& c) {
  if (c.level != geofence::Level::kZone) return "";
  if (c.restriction == "REQ_AUTHORISATION") {
    return "; an authorisation for it would lift it (list \"" + c.subject + "\" under the mission's authorisations)";
  }
  if (c.restriction == "CONDITIONAL") {
    return "; meeting its conditions would lift it (list \"" + c.subject + "\" under the mission's authorisations)";
  }
  return "";
}

}  // namespace

ApprovalReport Approver::Impl::run(const std::vector<Eigen::Vector3d>& stops, const std::vector<StopTiming>& stop_timing,
                                   const std::vector<maps::GpsTime>& departures, bool from_vehicle,
                                   const std::function<void(const std::string&)>& progress) {
  const auto started = std::chrono::steady_clock::now();
  const Say say{progress};
  ApprovalSetup setup = boundFlightTime(stops, stop_timing, departures, from_vehicle);
  ensureCostField(setup, say);
  fitSearchBox(setup);  // after the cost field: a replan's exemption grows with the PL predicted there
  ApprovalReport report;
  report.mission = record;
  report.limits = limits;
  // The mission's departure until an attempt sets its own: a mission rejected before any route
  // was timed (an unflyable start or goal) still names when it was to fly.
  if (!departures.empty()) report.departure = departures.front();
  AttemptHistory history;
  for (const maps::GpsTime& departure : departures) {
    if (tryDeparture(setup, departure, history, report, say)) break;
  }
  // Rejected: the last attempt's reasons; for a fixed departure, the earliest later departure
  // (within 24 h, in departure steps) at which the same route passes its integrity checks.
  if (!report.approved) {
    report.reasons = history.last_reasons;
    if (!history.last_route.empty() && departures.size() == 1 && !from_vehicle) {
      say("looking for a later departure");
      report.earliest_passing_departure = searchLaterDeparture(departures.front(), history);
    }
  }
  report.elapsed_s = secondsSince(started);
  return report;
}

ApprovalSetup Approver::Impl::boundFlightTime(const std::vector<Eigen::Vector3d>& stops,
                                              const std::vector<StopTiming>& stop_timing,
                                              const std::vector<maps::GpsTime>& departures, bool from_vehicle) const {
  ApprovalSetup setup;
  setup.stops = stops;
  setup.timing = stop_timing;
  setup.departures = departures;
  setup.from_vehicle = from_vehicle;
  // The straight legs at their speeds, and every hover; the fastest leg bounds how early the
  // vehicle can be anywhere.
  setup.fastest_mps = m.cruise_speed_mps;
  for (std::size_t i = 0; i < stops.size(); ++i) {
    setup.direct_s += stop_timing[i].hover_s;
    if (i == 0) continue;
    setup.direct_s += (stops[i] - stops[i - 1]).head<2>().norm() / stop_timing[i].speed_mps;
    setup.fastest_mps = std::max(setup.fastest_mps, stop_timing[i].speed_mps);
  }
  const double flight_bound_s = 2.0 * setup.direct_s + kFlightAllowance_s;
  // The zones' activity window reaches the mission's latest departure (a window whose length
  // is not a multiple of its step has its last departure before it); a replan's is `now`.
  const maps::GpsTime latest_departure = from_vehicle ? departures.back() : m.departure_latest;
  setup.zones_until = latest_departure.plus(flight_bound_s);
  return setup;
}

/// The integrity cost field is predicted once, at the first approval's mid-flight time.
void Approver::Impl::ensureCostField(const ApprovalSetup& setup, const Say& say) {
  if (cost_grid_built) return;
  say("predicted protection levels over the area (integrity cost field)");
  buildCostGrid(setup.departures.front().plus(setup.direct_s / 2.0));
  cost_grid_built = true;
}

/// From the vehicle: the search box reaches it, and near it only the vehicle's own point must be
/// clear (it may have drifted so close to a zone that its box is not: the route leads it away).
void Approver::Impl::fitSearchBox(ApprovalSetup& setup) const {
  setup.box_lo = lower;
  setup.box_hi = upper;
  setup.exempt_m = 0.0;
  if (!setup.from_vehicle) return;
  const Eigen::Vector3d& vehicle = setup.stops.front();
  setup.box_lo = setup.box_lo.cwiseMin(vehicle - Eigen::Vector3d::Constant(1.0));
  setup.box_hi = setup.box_hi.cwiseMax(vehicle + Eigen::Vector3d::Constant(1.0));
  setup.exempt_m = std::max(kMinExempt_m, 2.0 * planningVolume(vehicle).hpl_m);
}

/// One departure: attempt a route, and after violations replan up to max_replans times; true
/// when approved.
bool Approver::Impl::tryDeparture(const ApprovalSetup& setup, const maps::GpsTime& departure, AttemptHistory& history,
                                  ApprovalReport& report, const Say& say) const {
  ++report.planner.departures_tried;
  AttemptOutcome outcome = AttemptOutcome::kViolations;
  for (int attempt = 0; attempt <= m.max_replans && outcome == AttemptOutcome::kViolations; ++attempt) {
    outcome = attemptRoute(setup, departure, attempt, history, report, say);
  }
  return outcome == AttemptOutcome::kApproved;
}

/// One attempt: plan the legs, time the route, sample and check it; keep it in the report and
/// the history (approved, or its violations penalised for the next attempt).
AttemptOutcome Approver::Impl::attemptRoute(const ApprovalSetup& setup, const maps::GpsTime& departure, int attempt,
                                            AttemptHistory& history, ApprovalReport& report, const Say& say) const {
  ++report.planner.attempts;
  say("planning (departure " + maps::formatRfc3339(departure) + ", attempt " + std::to_string(attempt + 1) + ")");
  const LegPlan plan = planLegs(setup, departure, attempt, history.penalties, report.planner);
  if (!plan.ok) {
    history.last_reasons = {planningReason(setup, departure, plan, report.planner.status)};
    history.last_route.clear();
    return AttemptOutcome::kNoRoute;  // replanning cannot help; next departure
  }
  const std::vector<RoutePoint> route = timeRoute(plan.pts, pointTiming(setup, plan));
  report.planner.length_m = polylineLength(plan.pts);
  const RouteSamples samples = sampleRoute(route, say);
  SampleChecks checks = checkSamples(setup, departure, plan.pts, predictRoute(route, samples, departure), report.zones);
  std::vector<Reason> reasons = checks.reasons.summarised();
  report.level1_availability = levelAvailability(checks.predicted, limits.level1);
  report.level2_availability = levelAvailability(checks.predicted, limits.level2);
  if (std::optional<Reason> shortfall = availabilityShortfall(report.level1_availability)) {
    reasons.push_back(std::move(*shortfall));
  }
  history.last_route = route;
  history.last_samples = samples;
  report.route = route;
  report.predicted = std::move(checks.predicted);
  report.level1_exceedances = checks.level1_exceedances;
  report.departure = departure;
  if (reasons.empty()) {
    report.approved = true;
    return AttemptOutcome::kApproved;
  }
  history.last_reasons = std::move(reasons);
  history.penalties.insert(history.penalties.end(), checks.violations.begin(), checks.violations.end());
  return AttemptOutcome::kViolations;
}

/// Plan leg by leg through the waypoints; stop at the first leg without an exact path.
LegPlan Approver::Impl::planLegs(const ApprovalSetup& setup, const maps::GpsTime& departure, int attempt,
                                 const std::vector<Penalty>& penalties, PlannerStats& stats) const {
  LegPlan plan;
  plan.pts = {setup.stops.front()};
  plan.stop_at = {0};
  for (std::size_t leg = 1; leg < setup.stops.size(); ++leg) {
    plan.last = planPath(legProblem(setup, departure, attempt, leg, plan.pts.back(), penalties));
    stats.planning_time_s += plan.last.planning_time_s + plan.last.simplify_time_s;
    stats.iterations += plan.last.iterations;
    stats.stopped_by_time = stats.stopped_by_time || plan.last.stopped_by_time;
    if (plan.last.lattice_searched) {
      ++stats.lattice_legs_searched;
      stats.lattice_legs_seeded += plan.last.lattice_seed ? 1 : 0;
      stats.lattice_state_checks += plan.last.lattice_state_checks;
      stats.lattice_step_m = plan.last.lattice_step_m;
    }
    if (plan.last.status != PathStatus::kExact) {
      plan.ok = false;
      plan.failed_leg = leg;
      break;
    }
    plan.pts.insert(plan.pts.end(), plan.last.points.begin() + 1, plan.last.points.end());
    plan.stop_at.push_back(plan.pts.size() - 1);
  }
  stats.algorithm = std::string(plannerName(m.planner));
  stats.status = std::string(pathStatusName(plan.last.status));
  stats.straight_line = plan.last.straight_line && setup.stops.size() == 2;
  return plan;
}

/// One leg's query: a state is valid (approval.hpp, step 1) over the zones active from when the
/// vehicle could first be there to the end of the activity window.
PathProblem Approver::Impl::legProblem(const ApprovalSetup& setup, const maps::GpsTime& departure, int attempt,
                                       std::size_t leg, const Eigen::Vector3d& from,
                                       const std::vector<Penalty>& penalties) const {
  PathProblem prob;
  prob.lower_enu_m = setup.box_lo;
  prob.upper_enu_m = setup.box_hi;
  prob.start_enu_m = from;
  prob.goal_enu_m = setup.stops[leg];
  const Eigen::Vector2d start_xy = setup.stops.front().head<2>();
  const maps::GpsTime latest = setup.zones_until;
  const Eigen::Vector3d vehicle = setup.stops.front();
  const double exempt_m = setup.exempt_m, fastest_mps = setup.fastest_mps;
  prob.is_valid = [this, &penalties, start_xy, departure, latest, vehicle, exempt_m, fastest_mps](const Eigen::Vector3d& p) {
    const maps::GpsTime earliest = departure.plus((p.head<2>() - start_xy).norm() / fastest_mps);
    if (exempt_m > 0.0 && (p - vehicle).norm() <= exempt_m) {
      // Round the vehicle only its own point must be clear; outside a keep-in zone it may fly back in.
      return !obstructions->conflicts({earliest, latest, {p, 0.0, 0.0}}, /*with_keep_in=*/false);
    }
    return valid(p, earliest, latest, penalties);
  };
  if (!cost_field.cost.empty()) {
    prob.extra_cost = &cost_field;
    prob.cost_step_m = cost_field.cell_m / 2.0;
  }
  prob.resolution_m = m.resolution_m;
  prob.time_limit_s = m.time_limit_s;
  prob.max_iterations = m.iterations;
  prob.seed = m.seed + static_cast<std::uint64_t>(attempt) * 7919u + leg;
  prob.planner = m.planner;
  prob.simplify = m.simplify;
  prob.lattice_fallback = m.lattice_fallback;
  return prob;
}

/// Why no route was found: an unflyable start or goal (naming the zone or obstacle it lies in,
/// when one does), or the planner's budget.
Reason Approver::Impl::planningReason(const ApprovalSetup& setup, const maps::GpsTime& departure, const LegPlan& plan,
                                      const std::string& status) const {
  Reason r;
  r.kind = "planning";
  r.subject = status;
  const PathResult& last = plan.last;
  if (last.status != PathStatus::kInvalidStart && last.status != PathStatus::kInvalidGoal) {
    r.message = "no route found for leg " + std::to_string(plan.failed_leg) + " within " + std::to_string(last.iterations) +
                " planner iterations (" + status + (last.stopped_by_time ? ", stopped by the time limit)" : ")") +
                (last.lattice_searched ? ", nor on a lattice down to a " + fmtMetres(last.lattice_step_m) + " step (" +
                                             std::to_string(last.lattice_state_checks) + " states checked" +
                                             (last.lattice_budget_spent ? ", its whole budget)" : ")")
                                       : std::string()) +
                legBlockers(plan.pts.back(), setup.stops[plan.failed_leg], departure, setup.zones_until) +
                "; a wider search box (planner.margin_m " + fmtMetres(m.margin_m) + ") or more planner.iterations (" +
                std::to_string(m.iterations) + ") may find one";
    return r;
  }
  const bool start = last.status == PathStatus::kInvalidStart;
  const Eigen::Vector3d p = start ? plan.pts.back() : setup.stops[plan.failed_leg];
  unflyableCause(p, departure, setup.zones_until, start ? "the start" : "the goal", r);
  const maps::Geodetic g = geodetic(p);
  r.lat_rad = g.lat_rad;
  r.lon_rad = g.lon_rad;
  r.h_ell_m = g.h_ell_m;
  return r;
}

/// What blocks the direct line of a leg: the keep-in zone its planning volume leaves and the zones
/// and obstacles it meets along it (every resolution_m, at most three, in the order met).
std::string Approver::Impl::legBlockers(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const maps::GpsTime& t0,
                                        const maps::GpsTime& t1) const {
  std::vector<std::string> met;
  const int n = std::max(1, static_cast<int>(std::ceil((to - from).norm() / std::max(m.resolution_m, 1.0))));
  for (int k = 0; k <= n && met.size() < 3; ++k) {
    const Eigen::Vector3d p = from + (to - from) * (static_cast<double>(k) / n);
    const std::optional<geofence::Check> c = obstructions->firstConflict({t0, t1, planningVolume(p)});
    if (!c) continue;
    const std::string what = (c->level == geofence::Level::kKeepIn ? "leaves " : "meets ") + describeCheck(*c);
    if (std::find(met.begin(), met.end(), what) == met.end()) met.push_back(what);
  }
  if (met.empty()) return "";
  std::string out = ": the direct line ";
  for (std::size_t i = 0; i < met.size(); ++i) out += (i == 0 ? "" : i + 1 == met.size() ? " and " : ", ") + met[i];
  return out;
}

/// Why `p` is not a valid state (Impl::valid), in the order valid() asks: the terrain, the
/// altitude limits, then what its planning volume (the level-1 box grown to the predicted PL)
/// reaches — the keep-in zone it leaves, the zone or obstacle it meets, and what would lift it.
void Approver::Impl::unflyableCause(const Eigen::Vector3d& p, const maps::GpsTime& from, const maps::GpsTime& until,
                                    const std::string& what, Reason& r) const {
  r.message = what + " is not flyable at its height: ";
  const auto g = ground(p.head<2>());
  if (!g) {
    r.message += "it lies outside the terrain model";
    return;
  }
  const double agl = p.z() - *g;
  if (agl < m.min_agl_m || agl > m.max_agl_m) {
    r.message += fmtMetres(agl) + " above the ground is outside the altitude limits " + fmtMetres(m.min_agl_m) + " to " +
                 fmtMetres(m.max_agl_m) + " AGL";
    return;
  }
  const maps::Geodetic q = geodetic(p);
  const double amsl = maps::Geoid::egm96().amslFromEllipsoidal_m(q.lat_rad, q.lon_rad, p.z());
  if (m.max_amsl_m && amsl > *m.max_amsl_m) {
    r.message += fmtMetres(amsl) + " AMSL is above the mission's max_amsl " + fmtMetres(*m.max_amsl_m);
    return;
  }
  const geofence::ProtectionVolume pv = planningVolume(p);
  const std::optional<geofence::Check> c = obstructions->firstConflict({from, until, pv});
  if (!c) {
    r.message += "it lies where an earlier attempt's route broke a rule";
    return;
  }
  r.kind = geofence::levelName(c->level);
  r.subject = c->subject;
  r.message = what + conflictCause(*c, {from, until, {p, 0.0, 0.0}}, pv) + liftedBy(*c);
}

/// " lies in zone X", or ": its planning volume (…) reaches zone X, d m away" (from the point's own check).
std::string Approver::Impl::conflictCause(const geofence::Check& c, const geofence::TimedVolume& point,
                                          const geofence::ProtectionVolume& pv) const {
  const std::string box = "its planning volume (the level-1 box ±" + fmtMetres(limits.level1.hal_m) + " / ±" +
                          fmtMetres(limits.level1.val_m) + " grown to 1.2 × the predicted PL: ±" + fmtMetres(pv.hpl_m) +
                          " / ±" + fmtMetres(pv.vpl_m) + ")";
  if (c.level == geofence::Level::kKeepIn) {
    const std::optional<geofence::Check> own = obstructions->keepIn(point);
    if (own && own->verdict != geofence::Verdict::kInside) return " lies outside " + describeCheck(c);
    return " is too close to the edge of " + describeCheck(c) + ": " + box + " reaches out of it, " +
           fmtMetres(std::min(own->margin_h_m, own->margin_v_m)) + " from the edge";
  }
  for (const geofence::Check& o : obstructions->check(point, std::max(pv.hpl_m, pv.vpl_m) + 1.0)) {
    if (o.level != c.level || o.subject != c.subject) continue;
    if (o.verdict != geofence::Verdict::kInside) return " lies in " + describeCheck(c);
    return ": " + box + " reaches " + describeCheck(c) + ", " + fmtMetres(*o.clearance_m) + " away";
  }
  return ": " + box + " reaches " + describeCheck(c);
}

/// Sample times every sample_s, where each hover starts and ends, and the route's end; the
/// place and sky mask at each.
RouteSamples Approver::Impl::sampleRoute(const std::vector<RoutePoint>& route, const Say& say) const {
  const double total_s = route.back().eta_s + route.back().hover_s;
  RouteSamples samples;
  for (double t = 0.0;; t += m.sample_s) {
    const double tt = std::min(t, total_s);
    samples.t_s.push_back(tt);
    if (tt >= total_s) break;
  }
  addHoverEdges(route, samples.t_s);
  say("predicting " + std::to_string(samples.t_s.size()) + " samples");
  const bool with_masks = masked();
  for (double t : samples.t_s) {
    const Eigen::Vector3d p = positionAlong(route, t);
    samples.xyz.push_back(p);
    samples.geo.push_back(geodetic(p));
    samples.masks.push_back(with_masks ? std::optional(skyMaskAt(samples.geo.back())) : std::nullopt);
  }
  return samples;
}

/// Per point of the plan: the speed of its stop's leg (the segment arriving there) and, at a
/// stop, the stop's hover.
std::vector<StopTiming> Approver::Impl::pointTiming(const ApprovalSetup& setup, const LegPlan& plan) const {
  std::vector<StopTiming> out(plan.pts.size());
  std::size_t from = 0;
  for (std::size_t s = 0; s < plan.stop_at.size(); ++s) {
    for (std::size_t i = from; i <= plan.stop_at[s]; ++i) out[i].speed_mps = setup.timing[s].speed_mps;
    out[plan.stop_at[s]].hover_s = setup.timing[s].hover_s;
    from = plan.stop_at[s] + 1;
  }
  return out;
}

RouteCorridors Approver::Impl::corridorsAlong(const std::vector<Eigen::Vector3d>& pts) const {
  return {geofence::Corridor(pts, limits.level1, {}), geofence::Corridor(pts, limits.level2, {})};
}

/// Every sample with its predicted PLs (predictRoute): with a PL, the fence check of its
/// protection volume.
SampleChecks Approver::Impl::checkSamples(const ApprovalSetup& setup, const maps::GpsTime& departure,
                                          const std::vector<Eigen::Vector3d>& pts, std::vector<PredictedSample> predicted,
                                          std::vector<ZoneApproach>& zones) const {
  const RouteCorridors corridors = corridorsAlong(pts);
  SampleChecks checks;
  for (PredictedSample& ps : predicted) {
    const maps::GpsTime t = departure.plus(ps.t_s);
    if (ps.pl_available) {
      ps.fence = checkFence(setup, corridors, t, ps, checks, zones);
    } else {
      checks.reasons.add(noPlReason(ps), ps);
      checks.violations.emplace_back(ps.xyz, kNoPlPenalty_m);
    }
    checks.predicted.push_back(std::move(ps));
  }
  return checks;
}

PredictedSample Approver::Impl::predictSample(const RouteSamples& samples, std::size_t k, const maps::GpsTime& t) const {
  PredictedSample ps;
  ps.t_s = samples.t_s[k];
  ps.xyz = samples.xyz[k];
  ps.lat_rad = samples.geo[k].lat_rad;
  ps.lon_rad = samples.geo[k].lon_rad;
  ps.h_ell_m = samples.geo[k].h_ell_m;
  const integrity::PredictSample pr = predictAt(samples.geo[k], t, samples.masks[k]);
  ps.pl_available = pr.pl.pl_computed;
  ps.hpl_m = pr.pl.hpl_m;
  ps.vpl_m = pr.pl.vpl_m;
  ps.satellites = static_cast<int>(pr.sats.size());
  ps.blocked = static_cast<int>(pr.blocked);
  return ps;
}

/// The fence at this instant: both levels, zones and obstacles. Level 1 is counted, level 2, the
/// zones and the obstacles give reasons and penalties; every zone's nearest approach is kept.
geofence::FenceVerdict Approver::Impl::checkFence(const ApprovalSetup& setup, const RouteCorridors& corridors,
                                                  const maps::GpsTime& t, const PredictedSample& ps, SampleChecks& checks,
                                                  std::vector<ZoneApproach>& zones) const {
  // The fence borrows the obstructions: a copy would rebuild the scene.
  const geofence::TimedVolume v{t, t, {ps.xyz, ps.hpl_m, ps.vpl_m}};
  geofence::FenceVerdict fv = geofence::checkVolume(corridors.level1, corridors.level2, *obstructions, v);
  // A replan's first metres leave the place the vehicle is in; they are not its reasons.
  const bool leaving = setup.from_vehicle && (ps.xyz - setup.stops.front()).norm() <= setup.exempt_m;
  for (const geofence::Check& c : fv.checks) {
    const bool inside = c.verdict == geofence::Verdict::kInside;
    if (c.level == geofence::Level::kCorridor) {
      // Level 1 is not a rejection: in flight HPL > HAL₁ reruns the monitoring.
      if (!inside) ++checks.level1_exceedances;
    } else if (c.level == geofence::Level::kAirspace) {
      if (inside) continue;
      checks.reasons.add(airspaceReason(c, ps, limits.level2), ps);
      checks.violations.emplace_back(ps.xyz, violationRadius(ps));
    } else {
      if (!inside && !leaving) {  // (a zone or obstacle met, a keep-in zone left)
        checks.reasons.add(obstructionReason(c, ps), ps);
        checks.violations.emplace_back(ps.xyz, violationRadius(ps) + limits.level1.hal_m);
      }
      if (c.level == geofence::Level::kZone) noteZoneApproach(c, zones);
    }
  }
  return fv;
}

void Approver::Impl::noteZoneApproach(const geofence::Check& c, std::vector<ZoneApproach>& zones) const {
  auto it = std::find_if(zones.begin(), zones.end(), [&](const ZoneApproach& z) { return z.identifier == c.subject; });
  if (it == zones.end()) {
    const airspace::Zone& z = obstructions->zones()[c.index];
    zones.push_back({z.identifier, std::string(airspace::restrictionLabel(z)), obstructions->zoneCounts(c.index),
                     *c.clearance_m});
  } else {
    it->min_clearance_m = std::min(it->min_clearance_m, *c.clearance_m);
  }
}

void ReasonTally::add(Reason reason, const PredictedSample& at) {
  reason.t_s = at.t_s;
  reason.lat_rad = at.lat_rad;
  reason.lon_rad = at.lon_rad;
  reason.h_ell_m = at.h_ell_m;
  // One reason per kind and subject: where and when it is worst, and from when.
  for (std::size_t i = 0; i < reasons.size(); ++i) {
    Reason& known = reasons[i];
    if (known.kind != reason.kind || known.subject != reason.subject) continue;
    ++occurrences[i];
    if (reason.value_m && known.value_m && *reason.value_m > *known.value_m) known = std::move(reason);
    return;
  }
  reasons.push_back(std::move(reason));
  occurrences.push_back(1);
  first_t_s.push_back(at.t_s);
}

std::vector<Reason> ReasonTally::summarised() const {
  std::vector<Reason> out = reasons;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (occurrences[i] > 1) {
      out[i].message += " (worst of " + std::to_string(occurrences[i]) + " samples from " + fmtTime(first_t_s[i]) + ")";
    }
  }
  return out;
}

/// The earliest departure, in departure steps within a day, at which the last route passes.
std::optional<maps::GpsTime> Approver::Impl::searchLaterDeparture(const maps::GpsTime& departure,
                                                                  const AttemptHistory& history) const {
  std::vector<Eigen::Vector3d> pts;
  for (const RoutePoint& p : history.last_route) pts.push_back(p.xyz);
  const RouteCorridors corridors = corridorsAlong(pts);
  for (double shift = m.departure_step_s; shift <= kLaterDepartureHorizon_s; shift += m.departure_step_s) {
    const maps::GpsTime later = departure.plus(shift);
    if (routePassesAt(later, corridors, history.last_route, history.last_samples)) return later;
  }
  return std::nullopt;
}

/// The same rule as the approval: every sample has a PL (for the mission's navigation), every
/// check but level 1 holds, and the policy's level-1 availability is met.
bool Approver::Impl::routePassesAt(const maps::GpsTime& departure, const RouteCorridors& corridors,
                                   const std::vector<RoutePoint>& route, const RouteSamples& samples) const {
  const std::vector<PredictedSample> predicted = predictRoute(route, samples, departure);
  if (availabilityShortfall(levelAvailability(predicted, limits.level1))) return false;
  for (const PredictedSample& ps : predicted) {
    const maps::GpsTime t = departure.plus(ps.t_s);
    if (!ps.pl_available) return false;
    const geofence::TimedVolume v{t, t, {ps.xyz, ps.hpl_m, ps.vpl_m}};
    for (const geofence::Check& c : geofence::checkVolume(corridors.level1, corridors.level2, *obstructions, v).checks) {
      if (c.level != geofence::Level::kCorridor && c.verdict != geofence::Verdict::kInside) return false;
    }
  }
  return true;
}

}  // namespace skylane::planner
