#include "planner/tracking/tracking_session.hpp"

#include "maps/parse_error.hpp"

#include "maps/text_file.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>

namespace skylane::planner {

TrackingSession::TrackingSession(TrackerOptions options, std::unique_ptr<TrackStore> store, int batch, Log log)
    : tracker_(options), store_(std::move(store)), batch_(batch), log_(std::move(log)) {
  if (batch_ < 1) throw std::invalid_argument("tracking session: the checkpoint batch must be ≥ 1 fix");
  if (!log_) log_ = [](const std::string&) {};
  if (store_) sinks_.push_back(store_.get());
}

void TrackingSession::resumeFlights() {
  if (!store_) return;
  for (const StoredFlight& f : store_->flights()) {
    // The approval comes from the database (the report file may have gone); the mission must
    // still be there, unchanged.
    const std::string id = tracker_.addApproval(f.approval, f.report, f.id);
    tracker_.restore(id, parseFlightState(f.state, store_->path() + ": flight " + id), f.route);
    report_of_[id] = f.report;
    log_("resumed flight " + id + " (" + std::to_string(tracker_.state(id).fixes) + " fixes so far, route version " +
         std::to_string(tracker_.state(id).route_version) + ")");
  }
}

std::string TrackingSession::addApprovalFile(const std::string& report_path, const std::string& id) {
  const bool resumed = id.empty() ? std::any_of(report_of_.begin(), report_of_.end(),
                                                [&](const auto& kv) {
                                                  std::error_code ec;
                                                  return kv.second == report_path ||
                                                         std::filesystem::equivalent(kv.second, report_path, ec);
                                                })
                                  : report_of_.count(id) > 0;
  if (resumed) return {};
  const nlohmann::json report = maps::readJsonFile(report_path);
  const std::string got = tracker_.addApproval(report, report_path, id);
  report_of_[got] = report_path;
  if (store_) {  // kept once; the checkpoints update the state and the route
    store_->begin();
    store_->putFlight({got, report_path, report, flightStateJson(tracker_.state(got)), tracker_.routeJson(got)});
    store_->commit();
  }
  return got;
}

void TrackingSession::beginBatch() {
  if (store_) store_->begin();
}

void TrackingSession::emit(const std::vector<TrackEvent>& events) {
  for (const TrackEvent& e : events) {
    // Quoted input may hold bytes that are not UTF-8: they are replaced, not fatal.
    line_.clear();
    e.appendJsonLine(line_);
    for (EventSink* sink : sinks_) {
      sink->write(e, line_);
      // A closed output (the reader of a pipe went away): stop as on a stop request, the batch saved.
      if (sink->closed() && !summary_.output_closed) {
        summary_.output_closed = true;
        stop_ = true;
      }
    }
    ++summary_.events;
    if (e.is("rejected_input")) ++summary_.rejected;
    if (e.is("fix")) ++summary_.accepted;
    if (!e.flight.empty() && !e.is("rejected_input")) touched_.insert(e.flight);
  }
}

void TrackingSession::checkpoint(bool force) {
  if (!force && pending_ < batch_) return;
  if (store_) {
    for (const std::string& id : touched_) store_->putState(id, flightStateJson(tracker_.state(id)), tracker_.routeJson(id));
    touched_.clear();
    if (source_ && resumable_) store_->setInputLine(source_->name(), source_->checkpointLine());
    for (EventSink* sink : sinks_) {
      if (sink != store_.get()) sink->beforeCommit();
    }
    store_->commit();
  }
  // The other sinks see each batch too, and a quiet live input's last events at once.
  for (EventSink* sink : sinks_) {
    if (sink != store_.get()) sink->flush();
  }
  pending_ = 0;
}

void TrackingSession::submit(const TrackFix& fix) {
  beginBatch();
  try {
    tracker_.process(fix, events_);
    emit(events_);
  } catch (const std::exception& e) {  // a fix the tracker cannot take never ends the stream
    emit({tracker_.rejectedInput(fix.source, fix.line, e.what())});
    log_("skipped " + fix.source + ": " + e.what());
  }
  ++pending_;
  checkpoint(false);
}

void TrackingSession::reject(const std::string& where, std::size_t line, const std::string& why, const std::string& flight) {
  beginBatch();
  TrackEvent e = tracker_.rejectedInput(where, line, why);
  e.flight = flight;
  emit({e});
  log_("skipped " + where + ": " + why);
  ++pending_;
}

void TrackingSession::reportDropped(const std::string& source, std::uint64_t total) {
  std::uint64_t& reported = dropped_[source];
  if (total <= reported) return;
  beginBatch();
  emit({inputDroppedEvent(source, total - reported, total)});
  log_(source + ": " + std::to_string(total - reported) + " datagrams dropped by the kernel (receive buffer full; " +
       std::to_string(total) + " in all)");
  reported = total;
  summary_.dropped = total;
  ++pending_;
}

void TrackingSession::sweepWhileQuiet(double quiet_s) {
  // A quiet live input: stream time runs on with the wall clock for the stale check.
  if (!tracker_.streamTime()) return;
  beginBatch();
  emit(tracker_.sweepStale(tracker_.streamTime()->plus(quiet_s)));
  checkpoint(true);
}

void TrackingSession::finish() {
  beginBatch();
  if (tracker_.streamTime()) emit(tracker_.sweepStale(*tracker_.streamTime()));
  checkpoint(true);
  for (EventSink* sink : sinks_) sink->flush();
}

void TrackingSession::tick() {
  for (const Ticker& t : tickers_) {
    std::vector<TrackEvent> events = t();
    if (events.empty()) continue;
    beginBatch();
    emit(events);
    checkpoint(true);  // a link's news goes out at once
  }
}

void TrackingSession::requirePositionWithinInput(const FixSource& source, std::size_t resume_line) const {
  // Read to its end without reaching the stored position: the input is shorter than the one the
  // database was written for (another file, a cut one) or the position is damaged; resuming
  // would skip every fix of it for good.
  if (stop_ || resume_line == 0 || source.checkpointLine() >= resume_line) return;
  throw maps::ParseError(store_->path(), 0, "(tracker database) inputs[" + source.name() + "].line", std::to_string(resume_line),
                         "a line within " + source.name() + " (which has " + std::to_string(source.checkpointLine()) +
                             "): the database belongs to a longer input or is damaged");
}

SessionSummary TrackingSession::run(FixSource& source) {
  source_ = &source;
  // A rereadable input (not stdin, a FIFO or UDP) resumes where the last committed batch left it.
  resumable_ = store_ && source.rereadable();
  const std::size_t resume_line = resumable_ ? store_->inputLine(source.name()) : 0;
  if (resume_line > 0) {
    source.resumeAfter(resume_line);
    log_(source.name() + ": resuming after line " + std::to_string(resume_line));
  }
  constexpr int kIdlePollMs = 250;  // how often a quiet live input looks at the stop flag and the clock
  auto last_wall = std::chrono::steady_clock::now();
  auto last_drop_report = last_wall;
  // A UDP input's kernel drops: one event per second at most while datagrams flow (a flood
  // drops thousands a second), and whenever the input goes quiet, and at the end.
  constexpr double kDropReportPeriod_s = 1.0;
  const auto reportDrops = [&](bool now) {
    const auto dropped = source.droppedDatagrams();
    if (!dropped) return;
    const auto wall = std::chrono::steady_clock::now();
    if (!now && std::chrono::duration<double>(wall - last_drop_report).count() < kDropReportPeriod_s) return;
    last_drop_report = wall;
    reportDropped(source.name(), *dropped);
  };
  if (source.droppedDatagrams()) summary_.dropped = 0;
  while (!stop_) {
    source.nextInto(kIdlePollMs, record_);  // one record, its storage reused
    const SourceRecord& r = record_;
    reportDrops(r.kind == SourceRecord::Kind::kIdle);
    tick();
    if (r.kind == SourceRecord::Kind::kEnd) break;
    if (r.kind == SourceRecord::Kind::kIdle) {
      if (source.live()) sweepWhileQuiet(std::chrono::duration<double>(std::chrono::steady_clock::now() - last_wall).count());
      continue;
    }
    last_wall = std::chrono::steady_clock::now();
    if (r.kind == SourceRecord::Kind::kBad) {
      reject(r.where, r.line, r.error, r.flight);
    } else {
      submit(r.fix);
    }
  }
  reportDrops(true);
  requirePositionWithinInput(source, resume_line);
  summary_.stopped = stop_ && !summary_.output_closed;
  finish();
  source_ = nullptr;
  return summary_;
}

}  // namespace skylane::planner
