// The tracking engine as a library: a session driven by in-memory and file sources, with
// in-memory sinks — no CLI. Resume from the database after a stop, a bad record skipped, a
// closed sink stopping the run, and the same events as the tracker alone.
#include "planner/tracking/tracking_session.hpp"

#include "maps/text_file.hpp"
#include "planner/tracking/fix_source.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <memory>

namespace skylane::planner {
namespace {

using nlohmann::json;

const std::string kExampleDir = std::string(SKYLANE_TEST_DATA) + "/../../examples/approve";

/// The bundled example approved once, its report written to a scratch file.
struct Example {
  std::shared_ptr<Approver> approver;
  ApprovalReport report;
  std::string report_path;
};

const Example& example() {
  static const Example e = [] {
    Example x;
    x.approver = std::make_shared<Approver>(loadMission(kExampleDir + "/mission.json"));
    x.report = x.approver->approve();
    x.report_path = test::scratchPath("session_report.json");
    std::ofstream(x.report_path) << nlohmann::json(x.report).dump(2);
    return x;
  }();
  return e;
}

/// `n` fixes along the approved route, one per second, with small onboard PLs.
std::vector<TrackFix> fixesAlongRoute(int n) {
  const Example& ex = example();
  std::vector<TrackFix> out;
  for (int k = 0; k < n; ++k) {
    TrackFix f;
    f.flight = "F1";
    f.time = ex.report.departure.plus(k);
    const Eigen::Vector3d p = positionAlong(ex.report.route, k);
    const Eigen::Vector2d ll = ex.approver->frame().toLatLon(p.head<2>());
    f.lat_rad = ll.x();
    f.lon_rad = ll.y();
    f.h_ell_m = p.z();
    f.hpl_m = 0.5;
    f.vpl_m = 0.6;
    out.push_back(f);
  }
  return out;
}

std::vector<std::string> jsonLines(const std::vector<TrackFix>& fixes) {
  std::vector<std::string> lines;
  for (const TrackFix& f : fixes) lines.push_back(trackFixJson(f).dump());
  return lines;
}

std::size_t count(const MemorySink& sink, const char* type) {
  std::size_t n = 0;
  for (const TrackEvent& e : sink.events) n += e.is(type) ? 1 : 0;
  return n;
}

/// A source that asks the session to stop after `after` records of the wrapped source.
class StopAfter final : public FixSource {
 public:
  StopAfter(FixSource& inner, TrackingSession& session, int after) : inner_(inner), session_(session), left_(after) {}
  SourceRecord next(int timeout_ms) override {
    if (--left_ == 0) session_.requestStop();
    return inner_.next(timeout_ms);
  }
  const std::string& name() const override { return inner_.name(); }
  bool live() const override { return inner_.live(); }
  bool rereadable() const override { return inner_.rereadable(); }
  void resumeAfter(std::size_t line) override { inner_.resumeAfter(line); }
  std::size_t checkpointLine() const override { return inner_.checkpointLine(); }

 private:
  FixSource& inner_;
  TrackingSession& session_;
  int left_;
};

TEST(TrackingSession, InMemorySourceAndSinkGiveTheTrackersEventsWithoutAFile) {
  // GIVEN a session with one flight, an in-memory JSON-lines source with one malformed line
  TrackingSession session({}, nullptr);
  session.tracker().addFlight("F1", parseApprovalReport(nlohmann::json(example().report), "r"),
                              example().approver);
  std::vector<std::string> lines = jsonLines(fixesAlongRoute(12));
  lines.insert(lines.begin() + 5, "{\"flight\": \"F1\", \"time\": 3}");
  JsonLinesFixSource source(std::make_unique<MemoryLineInput>("memory", lines));
  MemorySink sink;
  session.addSink(sink);
  // WHEN it runs to the end
  const SessionSummary sum = session.run(source);
  // THEN every fix is judged inside and the bad line is reported with its line number, not fatal
  EXPECT_EQ(sum.accepted, 12u);
  EXPECT_EQ(sum.rejected, 1u);
  EXPECT_EQ(sum.events, sink.events.size());
  EXPECT_FALSE(sum.stopped);
  ASSERT_EQ(count(sink, "rejected_input"), 1u);
  const TrackEvent& bad = sink.events[5];
  ASSERT_TRUE(bad.is("rejected_input"));
  EXPECT_EQ(bad.body.at("line"), 6);
  EXPECT_EQ(bad.body.at("source"), "memory:6");
  EXPECT_NE(bad.body.at("error").get<std::string>().find("time"), std::string::npos) << bad.body.dump();
  EXPECT_EQ(bad.flight, "F1");  // the line named its flight: the rejection says whose it was
  // AND the events are the ones a tracker alone gives for the same fixes (JSON lines agree too)
  Tracker alone;
  alone.addFlight("F1", parseApprovalReport(nlohmann::json(example().report), "r"),
                  example().approver);
  std::size_t i = 0;
  for (const TrackFix& f : fixesAlongRoute(12)) {
    if (i == 5) ++i;  // the rejected record
    TrackFix parsed = parseTrackFixJson(json::parse(trackFixJson(f).dump()), "x");
    parsed.line = i + 1;
    parsed.source = "memory:" + std::to_string(i + 1);
    for (const TrackEvent& e : alone.process(parsed)) {
      ASSERT_LT(i, sink.events.size());
      EXPECT_EQ(sink.lines[i], e.jsonLine());
      EXPECT_EQ(sink.events[i].toJson(), json::parse(sink.lines[i]));
      ++i;
    }
  }
  EXPECT_EQ(i, sink.events.size());
}

TEST(TrackingSession, AStoppedSessionResumesTheFileWhereItsCheckpointLeftIt) {
  // GIVEN 40 fixes in a file and a database
  const std::string input = test::scratchPath("session_fixes.jsonl");
  const std::string db = test::scratchPath("session.sqlite");
  {
    std::ofstream out(input);
    for (const std::string& l : jsonLines(fixesAlongRoute(40))) out << l << '\n';
  }
  std::vector<std::size_t> judged;
  auto runOnce = [&](int stop_after) {
    TrackingSession session({}, std::make_unique<TrackStore>(db), 7);
    session.resumeFlights();
    session.addApprovalFile(example().report_path, "F1");
    JsonLinesFixSource file(openLineInput(input));
    StopAfter source(file, session, stop_after);
    MemorySink sink;
    session.addSink(sink);
    const SessionSummary sum = session.run(source);
    for (const TrackEvent& e : sink.events) {
      if (e.is("fix")) judged.push_back(e.fix->line);
    }
    return sum;
  };
  // WHEN a first session is stopped after 17 records and a second one runs on the same database
  const SessionSummary first = runOnce(17);
  EXPECT_TRUE(first.stopped);
  EXPECT_EQ(first.accepted, 17u);
  const SessionSummary second = runOnce(-1);
  EXPECT_FALSE(second.stopped);
  // THEN every line is judged exactly once, in order, and the flight's state counts all of them
  ASSERT_EQ(judged.size(), 40u);
  for (std::size_t k = 0; k < judged.size(); ++k) EXPECT_EQ(judged[k], k + 1);
  TrackStore store(db);
  EXPECT_EQ(store.inputLine(input), 40u);
  ASSERT_EQ(store.flights().size(), 1u);
  EXPECT_EQ(store.flights().front().state.at("fixes"), 40);
  EXPECT_EQ(store.events("fix").size(), 40u);
}

/// A sink whose reader goes away after `after` events.
class ClosingSink final : public EventSink {
 public:
  explicit ClosingSink(std::size_t after) : after_(after) {}
  void write(const TrackEvent&, const std::string&) override { ++written_; }
  bool closed() const override { return written_ >= after_; }

 private:
  std::size_t after_, written_ = 0;
};

TEST(TrackingSession, AClosedSinkStopsTheRunAndSaysSo) {
  TrackingSession session({}, nullptr);
  session.addApprovalFile(example().report_path, "F1");
  MemoryFixSource source("memory", fixesAlongRoute(30));
  ClosingSink sink(4);
  session.addSink(sink);
  const SessionSummary sum = session.run(source);
  EXPECT_TRUE(sum.output_closed);
  EXPECT_FALSE(sum.stopped);
  EXPECT_EQ(sum.accepted, 4u);
}

TEST(TrackingSession, AnApprovalFileTheDatabaseGaveBackIsNotAddedTwice) {
  const std::string db = test::scratchPath("session_twice.sqlite");
  {
    TrackingSession s({}, std::make_unique<TrackStore>(db));
    EXPECT_EQ(s.addApprovalFile(example().report_path), example().approver->mission().name);
  }
  TrackingSession s({}, std::make_unique<TrackStore>(db));
  s.resumeFlights();
  EXPECT_EQ(s.addApprovalFile(example().report_path), "");
  EXPECT_EQ(s.tracker().flights().size(), 1u);
}

}  // namespace
}  // namespace skylane::planner
