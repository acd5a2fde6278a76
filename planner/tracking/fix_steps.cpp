#include "planner/tracking/fix_steps.hpp"

#include "planner/operational_intent.hpp"

#include "geofence/verdict_json.hpp"
#include "maps/geodesy.hpp"
#include "maps/json_numbers.hpp"
#include "maps/plane_grid.hpp"
#include "planner/tracking/tracker.hpp"

#include <algorithm>
#include <cmath>

namespace skylane::planner {

using nlohmann::json;
using maps::metresOrNull;

namespace {

constexpr int kLevels = 5;  // geofence::Level: 1, 2, zone, obstacle, keep-in

/// Pushes v into a window of at most n values and returns how many are true.
int pushWindow(std::vector<bool>& w, bool v, int n) {
  w.push_back(v);
  while (static_cast<int>(w.size()) > n) w.erase(w.begin());
  return static_cast<int>(std::count(w.begin(), w.end(), true));
}

json satelliteList(const std::vector<integrity::SatId>& sats) {
  json ex = json::array();
  for (const integrity::SatId& s : sats) ex.push_back(s.str());
  return ex;
}

/// What a `monitoring_rerun` event reports (both reruns write it with monitoringRerunEvent).
struct RerunReport {
  bool detected = false;
  std::vector<integrity::SatId> excluded;
  std::optional<double> hpl_before_m, vpl_before_m;  ///< null when there was no first PL
  std::optional<geofence::Verdict> verdict_before;
  std::optional<double> hpl_after_m, vpl_after_m;    ///< null when the rerun gave none
  std::optional<geofence::Verdict> verdict_after;
  std::optional<std::string> note;
};

TrackEvent monitoringRerunEvent(const std::string& id, const TrackFix& fix, const RerunReport& r) {
  auto metresOrNullOpt = [](const std::optional<double>& v) { return v ? metresOrNull(*v) : json(nullptr); };
  TrackEvent e = trackEvent("monitoring_rerun", id, fix.time);
  e["fault_detected"] = r.detected;
  e["excluded"] = satelliteList(r.excluded);
  e["hpl_before_m"] = metresOrNullOpt(r.hpl_before_m);
  e["vpl_before_m"] = metresOrNullOpt(r.vpl_before_m);
  if (r.verdict_before) e["verdict_before"] = geofence::verdictName(*r.verdict_before);
  e["hpl_after_m"] = metresOrNullOpt(r.hpl_after_m);
  e["vpl_after_m"] = metresOrNullOpt(r.vpl_after_m);
  if (r.verdict_after) e["verdict_after"] = geofence::verdictName(*r.verdict_after);
  if (r.note) e["note"] = *r.note;
  e["line"] = fix.line;
  return e;
}

geofence::TimedVolume volumeAt(const TrackedFlight& f, const maps::GpsTime& t, const maps::Geodetic& g, double h, double v) {
  const Eigen::Vector2d xy = f.approver->fixProjection().toPlane(g.lat_rad, g.lon_rad);
  return geofence::TimedVolume{t, t, {Eigen::Vector3d(xy.x(), xy.y(), g.h_ell_m), h, v}};
}

geofence::FenceVerdict fenceVerdict(const TrackerOptions& o, const TrackedFlight& f, const geofence::TimedVolume& vol) {
  return geofence::checkVolume(*f.level1, *f.level2, f.approver->obstructions(), vol, o.horizon_m);
}

/// The time jump of a fix, if any: from the last accepted fix or (the first fix) from the
/// approved departure and flight. Sets `why` for a duplicate or a fix out of order.
std::optional<double> timeJump(const TrackerOptions& o, const TrackedFlight& f, const TrackFix& fix, std::string& from,
                               std::string& why) {
  const FlightState& st = f.st;
  if (st.last_time) {
    const double dt = fix.time - *st.last_time;
    if (std::abs(dt) > o.max_time_jump_s) {
      from = "the last accepted fix";
      return dt;
    }
    if (dt == 0.0) {
      why = "duplicate time " + maps::formatRfc3339(fix.time, 3) + " (already accepted for flight " + f.id + ")";
    } else if (dt < 0.0) {
      why = "out of order: " + maps::formatRfc3339(fix.time, 3) + " is before the last accepted fix " +
            maps::formatRfc3339(*st.last_time, 3);
    }
    return std::nullopt;
  }
  const double from_departure = fix.time - f.plan.departure;
  const double flight_s = f.plan.route.back().eta_s + f.plan.route.back().hover_s;
  if (from_departure < -o.max_time_jump_s || from_departure > flight_s + o.max_time_jump_s) {
    from = "the approved departure " + maps::formatRfc3339(f.plan.departure);
    return from_departure;
  }
  return std::nullopt;
}

}  // namespace

geofence::Verdict worstVerdict(const geofence::FenceVerdict& v, geofence::Level level) {
  geofence::Verdict worst = geofence::Verdict::kInside;
  for (const geofence::Check& c : v.checks) {
    if (c.level != level || c.verdict == geofence::Verdict::kInside) continue;
    if (c.verdict == geofence::Verdict::kOutside || worst == geofence::Verdict::kInside) worst = c.verdict;
  }
  return worst;
}

TrackEvent rejectedFix(const TrackFix& fix, const std::string& id, const std::string& why) {
  TrackEvent e = rejectedInputEvent(fix.source, fix.line, why);
  e.flight = id;
  return e;
}

bool checkOrder(const TrackerOptions& o, TrackedFlight& f, FixWork& w, const std::optional<maps::GpsTime>& stream_time) {
  FlightState& st = f.st;
  const TrackFix& fix = w.fix;
  std::string from, why;
  const std::optional<double> jump_s = timeJump(o, f, fix, from, why);
  if (!why.empty()) {
    w.out.push_back(rejectedFix(fix, f.id, why));
    return false;
  }
  if (jump_s) {
    // A jump of the receiver's clock, a long outage, a late flight: the fix is refused unless it
    // continues a run of jump_confirm fixes in order on the new timeline (then that is taken).
    const bool continues = st.jump_candidate && fix.time - *st.jump_candidate > 0 &&
                           fix.time - *st.jump_candidate <= o.max_time_jump_s;
    st.jump_count = continues ? st.jump_count + 1 : 1;
    st.jump_candidate = fix.time;
    const std::string size = "time jump of " + std::to_string(static_cast<long long>(*jump_s)) + " s from " + from;
    if (st.jump_count < o.jump_confirm) {
      w.out.push_back(rejectedFix(fix, f.id,
                                  size + " (more than " + std::to_string(static_cast<long long>(o.max_time_jump_s)) + " s; " +
                                      std::to_string(st.jump_count) + " of " + std::to_string(o.jump_confirm) +
                                      " fixes in order to take the new timeline)"));
      return false;
    }
    w.jump_note = "a new timeline after a " + size + ", confirmed by " + std::to_string(st.jump_count) + " fixes in order";
    // The flight's clock from here on is the stream's plus an offset: the fix is "now" (taken
    // once the fix is accepted, after the sweep has seen the flight's gap on its old clock).
    if (st.last_time && stream_time) w.new_offset = fix.time - *stream_time;
  }
  st.jump_candidate.reset();
  st.jump_count = 0;
  return true;
}

void runGnssInsEpoch(TrackedFlight& f, FixWork& w) {
  const TrackFix& fix = w.fix;
  if (!fix.imu || fix.ranges.empty()) return;
  try {
    w.ins_epoch = f.insEpoch(fix, w.note, w.ins_before);
  } catch (const std::exception& err) {  // e.g. a covariance gone non-positive: align again
    f.nav.reset();
    w.ins_epoch.reset();
    w.ins_before.reset();
    w.note = std::string("GNSS/INS filter failed (") + err.what() + "); the filter aligns again";
  }
  if (w.ins_epoch && !w.ins_epoch->fault_mode_available && w.ins_epoch->gnss_fault_detected && w.ins_before) {
    // A fault detected and not excluded: the monitoring rerun at once, one more exclusion allowed.
    if (auto again = f.deeperEpoch(*w.ins_before, fix)) {
      RerunReport r;
      r.detected = true;
      r.excluded = again->excluded;
      r.hpl_after_m = again->fault_mode_hpl_m;
      r.vpl_after_m = again->fault_mode_vpl_m;
      r.note = "GNSS/INS: a fault detected and not excluded; the epoch again with one more exclusion";
      w.pre_events.push_back(monitoringRerunEvent(f.id, fix, r));
      w.ins_epoch = again;
      w.early_rerun = true;
    }
  }
  if (w.ins_epoch && !w.ins_epoch->fault_mode_available) {
    const bool unresolved = w.ins_epoch->gnss_fault_detected && w.ins_epoch->excluded.empty();
    w.note = w.ins_epoch->outage
                 ? "GNSS/INS: no pseudorange above the mask (dead reckoning, no integrity); the snapshot is used"
                 : "GNSS/INS gave no protection level (" +
                       std::string(unresolved ? "a fault detected and not excluded" : "too few satellites or no fault-mode PL") +
                       "); the snapshot is used";
    w.ins_epoch.reset();
  }
}

void solveSnapshot(TrackedFlight& f, FixWork& w) {
  const TrackFix& fix = w.fix;
  if (w.ins_epoch) {
    const integrity::ins::NavigatorEpoch& ep = *w.ins_epoch;
    if (ep.baro_refused || ep.heading_refused) {
      w.note = std::string("GNSS/INS refused the ") +
               (ep.baro_refused ? (ep.heading_refused ? "barometer and magnetometer" : "barometer") : "magnetometer") +
               " reading (its innovation failed the gate)";
    }
    w.pos = maps::ecefToGeodetic(ep.r_ecef_m);
    w.hpl_m = ep.fault_mode_hpl_m;
    w.vpl_m = ep.fault_mode_vpl_m;
    w.source = PlSource::kGnssIns;
    return;
  }
  if (fix.ranges.empty()) return;
  w.first = integrity::solveLiveFix(fix.ranges, w.pos, fix.time, f.live, false, &f.approver->orbits());
  if (w.first->solved && w.first->pl.pl_computed) {
    w.pos = w.first->position;
    w.hpl_m = w.first->pl.hpl_m;
    w.vpl_m = w.first->pl.vpl_m;
    w.source = PlSource::kRaw;
    if (fix.imu && !f.nav && !w.first->fault_detected) f.align(fix, *w.first, w.note);
  } else {
    w.note = "raw pseudoranges gave no PL (" + w.first->note + (w.first->pl.reason.empty() ? "" : "; " + w.first->pl.reason) + ")";
    w.first.reset();
  }
}

void applyInsNominalPl(FixWork& w) {
  if (!w.fix.ins) return;
  const auto [h, v] = insNominalPl(*w.fix.ins);
  w.hpl_m = std::max(w.hpl_m.value_or(0.0), h);
  w.vpl_m = std::max(w.vpl_m.value_or(0.0), v);
}

bool requireProtectionLevels(const TrackedFlight& f, FixWork& w) {
  if (w.hpl_m && w.vpl_m) return true;
  w.out.push_back(rejectedFix(w.fix, f.id, "no protection level for the fix: " + (w.note.empty() ? "none given" : w.note)));
  return false;
}

bool checkFence(const TrackerOptions& o, const TrackedFlight& f, FixWork& w) {
  w.volume = volumeAt(f, w.fix.time, w.pos, *w.hpl_m, *w.vpl_m);
  try {
    // Into the fix's verdict, whose storage the tracker took from the previous fix's event.
    geofence::checkVolume(*f.level1, *f.level2, f.approver->obstructions(), w.volume, o.horizon_m, w.verdict);
  } catch (const std::invalid_argument& e) {  // e.g. a volume beyond the modelled heights
    w.out.push_back(rejectedFix(w.fix, f.id, std::string("the fix cannot be checked: ") + e.what()));
    return false;
  }
  return true;
}

namespace {

/// The rerun's solution.
struct RerunSolution {
  bool ok = false;
  maps::Geodetic pos;
  double hpl_m = 0.0, vpl_m = 0.0;
  std::vector<integrity::SatId> excluded;
  std::string note;
};

/// GNSS/INS: the epoch again from the filter as it was with one more exclusion allowed (the
/// flow's FDE already ran); raw ranges: the method's FDE.
RerunSolution rerunSolution(TrackedFlight& f, FixWork& w, bool detected) {
  const TrackFix& fix = w.fix;
  if (w.ins_epoch) {
    RerunSolution again{true, w.pos, *w.hpl_m, *w.vpl_m, w.ins_epoch->excluded, ""};
    if (detected && w.ins_before) {
      if (auto ep2 = f.deeperEpoch(*w.ins_before, fix)) {
        again = {true, maps::ecefToGeodetic(ep2->r_ecef_m), ep2->fault_mode_hpl_m, ep2->fault_mode_vpl_m, ep2->excluded, ""};
        w.ins_epoch = ep2;
      } else {
        again.note = "the epoch with one more exclusion gave no PL; the first pass stands";
      }
    }
    return again;
  }
  // The FDE goes on from the first pass's all-in-view solution; without a detected fault it
  // would give the first pass back (nothing to exclude).
  const integrity::LiveFix lf = detected ? integrity::excludeFaults(*w.first, f.live) : *w.first;
  RerunSolution again{lf.solved && lf.pl.pl_computed, lf.position, lf.pl.hpl_m, lf.pl.vpl_m, lf.excluded, lf.note + lf.pl.reason};
  // A filter not yet aligned can start from the solution without the faulty satellite.
  if (fix.imu && !f.nav && again.ok && lf.fault_excluded) f.align(fix, lf, w.note);
  return again;
}

/// Takes the rerun's solution when it has one: the position, PLs and the fence check again.
void applyRerunSolution(const TrackerOptions& o, const TrackedFlight& f, FixWork& w, const RerunSolution& again,
                        RerunReport& r) {
  if (!again.ok) {
    r.verdict_after = r.verdict_before;
    r.note = again.note;
    return;
  }
  w.pos = again.pos;
  w.hpl_m = again.hpl_m;
  w.vpl_m = again.vpl_m;
  w.excluded = again.excluded;
  const geofence::TimedVolume vol2 = volumeAt(f, w.fix.time, w.pos, *w.hpl_m, *w.vpl_m);
  try {
    w.verdict = fenceVerdict(o, f, vol2);
    w.volume = vol2;
  } catch (const std::invalid_argument& err) {
    r.note = std::string("the rerun's volume cannot be checked: ") + err.what();
  }
  r.hpl_after_m = *w.hpl_m;
  r.vpl_after_m = *w.vpl_m;
  r.verdict_after = worstVerdict(w.verdict, geofence::Level::kCorridor);
  if (!again.note.empty() && !r.note) r.note = again.note;
}

}  // namespace

void rerunMonitoring(const TrackerOptions& o, TrackedFlight& f, FixWork& w) {
  w.rerun = w.early_rerun;  // (GNSS/INS: already rerun for a fault it could not exclude)
  if (w.ins_epoch) w.excluded = w.ins_epoch->excluded;
  if (!(w.first || w.ins_epoch) || w.early_rerun) return;
  if (worstVerdict(w.verdict, geofence::Level::kCorridor) == geofence::Verdict::kInside) return;
  RerunReport r;
  r.detected = w.ins_epoch ? w.ins_epoch->gnss_fault_detected : w.first->fault_detected;
  r.hpl_before_m = *w.hpl_m;
  r.vpl_before_m = *w.vpl_m;
  r.verdict_before = worstVerdict(w.verdict, geofence::Level::kCorridor);
  const RerunSolution again = rerunSolution(f, w, r.detected);
  r.excluded = again.excluded;
  w.rerun = true;
  ++f.st.rerun_count;
  applyRerunSolution(o, f, w, again, r);
  // Its event is written on a detection and at the start of a level-1 episode (a PL that never
  // fits HAL₁ would otherwise repeat it at every fix).
  if (r.detected || !f.st.violated[static_cast<int>(geofence::Level::kCorridor)]) {
    w.out.push_back(monitoringRerunEvent(f.id, w.fix, r));
  }
}

namespace {

TrackEvent violationEvent(const TrackedFlight& f, const FixWork& w, geofence::Level level, geofence::Verdict v, bool pl_cause) {
  TrackEvent e = trackEvent("violation", f.id, w.fix.time);
  e["level"] = geofence::levelName(level);
  e["verdict"] = geofence::verdictWord(level, v);
  for (const geofence::Check& c : w.verdict.checks) {
    if (c.level != level || c.verdict == geofence::Verdict::kInside) continue;
    e.body.update(geofence::pickMembers(json(c), {"subject", "name", "restriction", "margin_h_m", "margin_v_m", "clearance_m"}));
    break;
  }
  if (level == geofence::Level::kCorridor) {
    e["cause"] = pl_cause ? "protection_level" : "position";
    e["rerun"] = w.rerun;
  }
  e["hpl_m"] = metresOrNull(*w.hpl_m);
  e["vpl_m"] = metresOrNull(*w.vpl_m);
  e["line"] = w.fix.line;
  return e;
}

/// `violation` at a level's first violated fix, `recovered` after recover_after fixes inside.
void levelEpisodes(const TrackerOptions& o, TrackedFlight& f, FixWork& w, const std::array<geofence::Verdict, kLevels>& lv,
                   bool pl_cause) {
  FlightState& st = f.st;
  for (int l = 0; l < kLevels; ++l) {
    const auto level = static_cast<geofence::Level>(l);
    if (lv[l] != geofence::Verdict::kInside) {
      st.inside_streak[l] = 0;
      if (!st.violated[l]) {
        st.violated[l] = true;
        w.out.push_back(violationEvent(f, w, level, lv[l], pl_cause));
      }
    } else if (st.violated[l] && ++st.inside_streak[l] >= o.recover_after) {
      st.violated[l] = false;
      TrackEvent e = trackEvent("recovered", f.id, w.fix.time);
      e["level"] = geofence::levelName(level);
      e["after_fixes"] = st.inside_streak[l];
      e["line"] = w.fix.line;
      w.out.push_back(std::move(e));
    }
  }
}

}  // namespace

void updatePersistence(const TrackerOptions& o, TrackedFlight& f, FixWork& w) {
  std::array<geofence::Verdict, kLevels> lv{};
  for (int l = 0; l < kLevels; ++l) lv[l] = worstVerdict(w.verdict, static_cast<geofence::Level>(l));
  const bool bad1 = lv[0] != geofence::Verdict::kInside;
  const bool bad2 = lv[1] != geofence::Verdict::kInside || lv[2] != geofence::Verdict::kInside ||
                    lv[3] != geofence::Verdict::kInside || lv[4] != geofence::Verdict::kInside;
  const bool pl_cause = *w.hpl_m > f.plan.level1.hal_m || *w.vpl_m > f.plan.level1.val_m;
  // The level-1 window counts the violations a replan can mend (by the position; also by the
  // PLs with replan_on_pl_exceedance), so PL excursions do not make a drift look persistent.
  const bool mendable1 = bad1 && (!pl_cause || o.replan_on_pl_exceedance);
  const int count1 = pushWindow(f.st.level1_window, mendable1, o.level1_n);
  const int count2 = pushWindow(f.st.level2_window, bad2, o.level2_n);
  levelEpisodes(o, f, w, lv, pl_cause);
  if (count2 >= o.level2_m && bad2) {
    w.trigger = lv[1] != geofence::Verdict::kInside   ? geofence::Level::kAirspace
                : lv[4] != geofence::Verdict::kInside ? geofence::Level::kKeepIn
                : lv[2] != geofence::Verdict::kInside ? geofence::Level::kZone
                                                      : geofence::Level::kObstacle;
  } else if (count1 >= o.level1_m && mendable1) {
    w.trigger = geofence::Level::kCorridor;
  }
}

void updateProgress(const TrackerOptions& o, TrackedFlight& f, const FixWork& w) {
  FlightState& st = f.st;
  const Eigen::Vector3d p_map = w.volume.volume.p_map;
  while (st.next_stop + 1 < f.stops.size() && (f.stops[st.next_stop] - p_map).head<2>().norm() <= o.waypoint_radius_m) {
    ++st.next_stop;
  }
  st.arrived = st.next_stop + 1 == f.stops.size() && (f.stops.back() - p_map).head<2>().norm() <= o.waypoint_radius_m;
}

void writeFixEvent(const TrackedFlight& f, FixWork& w) {
  TrackEvent e = trackEvent("fix", f.id, w.fix.time);
  FixRecord rec;
  rec.line = w.fix.line;
  rec.lat_rad = w.pos.lat_rad;
  rec.lon_rad = w.pos.lon_rad;
  rec.h_ell_m = w.pos.h_ell_m;
  rec.hpl_m = *w.hpl_m;
  rec.vpl_m = *w.vpl_m;
  rec.pl_source = w.source;
  if (w.first) rec.fault_detected = w.first->fault_detected;
  if (w.ins_epoch) {
    rec.fault_detected = w.ins_epoch->gnss_fault_detected;
    rec.ins_degraded = w.ins_epoch->degraded;
  }
  rec.excluded = std::move(w.excluded);
  rec.route_version = f.st.route_version;
  rec.rerun = w.rerun;
  rec.note = w.jump_note.empty() ? w.note : (w.note.empty() ? w.jump_note : w.jump_note + "; " + w.note);
  rec.verdict = std::move(w.verdict);
  e.fix = std::move(rec);
  w.out.push_back(std::move(e));
}

namespace {

/// An approved replan becomes the flight's route: both box levels, a new version, empty windows.
/// Whether a replan must wait for the vehicle to take the current route: the link's answer is
/// awaited, or it has neither joined the route (cleared in replanIfPersistent) nor run out of
/// join_timeout_s.
bool handoffHolds(const TrackerOptions& o, FlightState& st, const maps::GpsTime& t) {
  if (!st.handoff_since) return false;
  if (st.handoff_awaits_link) return true;
  if (t - *st.handoff_since < o.join_timeout_s) return true;
  st.handoff_since.reset();  // not joined in time: the route may be replanned again
  return false;
}

void takeNewRoute(TrackedFlight& f, const ApprovalReport& r, TrackEvent& rp) {
  json intent = operationalIntent(r, f.approver->frame());
  rp["operational_intent"] = std::move(intent["operational_intent"]);
  rp["corridor_volumes"] = std::move(intent["corridor_volumes"]);
  f.plan.route = r.route;
  f.plan.departure = r.departure;
  f.buildBoxes();
  ++f.st.route_version;
  // The new corridor starts with empty persistence windows; a level still marked violated is
  // `recovered` once the fixes are inside the new boxes.
  f.st.level1_window.clear();
  f.st.level2_window.clear();
}

}  // namespace

void holdReplanForHandoff(const TrackerOptions& o, TrackedFlight& f, FixWork& w) {
  FlightState& st = f.st;
  if (st.handoff_since && !st.handoff_awaits_link) {
    // Joined: as many fixes in a row inside the route's level-1 corridor as the persistence
    // window holds (a vehicle still flying its old route crosses the new corridor, it does not stay).
    const bool inside = worstVerdict(w.verdict, geofence::Level::kCorridor) == geofence::Verdict::kInside;
    st.handoff_inside = inside ? st.handoff_inside + 1 : 0;
    if (st.handoff_inside >= o.level1_n) st.handoff_since.reset();
  }
  if (!w.trigger || !o.replan || st.arrived || !handoffHolds(o, st, w.fix.time)) return;
  w.note += std::string(w.note.empty() ? "" : "; ") + "replan held: the vehicle has not yet taken route " +
            std::to_string(st.route_version) + (st.handoff_awaits_link ? " (awaiting the link's answer)" : "");
  w.trigger.reset();
}

void replanIfPersistent(const TrackerOptions& o, TrackedFlight& f, FixWork& w) {
  FlightState& st = f.st;
  const TrackFix& fix = w.fix;
  // (At the goal there is nowhere left to replan to: the violation stands.)
  if (!w.trigger || !o.replan || st.arrived || (st.last_replan && fix.time - *st.last_replan < o.replan_cooldown_s)) return;
  st.last_replan = fix.time;
  ++st.replans;
  TrackEvent rp = trackEvent("replan", f.id, fix.time);
  rp["trigger"] = geofence::levelName(*w.trigger);
  rp["from"] = {{"lat", maps::roundToDeg8(w.pos.lat_rad)}, {"lon", maps::roundToDeg8(w.pos.lon_rad)},
                {"h_ell_m", maps::roundToMm(w.pos.h_ell_m)}};
  rp["line"] = fix.line;
  ApprovalReport r;
  try {
    r = f.approver->replanFrom(w.volume.volume.p_map, fix.time, st.next_stop);
    rp["report"] = r;
  } catch (const std::exception& err) {  // the fix stays accepted; the replan is what failed
    rp["decision"] = "error";
    rp["error"] = err.what();
    rp["route_version"] = st.route_version;
    w.out.push_back(std::move(rp));
    return;
  }
  rp["decision"] = r.approved ? "approved" : "rejected";
  rp.body["report"].erase("predicted");  // the samples stay in the tracker's database with the route
  if (r.approved) {
    takeNewRoute(f, r, rp);
    st.handoff_since = fix.time;
    st.handoff_awaits_link = o.handoff_by_link;
    st.handoff_inside = 0;
  }
  rp["route_version"] = st.route_version;
  rp["planning_time_s"] = std::round(r.elapsed_s * 1e4) / 1e4;
  w.out.push_back(std::move(rp));
}

}  // namespace skylane::planner
