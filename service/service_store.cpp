#include "service/service_store.hpp"

#include <sqlite3.h>

#include <functional>
#include <map>
#include <stdexcept>

namespace skylane::service {

namespace {

/// A prepared statement, finalised when it goes out of scope.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql, const std::function<void(const std::string&)>& fail) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &s_, nullptr) != SQLITE_OK) fail("cannot prepare a statement");
  }
  ~Statement() { sqlite3_finalize(s_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  Statement& text(int i, const std::string& v) {
    sqlite3_bind_text(s_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Statement& integer(int i, std::int64_t v) {
    sqlite3_bind_int64(s_, i, v);
    return *this;
  }
  [[nodiscard]] bool row() { return sqlite3_step(s_) == SQLITE_ROW; }
  [[nodiscard]] bool done() { return sqlite3_step(s_) == SQLITE_DONE; }
  [[nodiscard]] std::string col(int i) const {
    const unsigned char* t = sqlite3_column_text(s_, i);
    return t ? std::string(reinterpret_cast<const char*>(t)) : std::string();
  }
  [[nodiscard]] int colInt(int i) const { return sqlite3_column_int(s_, i); }

 private:
  sqlite3* db_;
  sqlite3_stmt* s_ = nullptr;
};

}  // namespace

ServiceStore::ServiceStore(const std::string& path) : path_(path) {
  if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK) {
    const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw std::runtime_error("service database " + path + ": cannot open: " + msg);
  }
  sqlite3_busy_timeout(db_, 5000);
  try {
    exec("PRAGMA journal_mode=WAL");
    exec("PRAGMA synchronous=NORMAL");
    exec("CREATE TABLE IF NOT EXISTS zonesets (id TEXT PRIMARY KEY, owner TEXT NOT NULL, name TEXT NOT NULL, created TEXT NOT NULL)");
    exec("CREATE TABLE IF NOT EXISTS zoneset_versions (id TEXT NOT NULL, version INTEGER NOT NULL, file TEXT NOT NULL, "
         "zones INTEGER NOT NULL, created TEXT NOT NULL, PRIMARY KEY (id, version))");
    exec("CREATE TABLE IF NOT EXISTS approvals (id TEXT PRIMARY KEY, owner TEXT NOT NULL, name TEXT NOT NULL, status TEXT NOT NULL, "
         "created TEXT NOT NULL, dir TEXT NOT NULL, summary TEXT NOT NULL, error TEXT NOT NULL)");
    exec("CREATE TABLE IF NOT EXISTS service_flights (id TEXT PRIMARY KEY, owner TEXT NOT NULL, approval TEXT NOT NULL, "
         "created TEXT NOT NULL)");
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
}

ServiceStore::~ServiceStore() { sqlite3_close(db_); }

void ServiceStore::fail(const std::string& what) const {
  throw std::runtime_error("service database " + path_ + ": " + what + ": " + sqlite3_errmsg(db_));
}

void ServiceStore::exec(const std::string& sql) const {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string msg = err ? err : "?";
    sqlite3_free(err);
    throw std::runtime_error("service database " + path_ + ": " + msg + " (is it a skylane database?)");
  }
}

void ServiceStore::addZoneSet(const ZoneSet& z) {
  const auto failure = [this](const std::string& w) { fail(w); };
  Statement st(db_, "INSERT INTO zonesets (id, owner, name, created) VALUES (?, ?, ?, ?)", failure);
  if (!st.text(1, z.id).text(2, z.owner).text(3, z.name).text(4, z.created).done()) fail("cannot store zone set " + z.id);
  for (const ZoneSetVersion& v : z.versions) addZoneSetVersion(z.id, v);
}

void ServiceStore::addZoneSetVersion(const std::string& id, const ZoneSetVersion& v) {
  const auto failure = [this](const std::string& w) { fail(w); };
  Statement st(db_, "INSERT INTO zoneset_versions (id, version, file, zones, created) VALUES (?, ?, ?, ?, ?)", failure);
  if (!st.text(1, id).integer(2, v.version).text(3, v.file).integer(4, v.zones).text(5, v.created).done()) {
    fail("cannot store version " + std::to_string(v.version) + " of zone set " + id);
  }
}

std::vector<ZoneSet> ServiceStore::zoneSets() const {
  const auto failure = [this](const std::string& w) { fail(w); };
  std::vector<ZoneSet> out;
  std::map<std::string, std::size_t> at;
  Statement sets(db_, "SELECT id, owner, name, created FROM zonesets ORDER BY created, id", failure);
  while (sets.row()) {
    at[sets.col(0)] = out.size();
    out.push_back({sets.col(0), sets.col(1), sets.col(2), sets.col(3), {}});
  }
  Statement versions(db_, "SELECT id, version, file, zones, created FROM zoneset_versions ORDER BY id, version", failure);
  while (versions.row()) {
    const auto it = at.find(versions.col(0));
    if (it == at.end()) fail("zone set version without its set: " + versions.col(0));
    out[it->second].versions.push_back({versions.colInt(1), versions.col(2), versions.colInt(3), versions.col(4)});
  }
  for (const ZoneSet& z : out) {
    if (z.versions.empty()) fail("zone set " + z.id + " has no version");
  }
  return out;
}

void ServiceStore::putApproval(const ApprovalRow& a) {
  const auto failure = [this](const std::string& w) { fail(w); };
  Statement st(db_,
               "INSERT OR REPLACE INTO approvals (id, owner, name, status, created, dir, summary, error) VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
               failure);
  st.text(1, a.id).text(2, a.owner).text(3, a.name).text(4, a.status).text(5, a.created).text(6, a.dir).text(7, a.summary).text(8, a.error);
  if (!st.done()) fail("cannot store approval " + a.id);
}

std::vector<ApprovalRow> ServiceStore::approvals() const {
  const auto failure = [this](const std::string& w) { fail(w); };
  std::vector<ApprovalRow> out;
  Statement st(db_, "SELECT id, owner, name, status, created, dir, summary, error FROM approvals ORDER BY created, id", failure);
  while (st.row()) out.push_back({st.col(0), st.col(1), st.col(2), st.col(3), st.col(4), st.col(5), st.col(6), st.col(7)});
  return out;
}

void ServiceStore::addFlight(const FlightRow& f) {
  const auto failure = [this](const std::string& w) { fail(w); };
  Statement st(db_, "INSERT INTO service_flights (id, owner, approval, created) VALUES (?, ?, ?, ?)", failure);
  if (!st.text(1, f.id).text(2, f.owner).text(3, f.approval).text(4, f.created).done()) fail("cannot store flight " + f.id);
}

std::vector<FlightRow> ServiceStore::flights() const {
  const auto failure = [this](const std::string& w) { fail(w); };
  std::vector<FlightRow> out;
  Statement st(db_, "SELECT id, owner, approval, created FROM service_flights ORDER BY created, id", failure);
  while (st.row()) out.push_back({st.col(0), st.col(1), st.col(2), st.col(3)});
  return out;
}

}  // namespace skylane::service
