#pragma once
/// \file
/// \brief Where the tracking engine's events go: JSON lines on a stream (here), the tracker
/// database (track_store.hpp), and next an HTTP event stream or NATS (the service module). Each
/// event comes with its one JSON line (TrackEvent::jsonLine), made once for every sink.

#include "planner/tracking/track_event.hpp"

#include <ostream>
#include <string>
#include <vector>

namespace skylane::planner {

/// \brief A receiver of events.
class EventSink {
 public:
  virtual ~EventSink() = default;
  /// \brief One event and its JSON line.
  virtual void write(const TrackEvent& event, const std::string& json_line) = 0;
  /// \brief The end of a batch with a database, before it commits the batch (a sink that keeps
  /// its own position in the database writes it here, in the same transaction).
  virtual void beforeCommit() {}
  /// \brief The end of a batch (a checkpoint, the end of the stream): what was written is handed on.
  virtual void flush() {}
  /// \brief Whether the sink's reader has gone (the session then stops as on a stop request).
  [[nodiscard]] virtual bool closed() const { return false; }
};

/// \brief One JSON line per event on an output stream; a failed write (a closed pipe, a full
/// disk) closes the sink.
class JsonLinesSink final : public EventSink {
 public:
  explicit JsonLinesSink(std::ostream& out) : out_(out) {}
  void write(const TrackEvent& event, const std::string& json_line) override;
  void flush() override;
  [[nodiscard]] bool closed() const override { return closed_; }
  /// \brief The system's error (errno) of the write that closed the sink (EPIPE: the reader has
  /// gone; ENOSPC: a full disk), 0 when open or unknown.
  [[nodiscard]] int error() const { return error_; }

 private:
  void check();
  std::ostream& out_;
  bool closed_ = false;
  int error_ = 0;
};

/// \brief The events kept in memory (tests, a service's response).
class MemorySink final : public EventSink {
 public:
  void write(const TrackEvent& event, const std::string& json_line) override {
    events.push_back(event);
    lines.push_back(json_line);
  }
  std::vector<TrackEvent> events;
  std::vector<std::string> lines;
};

}  // namespace skylane::planner
