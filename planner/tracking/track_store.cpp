#include "planner/tracking/track_store.hpp"

#include "maps/time.hpp"

#include <sqlite3.h>

#include <stdexcept>

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

}  // namespace

TrackStore::TrackStore(const std::string& path) : path_(path) {
  if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK) fail("cannot open");
  sqlite3_busy_timeout(db_, 2000);
  // WAL: a kill between batches leaves the last committed batch intact; NORMAL sync is durable
  // against a process kill (the case a restart resumes from), not against power loss.
  exec("PRAGMA journal_mode=WAL");
  exec("PRAGMA synchronous=NORMAL");
  exec("CREATE TABLE IF NOT EXISTS flights (id TEXT PRIMARY KEY, report TEXT NOT NULL, approval TEXT NOT NULL, "
       "state TEXT NOT NULL, route TEXT NOT NULL)");
  exec("CREATE TABLE IF NOT EXISTS events (seq INTEGER PRIMARY KEY AUTOINCREMENT, flight TEXT, time TEXT, type TEXT NOT NULL, json TEXT NOT NULL)");
  exec("CREATE TABLE IF NOT EXISTS inputs (name TEXT PRIMARY KEY, line INTEGER NOT NULL)");
  auto prepare = [this](const char* sql, sqlite3_stmt** out) {
    if (sqlite3_prepare_v2(db_, sql, -1, out, nullptr) != SQLITE_OK) fail("cannot prepare a statement");
  };
  prepare("INSERT OR REPLACE INTO flights (id, report, approval, state, route) VALUES (?, ?, ?, ?, ?)", &put_flight_);
  prepare("UPDATE flights SET state = ?, route = ? WHERE id = ?", &put_state_);
  prepare("INSERT INTO events (flight, time, type, json) VALUES (?, ?, ?, ?)", &put_event_);
  prepare("INSERT OR REPLACE INTO inputs (name, line) VALUES (?, ?)", &put_input_);
}

TrackStore::~TrackStore() {
  // A batch still open here was cut short (an error unwound the run): it is not half-kept —
  // its events without the states and input position would be stored twice after a restart.
  if (in_batch_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  sqlite3_finalize(put_flight_);
  sqlite3_finalize(put_state_);
  sqlite3_finalize(put_event_);
  sqlite3_finalize(put_input_);
  sqlite3_close(db_);
}

void TrackStore::fail(const std::string& what) const {
  throw std::runtime_error("tracker database " + path_ + ": " + what + ": " + (db_ ? sqlite3_errmsg(db_) : "out of memory"));
}

void TrackStore::exec(const char* sql) const {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string msg = err ? err : "?";
    sqlite3_free(err);
    throw std::runtime_error("tracker database " + path_ + ": " + sql + ": " + msg);
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

}  // namespace skylane::planner
