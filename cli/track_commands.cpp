#include "cli/track_commands.hpp"

#include "cli/approve_commands.hpp"
#include "cli/progress.hpp"
#include "cli/svg_plot.hpp"

#include "integrity/gnss/nmea.hpp"
#include "integrity/raim/spp.hpp"
#include "integrity/sim/scenario.hpp"
#include "link/mavlink/fix_source.hpp"
#include "link/mavlink/handoff.hpp"
#include "link/plan_file_sink.hpp"
#include "link/ubx/fix_source.hpp"
#include "maps/atomic_file.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"
#include "planner/report_formats.hpp"
#include "planner/rehearsal/flight_sim.hpp"
#include "planner/tracking/event_file_sink.hpp"
#include "planner/tracking/tracker.hpp"
#include "planner/tracking/tracking_session.hpp"


#include <sys/stat.h>

#include <atomic>
#include <csignal>
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace skylane::cli {
namespace {

using maps::ParseError;
using nlohmann::json;

/// The running session's stop flag, for the signal handler.
std::atomic<std::atomic<bool>*> g_stop{nullptr};
extern "C" void onStopSignal(int) {
  if (std::atomic<bool>* stop = g_stop.load()) stop->store(true);
}

struct TrackOptions {
  std::vector<std::string> approvals;
  std::string input = "-";
  std::string format = "jsonl";
  int baud = 57600;
  int udp_buffer = 0;  ///< a UDP input's receive buffer [bytes] (0: the system default)
  bool no_handoff = false;
  std::string plans;  ///< directory for each replan's .plan
  std::vector<std::string> navs;
  std::string date;
  std::string db;
  std::string out;
  std::string level1 = "3/5";  ///< parsed into tracker.level1_m/_n
  std::string level2 = "1/1";
  bool no_replan = false;
  planner::TrackerOptions tracker;  ///< the defaults live there; the options write into it
  int batch = 200;
  std::string map;
};

/// What the map of a run shows: each flight's routes (the approved one and every accepted
/// replan), its track coloured by verdict, and the events that matter.
class TrackMap final : public planner::EventSink {
 public:
  void write(const planner::TrackEvent& e, const std::string& /*json_line*/) override { add(e); }
  void route(const std::string& flight, const std::vector<Eigen::Vector2d>& lat_lon_rad) { routes_[flight].push_back(lat_lon_rad); }
  void add(const planner::TrackEvent& e) {
    if (e.fix) {
      tracks_[e.flight].push_back({e.fix->lat_rad, e.fix->lon_rad, static_cast<int>(e.fix->verdict.verdict)});
      // The start of each exclusion and of each GNSS-alone stretch (IMU fault) is marked.
      Episodes& ep = episodes_[e.flight];
      std::string excluded;
      for (const integrity::SatId& s : e.fix->excluded) excluded += (excluded.empty() ? "" : ", ") + s.str();
      const Eigen::Vector2d here(e.fix->lat_rad, e.fix->lon_rad);
      if (!excluded.empty() && excluded != ep.excluded) marks_.push_back({here, "excluded " + excluded, "#17becf"});
      ep.excluded = excluded;
      const bool degraded = e.fix->ins_degraded.value_or(false);
      if (degraded && !ep.degraded) marks_.push_back({here, "GNSS alone (IMU fault)", "#8c564b"});
      ep.degraded = degraded;
      return;
    }
    if (!e.time || e.flight.empty()) return;
    if (e.is("replan") && e.body.value("decision", "") == "approved") {
      std::vector<Eigen::Vector2d> pts;
      for (const json& p : e.body.at("report").at("route")) {
        pts.emplace_back(maps::deg2rad(p.at("lat").get<double>()), maps::deg2rad(p.at("lon").get<double>()));
      }
      route(e.flight, pts);
      marks_.push_back({pts.front(), "replan " + std::to_string(e.body.value("route_version", 0)) + " (" +
                                         e.body.value("trigger", "") + ")", "#9467bd"});
    } else if (e.is("violation") && !tracks_[e.flight].empty()) {
      const auto& last = tracks_[e.flight].back();
      const std::string cause = e.body.value("cause", e.body.value("subject", ""));
      marks_.push_back({{last.lat, last.lon}, e.body.value("level", "") + " (" + cause + ")", "#d62728"});
    }
  }
  std::string svg(const planner::Tracker& tracker) const {
    const std::string first = tracker.flights().front();
    const planner::Approver& a = tracker.approver(first);
    const maps::PlaneFrame& frame = a.frame();
    auto plane = [&frame](const Eigen::Vector2d& ll) {
      const Eigen::Vector2d q = frame.toPlane(ll.x(), ll.y());
      return std::pair<double, double>(q.x(), q.y());
    };
    std::vector<MapShape> shapes = obstructionShapes(a.obstructions(), frame);
    std::vector<MapLine> lines;
    for (const auto& [flight, versions] : routes_) {
      const planner::Mission& m = tracker.approver(flight).mission();
      const geofence::LevelLimits lim = geofence::alertLimits(m.vehicle, m.levels);
      // Replanned routes first, the approved one drawn over them (they share their first part).
      std::vector<std::size_t> order;
      for (std::size_t v = 1; v < versions.size(); ++v) order.push_back(v);
      order.push_back(0);
      for (std::size_t v : order) {
        MapLine l;
        l.stroke = v == 0 ? "#000000" : "#9467bd";
        l.width_px = v == 0 ? 1.5 : 3.0;
        l.legend = v == 0 ? "approved route" : "replanned route";
        for (const Eigen::Vector2d& ll : versions[v]) l.xy.push_back(plane(ll));
        for (std::size_t i = 1; i < l.xy.size(); ++i) {
          const Eigen::Vector3d p0(l.xy[i - 1].first, l.xy[i - 1].second, 0), p1(l.xy[i].first, l.xy[i].second, 0);
          for (int level : {2, 1}) {
            MapShape box;
            const double hal = level == 1 ? lim.level1.hal_m : lim.level2.hal_m;
            for (const Eigen::Vector2d& c : planner::segmentOutline(p0, p1, hal)) box.xy.emplace_back(c.x(), c.y());
            box.fill = box.stroke = v == 0 ? (level == 1 ? "#1f77b4" : "#aec7e8") : (level == 1 ? "#9467bd" : "#c5b0d5");
            box.fill_opacity = level == 1 ? 0.5 : 0.12;
            box.legend = std::string(v == 0 ? "" : "new ") + (level == 1 ? "corridor (level 1)" : "airspace (level 2)");
            shapes.push_back(std::move(box));
          }
        }
        lines.push_back(std::move(l));
      }
    }
    static const char* kColour[] = {"#2ca02c", "#d62728", "#ff7f0e"};
    static const char* kLegend[] = {"track: inside", "track: outside", "track: indeterminate"};
    for (const auto& [flight, pts] : tracks_) {
      for (std::size_t i = 0; i < pts.size();) {
        MapLine l;
        l.stroke = kColour[pts[i].verdict];
        l.legend = kLegend[pts[i].verdict];
        l.width_px = 3.0;
        if (i > 0) l.xy.push_back(plane({pts[i - 1].lat, pts[i - 1].lon}));
        std::size_t j = i;
        for (; j < pts.size() && pts[j].verdict == pts[i].verdict; ++j) l.xy.push_back(plane({pts[j].lat, pts[j].lon}));
        lines.push_back(std::move(l));
        i = j;
      }
    }
    std::vector<MapMarker> markers;
    for (const Mark& m : marks_) {
      const auto [x, y] = plane(m.lat_lon);
      markers.push_back({x, y, m.label, m.colour});
    }
    std::size_t fixes = 0;
    for (const auto& [flight, pts] : tracks_) fixes += pts.size();
    return renderPlanMapSvg("skylane track: " + std::to_string(tracks_.size()) + " flight(s), " + std::to_string(fixes) + " fixes",
                            shapes, lines, markers, 150.0,
                            {"track coloured by the fix verdict (corridor, airspace, zones, obstacles)",
                             "purple: replans from where the vehicle was; red: violations; cyan: satellites excluded;",
                             "brown: GNSS alone after an IMU fault (GNSS/INS)"});
  }

 private:
  struct Point {
    double lat, lon;
    int verdict;
  };
  struct Mark {
    Eigen::Vector2d lat_lon;
    std::string label, colour;
  };
  std::map<std::string, std::vector<std::vector<Eigen::Vector2d>>> routes_;
  std::map<std::string, std::vector<Point>> tracks_;
  struct Episodes {
    std::string excluded;  ///< the satellites the last fix left out
    bool degraded = false;
  };
  std::vector<Mark> marks_;
  std::map<std::string, Episodes> episodes_;
};

std::pair<int, int> parseMofN(const std::string& text, const char* option) {
  int m = 0, n = 0;
  char slash = 0;
  std::istringstream s(text);
  if (!(s >> m >> slash >> n) || slash != '/' || !s.eof() || m < 1 || n < m) {
    throw ParseError(option, 0, option, text, "M/N with 1 ≤ M ≤ N (M violated fixes of the last N)");
  }
  return {m, n};
}

/// The tracker's options from the command line (the M/N rules, --no-replan).
/// Whether the vehicle can be answered on the input: a MAVLink stream over UDP or a serial device.
bool linkCanUpload(const TrackOptions& o) {
  if (o.format != "mavlink" || o.no_handoff) return false;
  struct stat info {};
  return o.input.rfind("udp://", 0) == 0 || (stat(o.input.c_str(), &info) == 0 && S_ISCHR(info.st_mode));
}

/// A longest time a tracker option can name (a day of stream time).
constexpr double kMaxTrackerSeconds = 86400.0;
/// The widest horizon a fix event lists zones within.
constexpr double kMaxHorizon_m = 100e3;

/// The tracker's numeric options in their ranges, each error naming the option as typed.
void requireTrackerRanges(const planner::TrackerOptions& t) {
  const auto need = [](bool ok, const char* option, double value, const char* expected) {
    if (ok) return;
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    throw ParseError(option, 0, option, text, expected);
  };
  need(t.stale_after_s > 0 && t.stale_after_s <= kMaxTrackerSeconds, "--stale-after", t.stale_after_s, "seconds in (0, 86400]");
  need(t.max_time_jump_s > 0 && t.max_time_jump_s <= kMaxTrackerSeconds, "--max-time-jump", t.max_time_jump_s,
       "seconds in (0, 86400]");
  need(t.replan_cooldown_s >= 0 && t.replan_cooldown_s <= kMaxTrackerSeconds, "--cooldown", t.replan_cooldown_s,
       "seconds in [0, 86400]");
  need(t.join_timeout_s > 0 && t.join_timeout_s <= kMaxTrackerSeconds, "--join-timeout", t.join_timeout_s, "seconds in (0, 86400]");
  need(t.horizon_m >= 0 && t.horizon_m <= kMaxHorizon_m, "--horizon", t.horizon_m, "metres in [0, 100000]");
  need(t.recover_after >= 1, "--recover-after", t.recover_after, "a whole number ≥ 1");
  need(t.jump_confirm >= 1, "--jump-confirm", t.jump_confirm, "a whole number ≥ 1");
}

planner::TrackerOptions trackerOptions(const TrackOptions& o) {
  requireTrackerRanges(o.tracker);
  planner::TrackerOptions topt = o.tracker;
  topt.handoff_by_link = linkCanUpload(o);
  std::tie(topt.level1_m, topt.level1_n) = parseMofN(o.level1, "--level1");
  std::tie(topt.level2_m, topt.level2_n) = parseMofN(o.level2, "--level2");
  topt.replan = !o.no_replan;
  return topt;
}

/// Every --approval ([ID=]FILE), unless the database gave it back already.
void addApprovals(planner::TrackingSession& session, const TrackOptions& o) {
  for (const std::string& a : o.approvals) {
    const auto eq = a.find('=');
    const std::string id = eq == std::string::npos ? "" : a.substr(0, eq);
    const std::string path = eq == std::string::npos ? a : a.substr(eq + 1);
    (void)session.addApprovalFile(path, id);
  }
  const planner::Tracker& tracker = session.tracker();
  if (tracker.flights().empty()) throw ParseError("--approval", 0, "--approval", "", "at least one approval report");
  if (o.format != "jsonl" && tracker.flights().size() != 1) {
    throw ParseError("--format", 0, "--format", o.format, "one approval (an NMEA, RINEX, MAVLink or UBX stream is one vehicle)");
  }
}

/// The fix source of --input and --format (`log` hears of a smaller UDP buffer than asked for).
std::unique_ptr<planner::FixSource> openFixSource(const TrackOptions& o, const planner::Tracker& tracker,
                                                  const std::function<void(const std::string&)>& log) {
  const planner::DatagramOptions udp{o.udp_buffer, log};
  if (o.format == "rinex") {
    // Replay: skylane's own position and PLs at every epoch, with the mission's integrity
    // method, mask and error model, as for its approval.
    const planner::Mission& m = tracker.approver(tracker.onlyFlight()).mission();
    integrity::SppConfig cfg;
    cfg.method = m.method;
    cfg.model = m.model;
    cfg.elevation_mask_rad = maps::deg2rad(m.mask_deg);
    return std::make_unique<planner::RinexReplayFixSource>(o.input, o.navs, cfg);
  }
  if (o.format == "mavlink") {
    return std::make_unique<link::mavlink::MavlinkFixSource>(link::openByteLink(o.input, o.baud, udp), std::string());
  }
  if (o.format == "ubx") return std::make_unique<link::ubx::UbxFixSource>(link::openByteLink(o.input, o.baud, udp), std::string());
  std::unique_ptr<planner::LineInput> in = planner::openLineInput(o.input, udp);
  if (o.format == "jsonl") return std::make_unique<planner::JsonLinesFixSource>(std::move(in));
  std::optional<integrity::NmeaDate> date;
  if (!o.date.empty()) {
    const auto t = maps::parseRfc3339(o.date + "T00:00:00Z");
    if (!t) throw ParseError("--date", 0, "--date", o.date, "a date YYYY-MM-DD (for NMEA streams without RMC/ZDA)");
    const maps::CalendarTime c = maps::utcFromGps(*t);
    date = integrity::NmeaDate{{0.0}, c.year, c.month, c.day};
  }
  return std::make_unique<planner::NmeaFixSource>(std::move(in), date);
}

/// SIGTERM and SIGINT request a stop (without SA_RESTART: a blocking read returns at once and the
/// session sees the flag); a broken pipe is an error on the write, not the end of the process.
void installStopSignals(std::atomic<bool>& stop) {
  g_stop = &stop;
  struct sigaction on_stop {};
  on_stop.sa_handler = onStopSignal;
  sigemptyset(&on_stop.sa_mask);
  sigaction(SIGTERM, &on_stop, nullptr);
  sigaction(SIGINT, &on_stop, nullptr);
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGPIPE, &ignore, nullptr);
}

/// Each flight's approved (or current) route on the map.
void drawRoutes(TrackMap& map, const planner::Tracker& tracker) {
  for (const std::string& id : tracker.flights()) {
    std::vector<Eigen::Vector2d> pts;
    const json route = tracker.routeJson(id);  // named: a range over a temporary's member dangles
    for (const json& p : route.at("route")) {
      pts.emplace_back(maps::deg2rad(p.at("lat").get<double>()), maps::deg2rad(p.at("lon").get<double>()));
    }
    map.route(id, pts);
  }
}

/// A session stopped by a failed write of its event stream: a full disk or a lost file is an
/// error naming it; a closed pipe (the reader has gone) is the clean stop the summary reports.
void requireOutputWritten(const planner::JsonLinesSink& out, const std::string& path) {
  if (!out.closed()) return;
  if (out.error() != EPIPE) throw maps::OutputError(path.empty() ? "standard output" : path, path.empty() ? "" : "--out",
                                                    maps::systemReason(out.error() != 0 ? out.error() : EIO));
  if (path.empty()) {  // nothing more can reach the reader: not an error at exit either
    std::cout.clear();
    std::clearerr(stdout);
  }
}

/// The event stream: with --out and --db a file kept in step with the database (every event
/// exactly once across kills and restarts: planner/tracking/event_file_sink.hpp); otherwise JSON
/// lines appended to --out or written to standard output as they come.
struct EventOutput {
  std::unique_ptr<planner::EventFileSink> file;
  std::ofstream stream_file;
  std::unique_ptr<planner::JsonLinesSink> lines;
  planner::EventSink& sink() { return file ? static_cast<planner::EventSink&>(*file) : *lines; }
};

void openEventOutput(EventOutput& out, const TrackOptions& o, planner::TrackingSession& session,
                     const std::function<void(const std::string&)>& log) {
  if (!o.out.empty() && session.store()) {
    out.file = std::make_unique<planner::EventFileSink>(o.out, *session.store());
    if (out.file->repairedLines() > 0) {
      log(o.out + ": its last batch was cut short; written again from the database (" +
          std::to_string(out.file->repairedLines()) + " events)");
    }
    return;
  }
  if (!o.out.empty()) {
    out.stream_file.open(o.out, std::ios::app);
    if (!out.stream_file) throw maps::OutputError(o.out, "--out", maps::systemReason(errno));
  }
  out.lines = std::make_unique<planner::JsonLinesSink>(o.out.empty() ? std::cout : out.stream_file);
}

void runTrack(const TrackOptions& o) {
  if (o.format != "jsonl" && o.format != "nmea" && o.format != "rinex" && o.format != "mavlink" && o.format != "ubx") {
    throw ParseError("--format", 0, "--format", o.format, "jsonl, nmea, rinex, mavlink or ubx");
  }
  auto log = [](const std::string& m) { std::cerr << "skylane: track: " << m << "\n"; };
  planner::TrackingSession session(trackerOptions(o), o.db.empty() ? nullptr : std::make_unique<planner::TrackStore>(o.db),
                                   o.batch, log);
  session.resumeFlights();
  addApprovals(session, o);
  TrackMap track_map;
  drawRoutes(track_map, session.tracker());
  // The map is staged before the run (a path that cannot be written fails at once) and
  // replaces an earlier one when the run has ended (maps/atomic_file.hpp).
  std::unique_ptr<maps::AtomicFile> map_file = o.map.empty() ? nullptr : std::make_unique<maps::AtomicFile>(o.map, "--map");
  EventOutput out;
  openEventOutput(out, o, session, log);
  session.addSink(out.sink());
  if (!o.map.empty()) session.addSink(track_map);
  installStopSignals(session.stopFlag());
  const std::unique_ptr<planner::FixSource> source = openFixSource(o, session.tracker(), log);
  // A MAVLink vehicle gets each new route and fence by the mission protocol on the same link.
  std::unique_ptr<link::mavlink::MavlinkHandoff> handoff;
  if (session.tracker().options().handoff_by_link) {
    handoff = std::make_unique<link::mavlink::MavlinkHandoff>(dynamic_cast<link::mavlink::MavlinkFixSource&>(*source), session.tracker());
    session.addSink(*handoff);
    session.addTicker([h = handoff.get()] { return h->tick(); });
  }
  std::unique_ptr<link::PlanFileSink> plans;
  if (!o.plans.empty()) {
    plans = std::make_unique<link::PlanFileSink>(o.plans, session.tracker(), log);
    session.addSink(*plans);
  }
  const planner::SessionSummary sum = session.run(*source);
  if (out.lines) requireOutputWritten(*out.lines, o.out);
  if (map_file) {
    map_file->stream() << track_map.svg(session.tracker());
    map_file->commit();
    log("wrote " + o.map);
  }
  log(std::to_string(sum.accepted) + " fix" + (sum.accepted == 1 ? "" : "es") + " accepted, " + std::to_string(sum.rejected) +
      " rejected, " + (sum.dropped ? std::to_string(*sum.dropped) + " datagrams dropped by the kernel, " : std::string()) +
      std::to_string(sum.events) + " events" +
      (sum.output_closed ? " (stopped: the output was closed; state saved)" : sum.stopped ? " (stopped by a signal; state saved)" : ""));
}

struct FlyOptions {
  std::string report, out, imu, faults, flight, truth;
  std::uint64_t seed = 1;
  bool no_aiding = false;
  bool progress = false;
};

/// `skylane fly`: an approved route flown by the simulator, written as tracker input.
void runFly(const FlyOptions& o) {
  const planner::ApprovedFlight plan = planner::parseApprovalReport(maps::readJsonFile(o.report), o.report);
  if (!plan.approved) throw ParseError(o.report, 0, "$.decision", "rejected", "an approved route");
  const planner::Approver approver(planner::loadMission(planner::approvedMissionPath(plan, o.report)));
  planner::FlightSimOptions sim;
  sim.flight = o.flight.empty() ? plan.mission_name : o.flight;
  sim.seed = o.seed;
  if (!o.imu.empty()) {
    const auto grade = integrity::ins::parseImuGrade(o.imu);
    if (!grade) throw ParseError("--imu", 0, "--imu", o.imu, "aviation, tactical or consumer");
    planner::ImuFeed feed;
    feed.grade = *grade;
    feed.aiding = !o.no_aiding;
    sim.imu = feed;
  }
  if (!o.faults.empty()) {
    // A list of faults in the scenario format ("skylane simulate"), or {"faults": [...]}.
    const json doc = maps::readJsonFile(o.faults);
    const maps::JsonNode root{doc, "$", o.faults};
    const maps::JsonNode list = doc.is_object() ? root.at("faults") : root;
    for (std::size_t i = 0; i < list.array().size(); ++i) sim.faults.push_back(integrity::sim::parseFault(list.item(i)));
  }
  // Both files are staged and written in place only when the flight has been written whole.
  maps::OutputSet outputs;
  std::ostream& out = outputs.add(o.out, "--out");
  std::ostream* truth = o.truth.empty() ? nullptr : &outputs.add(o.truth, "--truth");
  if (truth) *truth << "line,time,t_s,lat_deg,lon_deg,h_ell_m,faulty_sat\n";
  Progress bar("flying", o.progress);
  const std::vector<planner::SimulatedFix> fixes =
      planner::simulateFlight(plan, approver, sim, [&bar](double f) { bar(static_cast<std::size_t>(f * 1000.0), 1000); });
  if (fixes.empty()) throw ParseError(o.report, 0, "$.route", "", "a route long enough for one GNSS epoch (1 s of flight)");
  for (const planner::SimulatedFix& f : fixes) {
    out << planner::trackFixJson(f.fix).dump() << '\n';
    if (truth) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "%zu,%s,%.3f,%.9f,%.9f,%.4f,%s\n", f.fix.line, maps::formatRfc3339(f.fix.time, 3).c_str(),
                    f.t_s, maps::rad2deg(f.truth.lat_rad), maps::rad2deg(f.truth.lon_rad), f.truth.h_ell_m,
                    f.faulty ? f.faulty->str().c_str() : "");
      *truth << buf;
    }
  }
  outputs.commit();
  std::cerr << "skylane: fly: " << fixes.size() << " fixes of flight " << sim.flight << " (" << fixes.front().t_s << "–"
            << fixes.back().t_s << " s" << (sim.imu ? ", with IMU increments" : "") << ", " << sim.faults.size()
            << " fault(s)) written to " << o.out << "\n";
}

}  // namespace

void addTrackCommands(CLI::App& app) {
  {
    auto o = std::make_shared<FlyOptions>();
    CLI::App* c = app.add_subcommand(
        "fly", "fly an approved route with the GNSS/INS simulator (real orbits, the error model, faults) and write the fixes for skylane track");
    c->add_option("report", o->report, "approval report (skylane approve --out DIR: DIR/report.json)")->required();
    c->add_option("--out", o->out, "the fixes, as JSON lines for skylane track --format jsonl")->required();
    c->add_option("--imu", o->imu, "also write the IMU's increments, velocity and attitude: aviation, tactical or consumer");
    c->add_flag("--no-aiding", o->no_aiding, "with --imu: no barometer or magnetometer in the fixes");
    c->add_option("--faults", o->faults, "faults to inject, as the scenario's \"faults\" (skylane simulate): a JSON array or {\"faults\": [...]}");
    c->add_option("--seed", o->seed, "random seed of the sensors and faults")->capture_default_str();
    c->add_option("--flight", o->flight, "the flight id in every fix (default: the mission's name)");
    c->add_option("--truth", o->truth, "write the true positions and the faulty satellite per fix to this CSV");
    c->add_flag("--progress", o->progress, "show a progress bar even when stderr is not a terminal");
    c->callback([o]() { runFly(*o); });
  }
  auto o = std::make_shared<TrackOptions>();
  CLI::App* c = app.add_subcommand(
      "track", "live corridor tracking: check each fix against its corridor, airspace and zones; rerun monitoring; replan");
  c->add_option("--approval", o->approvals, "approval report (skylane approve --out DIR: DIR/report.json), as [ID=]FILE; repeatable")
      ->required();
  c->add_option("--input", o->input, "FILE, - (stdin), udp://127.0.0.1:PORT or (mavlink) a serial device");
  c->add_option("--format", o->format,
                "jsonl, nmea (GGA + GST [+ GBS]), rinex (observation replay; needs --nav), mavlink (MAVLink 1/2 telemetry) or "
                "ubx (u-blox NAV-PVT with NAV-PL)");
  c->add_option("--baud", o->baud, "serial device speed for --format mavlink or ubx (default 57600)");
  c->add_option("--udp-buffer", o->udp_buffer,
                "a udp:// input's socket receive buffer in bytes (default: the system's; the kernel caps it at "
                "net.core.rmem_max and the granted size is said when smaller); datagrams dropped when it is full are "
                "reported as input_dropped events")
      ->check(CLI::Range(planner::kMinReceiveBufferBytes, planner::kMaxReceiveBufferBytes));
  c->add_flag("--no-handoff", o->no_handoff, "--format mavlink: do not upload replanned routes to the vehicle");
  c->add_option("--plans", o->plans, "write each accepted replan as DIR/<flight>-route<N>.plan (QGroundControl)");
  c->add_option("--join-timeout", o->tracker.join_timeout_s,
                "seconds a new route waits for the vehicle to join it before another replan (default 60)");
  c->add_option("--nav", o->navs, "RINEX navigation file(s) for --format rinex");
  c->add_option("--date", o->date, "UTC date YYYY-MM-DD of an NMEA stream without RMC/ZDA");
  c->add_option("--db", o->db, "SQLite database: approvals, flight states and events; a restart resumes from it");
  c->add_option("--out", o->out, "append the events to this file (default: stdout)");
  c->add_option("--level1", o->level1, "level-1 persistence M/N before a replan (default 3/5)");
  c->add_option("--level2", o->level2, "level-2, zone and obstacle persistence M/N (default 1/1: at once)");
  planner::TrackerOptions& t = o->tracker;
  c->add_option("--recover-after", t.recover_after, "fixes in a row inside a level before 'recovered'")->capture_default_str();
  c->add_option("--stale-after", t.stale_after_s, "seconds without a fix before 'stale'")->capture_default_str();
  c->add_option("--cooldown", t.replan_cooldown_s, "least seconds between two replans of a flight")->capture_default_str();
  c->add_option("--max-time-jump", t.max_time_jump_s, "a fix more than this many seconds from the last is a time jump")
      ->capture_default_str();
  c->add_option("--jump-confirm", t.jump_confirm, "fixes in order on a jumped timeline before it is taken")->capture_default_str();
  c->add_flag("--no-replan", o->no_replan, "report violations without replanning");
  c->add_flag("--replan-on-pl", t.replan_on_pl_exceedance, "also replan when level 1 is violated by the PLs alone");
  c->add_option("--horizon", t.horizon_m, "list zones and obstacles within this distance of a volume in its fix event [m]")
      ->capture_default_str();
  c->add_option("--map", o->map, "write an SVG map: zones, buildings, routes and corridors (approved and replanned), the track by verdict, events");
  c->add_option("--batch", o->batch, "fixes per database transaction (default 200)");
  c->callback([o]() { runTrack(*o); });
}

}  // namespace skylane::cli
