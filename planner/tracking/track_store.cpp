#include "planner/tracking/track_store.hpp"

#include "maps/atomic_file.hpp"
#include "maps/parse_error.hpp"
#include "maps/time.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <system_error>

namespace skylane::planner {

namespace {

/// Finalises a statement when it goes out of scope.
struct Statement {
  sqlite3_stmt* s = nullptr;
  ~Statement() { sqlite3_finalize(s); }
};

void bindText(sqlite3_stmt* s, int i, const std::string& v) {
  sqlite3_bind_text(s, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
}

std::string columnText(sqlite3_stmt* s, int i) {
  const unsigned char* t = sqlite3_column_text(s, i);
  return t ? std::string(reinterpret_cast<const char*>(t)) : std::string();
}

/// A SQLite failure as the error a user can act on: a file that is not a tracker database, or
/// is damaged, is bad input (ParseError); the rest (cannot open, a full disk, no permission, a
/// lock held by another process) is a database that cannot be written (OutputError).
[[noreturn]] void raiseStoreError(const std::string& path, int code, const std::string& what, const std::string& reason) {
  const int primary = code & 0xff;
  if (primary == SQLITE_NOTADB || primary == SQLITE_CORRUPT) {
    throw maps::ParseError(path, 0, "(tracker database)", reason, "an undamaged skylane tracker database (SQLite 3)");
  }
  throw maps::OutputError(path, "", "tracker database: " + what + ": " + reason);
}

}  // namespace

TrackStore::TrackStore(const std::string& path) : path_(path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw maps::ParseError(path, 0, "(tracker database)", "a folder", "a tracker database file (SQLite 3)");
  }
  try {
    open();
  } catch (...) {
    close();  // the constructor throws: no destructor runs to release the connection
    throw;
  }
}

void TrackStore::open() {
  if (sqlite3_open(path_.c_str(), &db_) != SQLITE_OK) fail("cannot open");
  sqlite3_busy_timeout(db_, 2000);
  // WAL: a kill between batches leaves the last committed batch intact; NORMAL sync is durable
  // against a process kill (the case a restart resumes from), not against power loss.
  exec("PRAGMA journal_mode=WAL");
  exec("PRAGMA synchronous=NORMAL");
  verify();
  exec("CREATE TABLE IF NOT EXISTS flights (id TEXT PRIMARY KEY, report TEXT NOT NULL, approval TEXT NOT NULL, "
       "state TEXT NOT NULL, route TEXT NOT NULL)");
  exec("CREATE TABLE IF NOT EXISTS events (seq INTEGER PRIMARY KEY AUTOINCREMENT, flight TEXT, time TEXT, type TEXT NOT NULL, json TEXT NOT NULL)");
  exec("CREATE TABLE IF NOT EXISTS inputs (name TEXT PRIMARY KEY, line INTEGER NOT NULL)");
  exec("CREATE TABLE IF NOT EXISTS outputs (name TEXT PRIMARY KEY, bytes_before INTEGER NOT NULL, bytes_after INTEGER NOT NULL, "
       "first_seq INTEGER NOT NULL, last_seq INTEGER NOT NULL)");
  auto prepare = [this](const char* sql, sqlite3_stmt** out) {
    if (sqlite3_prepare_v2(db_, sql, -1, out, nullptr) != SQLITE_OK) fail("cannot prepare a statement");
  };
  prepare("INSERT OR REPLACE INTO flights (id, report, approval, state, route) VALUES (?, ?, ?, ?, ?)", &put_flight_);
  prepare("UPDATE flights SET state = ?, route = ? WHERE id = ?", &put_state_);
  prepare("INSERT INTO events (flight, time, type, json) VALUES (?, ?, ?, ?)", &put_event_);
  prepare("INSERT OR REPLACE INTO inputs (name, line) VALUES (?, ?)", &put_input_);
  prepare("INSERT OR REPLACE INTO outputs (name, bytes_before, bytes_after, first_seq, last_seq) VALUES (?, ?, ?, ?, ?)",
          &put_output_);
}

namespace {

/// The tables and their columns, in order, as open() creates them; `outputs` came later (a
/// database written before it has none and gets it).
const std::vector<std::pair<std::string, std::vector<std::string>>> kSchema = {
    {"flights", {"id", "report", "approval", "state", "route"}},
    {"events", {"seq", "flight", "time", "type", "json"}},
    {"inputs", {"name", "line"}},
    {"outputs", {"name", "bytes_before", "bytes_after", "first_seq", "last_seq"}},
};
const std::string kOptionalTable = "outputs";

}  // namespace

void TrackStore::verify() {
  requireUndamaged();
  requireSchema();
  requireInputPositions();
}

void TrackStore::requireUndamaged() const {
  // integrity_check reads every page, checks the b-trees and that the indexes match their
  // tables: a damaged page in the middle of the file is found here, before a resumed run
  // appends to it. It costs a read of the file (0.14 s for 200,000 events, 205 MB, on the
  // development machine; quick_check, without the index checks, took as long).
  Statement st;
  if (sqlite3_prepare_v2(db_, "PRAGMA integrity_check(1)", -1, &st.s, nullptr) != SQLITE_OK) fail("cannot check the file");
  const int rc = sqlite3_step(st.s);
  if (rc != SQLITE_ROW) fail("cannot check the file");
  const std::string verdict = columnText(st.s, 0);
  if (verdict != "ok") {
    throw maps::ParseError(path_, 0, "(tracker database)", "damaged (" + verdict + ")",
                           "an undamaged skylane tracker database (SQLite 3): restore it or start a new one");
  }
}

void TrackStore::requireSchema() const {
  Statement tables;
  if (sqlite3_prepare_v2(db_, "SELECT name FROM sqlite_master WHERE type = 'table' AND name != 'sqlite_sequence'", -1,
                         &tables.s, nullptr) != SQLITE_OK) {
    fail("cannot read the schema");
  }
  std::vector<std::string> present;
  while (sqlite3_step(tables.s) == SQLITE_ROW) present.push_back(columnText(tables.s, 0));
  // None of the tracker's tables: a new database, or one that another part of skylane keeps in
  // the same file (the service's tables): open() adds the tracker's. Some of them: all must be there.
  const bool any = std::any_of(kSchema.begin(), kSchema.end(), [&present](const auto& t) {
    return t.first != kOptionalTable && std::find(present.begin(), present.end(), t.first) != present.end();
  });
  if (!any) return;
  for (const auto& [table, columns] : kSchema) {
    std::vector<std::string> got;
    if (std::find(present.begin(), present.end(), table) != present.end()) {
      Statement info;
      const std::string sql = "PRAGMA table_info(" + table + ")";
      if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &info.s, nullptr) != SQLITE_OK) fail("cannot read the schema");
      while (sqlite3_step(info.s) == SQLITE_ROW) got.push_back(columnText(info.s, 1));
    }
    if (got != columns && !(got.empty() && table == kOptionalTable)) {
      std::string expected;
      for (const std::string& c : columns) expected += (expected.empty() ? "" : ", ") + c;
      throw maps::ParseError(path_, 0, "(tracker database) table " + table, got.empty() ? "missing" : "other columns",
                             "a skylane tracker database, whose table " + table + " has the columns " + expected);
    }
  }
}

void TrackStore::requireInputPositions() const {
  Statement st;
  if (sqlite3_prepare_v2(db_, "SELECT name, line, typeof(line) FROM inputs WHERE typeof(line) != 'integer' OR line < 0 LIMIT 1",
                         -1, &st.s, nullptr) != SQLITE_OK) {
    return;  // no inputs table yet (a new database)
  }
  if (sqlite3_step(st.s) == SQLITE_ROW) {
    throw maps::ParseError(path_, 0, "(tracker database) inputs[" + columnText(st.s, 0) + "].line", columnText(st.s, 1),
                           "a line number ≥ 0 (the database is damaged)");
  }
}

TrackStore::~TrackStore() {
  // A batch still open here was cut short (an error unwound the run): it is not half-kept —
  // its events without the states and input position would be stored twice after a restart.
  if (in_batch_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  close();
}

void TrackStore::close() noexcept {
  for (sqlite3_stmt** s : {&put_flight_, &put_state_, &put_event_, &put_input_, &put_output_}) {
    sqlite3_finalize(*s);
    *s = nullptr;
  }
  sqlite3_close(db_);  // also a handle that sqlite3_open() returned with an error
  db_ = nullptr;
}

void TrackStore::fail(const std::string& what) const {
  if (!db_) raiseStoreError(path_, SQLITE_NOMEM, what, "out of memory");
  raiseStoreError(path_, sqlite3_extended_errcode(db_), what, sqlite3_errmsg(db_));
}

void TrackStore::exec(const char* sql) const {
  char* err = nullptr;
  const int rc = sqlite3_exec(db_, sql, nullptr, nullptr, &err);
  if (rc != SQLITE_OK) {
    const std::string msg = err ? err : sqlite3_errstr(rc);
    sqlite3_free(err);
    raiseStoreError(path_, rc, sql, msg);
  }
}

std::vector<StoredFlight> TrackStore::flights() const {
  std::vector<StoredFlight> out;
  Statement st;
  if (sqlite3_prepare_v2(db_, "SELECT id, report, approval, state, route FROM flights ORDER BY id", -1, &st.s, nullptr) !=
      SQLITE_OK) {
    fail("cannot read flights");
  }
  while (sqlite3_step(st.s) == SQLITE_ROW) {
    StoredFlight f;
    f.id = columnText(st.s, 0);
    f.report = columnText(st.s, 1);
    try {
      f.approval = nlohmann::json::parse(columnText(st.s, 2));
      f.state = nlohmann::json::parse(columnText(st.s, 3));
      f.route = nlohmann::json::parse(columnText(st.s, 4));
    } catch (const nlohmann::json::exception& e) {
      fail("flight " + f.id + " has a damaged record (" + e.what() + ")");
    }
    out.push_back(std::move(f));
  }
  return out;
}

std::size_t TrackStore::inputLine(const std::string& name) const {
  Statement st;
  if (sqlite3_prepare_v2(db_, "SELECT line FROM inputs WHERE name = ?", -1, &st.s, nullptr) != SQLITE_OK) fail("cannot read inputs");
  bindText(st.s, 1, name);
  return sqlite3_step(st.s) == SQLITE_ROW ? static_cast<std::size_t>(sqlite3_column_int64(st.s, 0)) : 0;
}

std::vector<nlohmann::json> TrackStore::events(const std::string& type) const {
  std::vector<nlohmann::json> out;
  Statement st;
  const char* sql = type.empty() ? "SELECT json FROM events ORDER BY seq" : "SELECT json FROM events WHERE type = ? ORDER BY seq";
  if (sqlite3_prepare_v2(db_, sql, -1, &st.s, nullptr) != SQLITE_OK) fail("cannot read events");
  if (!type.empty()) bindText(st.s, 1, type);
  while (sqlite3_step(st.s) == SQLITE_ROW) out.push_back(nlohmann::json::parse(columnText(st.s, 0)));
  return out;
}

std::vector<TrackStore::LoggedEvent> TrackStore::eventsAfter(std::int64_t after, std::size_t limit) const {
  std::vector<LoggedEvent> out;
  Statement st;
  if (sqlite3_prepare_v2(db_, "SELECT seq, flight, type, json FROM events WHERE seq > ? ORDER BY seq LIMIT ?", -1, &st.s,
                         nullptr) != SQLITE_OK) {
    fail("cannot read events");
  }
  sqlite3_bind_int64(st.s, 1, after);
  sqlite3_bind_int64(st.s, 2, static_cast<sqlite3_int64>(limit));
  while (sqlite3_step(st.s) == SQLITE_ROW) {
    out.push_back({sqlite3_column_int64(st.s, 0), columnText(st.s, 1), columnText(st.s, 2), columnText(st.s, 3)});
  }
  return out;
}

std::map<std::string, std::string> TrackStore::lastEventOfEachFlight(const std::string& type) const {
  std::map<std::string, std::string> out;
  Statement st;
  if (sqlite3_prepare_v2(db_, "SELECT flight, json FROM events WHERE seq IN (SELECT MAX(seq) FROM events WHERE type = ? GROUP BY flight)",
                         -1, &st.s, nullptr) != SQLITE_OK) {
    fail("cannot read events");
  }
  bindText(st.s, 1, type);
  while (sqlite3_step(st.s) == SQLITE_ROW) out[columnText(st.s, 0)] = columnText(st.s, 1);
  return out;
}

std::int64_t TrackStore::lastEventSeq() const { return sqlite3_last_insert_rowid(db_); }

void TrackStore::begin() {
  if (in_batch_) return;
  exec("BEGIN");
  in_batch_ = true;
}

void TrackStore::commit() {
  if (!in_batch_) return;
  exec("COMMIT");
  in_batch_ = false;
}

void TrackStore::putFlight(const StoredFlight& f) {
  sqlite3_reset(put_flight_);
  bindText(put_flight_, 1, f.id);
  bindText(put_flight_, 2, f.report);
  bindText(put_flight_, 3, f.approval.dump());
  bindText(put_flight_, 4, f.state.dump());
  bindText(put_flight_, 5, f.route.dump());
  if (sqlite3_step(put_flight_) != SQLITE_DONE) fail("cannot store flight " + f.id);
}

void TrackStore::putState(const std::string& id, const nlohmann::json& state, const nlohmann::json& route) {
  sqlite3_reset(put_state_);
  bindText(put_state_, 1, state.dump());
  bindText(put_state_, 2, route.dump());
  bindText(put_state_, 3, id);
  if (sqlite3_step(put_state_) != SQLITE_DONE) fail("cannot store the state of flight " + id);
  if (sqlite3_changes(db_) != 1) fail("flight " + id + " is not in the database");
}

void TrackStore::appendEvent(const std::string& type, const std::string& flight, const std::string& time,
                             const std::string& line) {
  sqlite3_reset(put_event_);
  bindText(put_event_, 1, flight);
  bindText(put_event_, 2, time);
  bindText(put_event_, 3, type);
  bindText(put_event_, 4, line);
  if (sqlite3_step(put_event_) != SQLITE_DONE) fail("cannot store an event");
}

void TrackStore::setInputLine(const std::string& name, std::size_t line) {
  sqlite3_reset(put_input_);
  bindText(put_input_, 1, name);
  sqlite3_bind_int64(put_input_, 2, static_cast<sqlite3_int64>(line));
  if (sqlite3_step(put_input_) != SQLITE_DONE) fail("cannot store the input position");
}

void TrackStore::write(const TrackEvent& event, const std::string& json_line) {
  appendEvent(event.type, event.flight, event.time ? maps::formatRfc3339(*event.time, 3) : std::string(), json_line);
}

void TrackStore::setOutputMark(const std::string& name, const OutputMark& mark) {
  sqlite3_reset(put_output_);
  bindText(put_output_, 1, name);
  sqlite3_bind_int64(put_output_, 2, static_cast<sqlite3_int64>(mark.bytes_before));
  sqlite3_bind_int64(put_output_, 3, static_cast<sqlite3_int64>(mark.bytes_after));
  sqlite3_bind_int64(put_output_, 4, mark.first_seq);
  sqlite3_bind_int64(put_output_, 5, mark.last_seq);
  if (sqlite3_step(put_output_) != SQLITE_DONE) fail("cannot store the event file's position");
}

std::optional<OutputMark> TrackStore::outputMark(const std::string& name) const {
  Statement st;
  if (sqlite3_prepare_v2(db_, "SELECT bytes_before, bytes_after, first_seq, last_seq FROM outputs WHERE name = ?", -1, &st.s,
                         nullptr) != SQLITE_OK) {
    fail("cannot read outputs");
  }
  bindText(st.s, 1, name);
  if (sqlite3_step(st.s) != SQLITE_ROW) return std::nullopt;
  const sqlite3_int64 before = sqlite3_column_int64(st.s, 0), after = sqlite3_column_int64(st.s, 1);
  if (before < 0 || after < before) {
    throw maps::ParseError(path_, 0, "(tracker database) outputs[" + name + "]", std::to_string(before) + "…" + std::to_string(after),
                           "byte positions 0 ≤ before ≤ after (the database is damaged)");
  }
  return OutputMark{static_cast<std::uint64_t>(before), static_cast<std::uint64_t>(after), sqlite3_column_int64(st.s, 2),
                    sqlite3_column_int64(st.s, 3)};
}

std::vector<std::string> TrackStore::eventLines(std::int64_t first_seq, std::int64_t last_seq) const {
  std::vector<std::string> out;
  Statement st;
  if (sqlite3_prepare_v2(db_, "SELECT json FROM events WHERE seq BETWEEN ? AND ? ORDER BY seq", -1, &st.s, nullptr) != SQLITE_OK) {
    fail("cannot read events");
  }
  sqlite3_bind_int64(st.s, 1, first_seq);
  sqlite3_bind_int64(st.s, 2, last_seq);
  while (sqlite3_step(st.s) == SQLITE_ROW) out.push_back(columnText(st.s, 0));
  return out;
}

}  // namespace skylane::planner
