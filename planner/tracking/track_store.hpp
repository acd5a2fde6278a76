#pragma once
/// \file
/// \brief The tracker's embedded database (SQLite): approvals, each flight's state and current
/// route, the event log, and how far each input file was read — written in one transaction per
/// batch, so a tracker killed at any moment and restarted resumes every flight where the last
/// committed batch left it and re-reads the input from there: no accepted fix is lost (a fix
/// of the batch that was not committed is processed again).
///
/// Tables: flights(id, report file, approval report JSON, state JSON, route JSON),
/// events(seq, flight, time, type, JSON), inputs(name, line). An existing file is verified when
/// opened (no damaged page, these tables and columns, input positions ≥ 0) and refused with a
/// ParseError otherwise; the session refuses a stored position beyond the end of its input.

#include "planner/tracking/event_sink.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace skylane::planner {

/// \brief A flight as the database keeps it.
struct StoredFlight {
  std::string id;
  std::string report;  ///< the approval report file
  nlohmann::json approval;  ///< the report itself (a restart does not need the file)
  nlohmann::json state;
  nlohmann::json route;
};

/// \brief Where the last committed batch of an event file goes in it (event_file_sink.hpp).
struct OutputMark {
  std::uint64_t bytes_before = 0, bytes_after = 0;  ///< the file's length before and after the batch
  std::int64_t first_seq = 0, last_seq = 0;          ///< the batch's events (events.seq)
};

/// \brief The database of one tracker; as an event sink it logs every event in the batch.
class TrackStore final : public EventSink {
 public:
  /// \brief Opens (creates) the database file.
  /// \throws maps::ParseError when the file is a folder, not a SQLite database or damaged;
  /// maps::OutputError when it cannot be opened or written (both name the file and SQLite's
  /// message). Every later failure (a full disk at a COMMIT) throws the same way.
  explicit TrackStore(const std::string& path);
  ~TrackStore() override;
  TrackStore(const TrackStore&) = delete;
  TrackStore& operator=(const TrackStore&) = delete;

  [[nodiscard]] std::vector<StoredFlight> flights() const;
  /// \brief The last line read of an input (0 when never read).
  [[nodiscard]] std::size_t inputLine(const std::string& name) const;
  /// \brief Events in order (all, or of one type).
  [[nodiscard]] std::vector<nlohmann::json> events(const std::string& type = {}) const;
  /// \brief An event as stored: its sequence number (the order of the log, never reused), flight,
  /// type and JSON line.
  struct LoggedEvent {
    std::int64_t seq = 0;
    std::string flight, type, line;
  };
  /// \brief Up to `limit` events after sequence number `after`, in order (a resumed event stream).
  [[nodiscard]] std::vector<LoggedEvent> eventsAfter(std::int64_t after, std::size_t limit) const;
  /// \brief Each flight's last event of `type` (flight → its JSON line).
  [[nodiscard]] std::map<std::string, std::string> lastEventOfEachFlight(const std::string& type) const;
  /// \brief The sequence number of the event appended last on this connection (0: none yet).
  [[nodiscard]] std::int64_t lastEventSeq() const;

  /// \brief Starts a batch (a transaction); the writes below join it.
  void begin();
  /// \brief Adds (or replaces) a flight with its approval.
  void putFlight(const StoredFlight& f);
  /// \brief Updates a stored flight's state and route.
  void putState(const std::string& id, const nlohmann::json& state, const nlohmann::json& route);
  /// \brief An event as written to the stream (one JSON line) with its type, flight and time.
  void appendEvent(const std::string& type, const std::string& flight, const std::string& time, const std::string& line);
  void setInputLine(const std::string& name, std::size_t line);
  /// \brief The last committed batch's place in the event file `name` (in the open batch).
  void setOutputMark(const std::string& name, const OutputMark& mark);
  /// \brief The mark of event file `name`, if one was stored.
  [[nodiscard]] std::optional<OutputMark> outputMark(const std::string& name) const;
  /// \brief The JSON lines of events first_seq…last_seq, in order, as they were streamed.
  [[nodiscard]] std::vector<std::string> eventLines(std::int64_t first_seq, std::int64_t last_seq) const;

  /// \brief appendEvent() of the event (EventSink).
  void write(const TrackEvent& event, const std::string& json_line) override;
  /// \brief Commits the batch.
  void commit();
  [[nodiscard]] bool inBatch() const { return in_batch_; }
  /// \brief The database file.
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  void open();
  /// \brief An existing database checked before use (issue 23): no damaged page (PRAGMA
  /// integrity_check), the tables and columns of a tracker database, input positions ≥ 0.
  /// \throws maps::ParseError naming the file and what is wrong.
  void verify();
  void requireUndamaged() const;
  void requireSchema() const;
  void requireInputPositions() const;
  void close() noexcept;
  void exec(const char* sql) const;
  [[noreturn]] void fail(const std::string& what) const;
  std::string path_;
  sqlite3* db_ = nullptr;
  sqlite3_stmt* put_flight_ = nullptr;
  sqlite3_stmt* put_state_ = nullptr;
  sqlite3_stmt* put_event_ = nullptr;
  sqlite3_stmt* put_input_ = nullptr;
  sqlite3_stmt* put_output_ = nullptr;
  bool in_batch_ = false;
};

}  // namespace skylane::planner
