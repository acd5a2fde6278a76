#pragma once
/// \file
/// \brief The tracking engine as a service loop: a Tracker with its flights, an optional
/// database (track_store.hpp) it resumes from and checkpoints into, any number of event sinks,
/// and a fix source it runs until the source ends or a stop is requested. `skylane track` is
/// option parsing plus this wiring; the HTTP service and the NATS workers wire their own sources
/// and sinks to the same session.
///
/// Checkpoints: every `batch` fixes (and when a live input goes quiet, and at the end) the
/// touched flights' states and routes and the source's checkpoint line are committed in one
/// transaction with the batch's events, so a session killed at any moment and restarted on the
/// same database and a rereadable input resumes every flight where the last committed batch left
/// it (a fix of an uncommitted batch is processed again, none is lost).

#include "planner/tracking/event_sink.hpp"
#include "planner/tracking/fix_source.hpp"
#include "planner/tracking/track_store.hpp"
#include "planner/tracking/tracker.hpp"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace skylane::planner {

/// \brief What a run did.
struct SessionSummary {
  std::size_t accepted = 0;  ///< `fix` events
  std::size_t rejected = 0;  ///< `rejected_input` events
  std::size_t events = 0;
  /// A UDP input: datagrams the kernel dropped (its receive buffer was full), reported as
  /// `input_dropped` events; empty for any other input.
  std::optional<std::uint64_t> dropped;
  bool stopped = false;        ///< by requestStop()
  bool output_closed = false;  ///< a sink's reader went away
};

/// \brief One tracking engine with its persistence and outputs.
class TrackingSession {
 public:
  using Log = std::function<void(const std::string&)>;
  /// \brief `store` may be null (no persistence); `log` gets one-line progress messages.
  TrackingSession(TrackerOptions options, std::unique_ptr<TrackStore> store, int batch = 200, Log log = {});
  TrackingSession(const TrackingSession&) = delete;
  TrackingSession& operator=(const TrackingSession&) = delete;

  /// \brief Takes back every flight the database holds (approval, state, current route).
  void resumeFlights();
  /// \brief Adds an approval report unless the database gave it back already (the same id, or,
  /// without an id, the same report file); returns the flight id, or empty when resumed.
  /// \throws maps::ParseError for a bad report or mission.
  std::string addApprovalFile(const std::string& report_path, const std::string& id = {});
  /// \brief Events go to `sink` too (not owned; it outlives the session's runs).
  void addSink(EventSink& sink) { sinks_.push_back(&sink); }
  /// \brief Work that runs beside the stream (a link's mission upload): called after every
  /// record and whenever the input is quiet; the events it returns are the session's.
  using Ticker = std::function<std::vector<TrackEvent>()>;
  void addTicker(Ticker ticker) { tickers_.push_back(std::move(ticker)); }

  /// \brief Processes `source` until it ends or a stop is requested, resuming a rereadable
  /// input at the line the database stored; ends with a stale sweep and a checkpoint.
  SessionSummary run(FixSource& source);
  /// \brief Asks run() to stop after the record in hand (async-signal-safe).
  void requestStop() noexcept { stop_.store(true); }
  /// \brief The flag requestStop() sets (a signal handler may hold it).
  [[nodiscard]] std::atomic<bool>& stopFlag() noexcept { return stop_; }

  /// \brief One fix pushed by the caller (a service); `rejected_input` when it cannot be taken.
  void submit(const TrackFix& fix);
  /// \brief One record the caller could not read (`flight`: the flight it named, if any).
  void reject(const std::string& where, std::size_t line, const std::string& why, const std::string& flight = {});
  /// \brief A UDP input's kernel drops: `total` datagrams of `source` dropped so far (a counter
  /// that only grows); an `input_dropped` event with what is new since the last call, if any.
  void reportDropped(const std::string& source, std::uint64_t total);
  /// \brief The stale sweep at the stream time and a checkpoint (the end of a run).
  void finish();
  /// \brief A checkpoint now: what was submitted is committed and handed to the sinks (a
  /// service answers a request only after this, so an acknowledged fix is never lost).
  void commit() { checkpoint(true); }
  /// \brief The database, when there is one.
  [[nodiscard]] TrackStore* store() { return store_.get(); }

  [[nodiscard]] Tracker& tracker() { return tracker_; }
  [[nodiscard]] const Tracker& tracker() const { return tracker_; }
  [[nodiscard]] const SessionSummary& summary() const { return summary_; }

 private:
  /// \brief A ParseError naming the database when `source` ended before `resume_line`.
  void requirePositionWithinInput(const FixSource& source, std::size_t resume_line) const;
  void emit(const std::vector<TrackEvent>& events);
  void checkpoint(bool force);
  void sweepWhileQuiet(double quiet_s);
  void beginBatch();
  /// Runs the tickers and emits what they return.
  void tick();

  Tracker tracker_;
  std::unique_ptr<TrackStore> store_;
  int batch_;
  Log log_;
  std::vector<EventSink*> sinks_;
  std::vector<Ticker> tickers_;
  std::map<std::string, std::string> report_of_;  ///< flight id → approval report file
  std::set<std::string> touched_;                 ///< flights changed since the last checkpoint
  std::string line_;                              ///< the event line being written (reused)
  SourceRecord record_;                           ///< the record being processed (reused)
  std::vector<TrackEvent> events_;                ///< a fix's events (reused: Tracker::process)
  std::map<std::string, std::uint64_t> dropped_;  ///< UDP input → kernel drops reported so far
  int pending_ = 0;
  FixSource* source_ = nullptr;  ///< the source being run (its checkpoint line)
  bool resumable_ = false;
  std::atomic<bool> stop_{false};
  SessionSummary summary_;
};

}  // namespace skylane::planner
