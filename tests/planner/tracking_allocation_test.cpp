// A stream of fixes makes no allocation per fix once its storage has grown: a plain JSON line is
// read into the caller's fix (parseTrackFixLine(text, source, fix)), the tracker's events go into
// the caller's list, the fix event's checks into the storage of the previous fix event
// (Tracker::process(fix, events)), and the event line is written into a reused buffer without a
// string of its own for any value. Its own executable: it counts every operator new of the process.
#include "maps/json_node.hpp"
#include "maps/text_file.hpp"
#include "planner/approval.hpp"
#include "planner/report_formats.hpp"
#include "planner/tracking/event_sink.hpp"
#include "planner/tracking/fix_source.hpp"
#include "planner/tracking/tracker.hpp"
#include "planner/tracking/tracking_session.hpp"
#include "tests/allocation_counter.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace skylane::planner {
namespace {

const std::string kExampleDir = std::string(SKYLANE_TEST_DATA) + "/../../examples/approve";

/// The bundled example, approved once.
struct Example {
  std::shared_ptr<Approver> approver;
  ApprovalReport report;
  ApprovedFlight flight;
};

const Example& example() {
  static const Example e = [] {
    Example x;
    const nlohmann::json doc = maps::readJsonFile(kExampleDir + "/mission.json");
    x.approver = std::make_shared<Approver>(parseMission(doc, kExampleDir + "/mission.json", kExampleDir));
    x.report = x.approver->approve();
    x.flight = parseApprovalReport(nlohmann::json(x.report), "report.json");
    return x;
  }();
  return e;
}

/// Plain JSON lines of flight "F1" on the approved route, one every `step_s` for the first
/// `span_s` seconds after departure, with PLs of 0.5 m (every fix inside).
std::vector<std::string> lines(double step_s, double span_s) {
  const Example& e = example();
  std::vector<std::string> out;
  for (double t = 0.0; t < span_s; t += step_s) {
    const Eigen::Vector3d p = positionAlong(e.report.route, t);
    const Eigen::Vector2d ll = e.approver->frame().toLatLon(p.head<2>());
    char text[256];
    std::snprintf(text, sizeof text,
                  R"({"flight":"F1","time":"%s","lat":%.9f,"lon":%.9f,"h_ell_m":%.3f,"hpl_m":0.5,"vpl_m":0.5})",
                  maps::formatRfc3339(e.report.departure.plus(t), 3).c_str(), maps::rad2deg(ll.x()),
                  maps::rad2deg(ll.y()), p.z());
    out.emplace_back(text);
  }
  return out;
}

TEST(TrackingAllocations, ReadingTrackingAndWritingAFixAllocateNothingOnceGrown) {
  Tracker tracker;
  tracker.addFlight("F1", example().flight, example().approver);
  const std::vector<std::string> text = lines(1.0, 60.0);
  TrackFix fix;
  std::vector<TrackEvent> events;
  std::string source, out;
  long allocations = 0, fix_events = 0;
  for (std::size_t k = 0; k < text.size(); ++k) {
    source.assign("a/path/to/the/input/fixes.jsonl:");  // longer than a string keeps inline
    source += std::to_string(k + 1);
    const long made = test::allocationsOf([&] {
      parseTrackFixLine(text[k], source, fix);
      fix.line = k + 1;
      tracker.process(fix, events);
      out.clear();
      for (const TrackEvent& e : events) e.appendJsonLine(out);
    });
    if (k >= 20) allocations += made;  // the first fixes grow the storage
    for (const TrackEvent& e : events) fix_events += e.is("fix") && e.fix->verdict.verdict == geofence::Verdict::kInside;
  }
  EXPECT_EQ(fix_events, 60);  // every fix taken and inside: the path measured is the common one
  EXPECT_EQ(allocations, 0);
  // The same events as the allocating way (a fresh list and fix every time).
  Tracker again;
  again.addFlight("F1", example().flight, example().approver);
  std::vector<TrackEvent> last;
  for (std::size_t k = 0; k < text.size(); ++k) {
    TrackFix f = parseTrackFixLine(text[k], "x:" + std::to_string(k + 1));
    f.line = k + 1;
    last = again.process(f);
  }
  ASSERT_EQ(last.size(), events.size());
  EXPECT_EQ(last.back().jsonLine(), events.back().jsonLine());
}

/// A sink that only counts.
class CountingSink final : public EventSink {
 public:
  void write(const TrackEvent&, const std::string& line) override {
    ++events;
    bytes += line.size();
  }
  long events = 0;
  std::size_t bytes = 0;
};

/// The allocations of one session over a file of `text` (its set-up included).
long sessionAllocations(const std::vector<std::string>& text, long& events) {
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "skylane-tracking-allocations.jsonl";
  {
    std::ofstream f(file);
    for (const std::string& l : text) f << l << '\n';
  }
  TrackingSession session({}, nullptr);
  session.tracker().addFlight("F1", example().flight, example().approver);
  CountingSink sink;
  session.addSink(sink);
  JsonLinesFixSource source(openLineInput(file.string()));
  const long made = test::allocationsOf([&] { (void)session.run(source); });
  events = sink.events;
  std::filesystem::remove(file);
  return made;
}

TEST(TrackingAllocations, ASessionOverAFileAllocatesNothingPerFix) {
  // The same first minute of the flight at 5 Hz and at 10 Hz: the same waypoints and events but
  // for the fix events, so any difference in allocations is per fix.
  long events_5 = 0, events_10 = 0;
  (void)sessionAllocations(lines(0.2, 60.0), events_5);  // grows what lives longer than a session (per-thread scratch)
  const long at_5 = sessionAllocations(lines(0.2, 60.0), events_5);
  const long at_10 = sessionAllocations(lines(0.1, 60.0), events_10);
  EXPECT_EQ(events_10 - events_5, 300);
  EXPECT_EQ(at_10 - at_5, 0) << at_5 << " allocations for 300 fixes, " << at_10 << " for 600";
}

}  // namespace
}  // namespace skylane::planner
