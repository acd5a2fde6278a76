#pragma once
/// \file
/// \brief What `skylane serve` keeps besides the tracker's own tables (track_store.hpp, in the same
/// SQLite file): zone sets and their versions, approvals, and which operator owns which flight.
/// The files themselves (each zone set version, each approval's mission and outputs) live in the
/// service's folder beside the database; the rows name them.
///
/// Tables: zonesets(id, owner, name, created), zoneset_versions(id, version, file, zones, created),
/// approvals(id, owner, name, status, created, dir, summary, error), service_flights(id, owner,
/// approval, created). An owner is an operator's name, "" for the authority (public zone sets).

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

struct sqlite3;

namespace skylane::service {

struct ZoneSetVersion {
  int version = 0;
  std::string file;  ///< the zone file as uploaded
  int zones = 0;
  std::string created;
};

struct ZoneSet {
  std::string id, owner, name, created;
  std::vector<ZoneSetVersion> versions;  ///< ascending
  [[nodiscard]] const ZoneSetVersion& latest() const { return versions.back(); }
};

struct ApprovalRow {
  std::string id, owner, name, status, created, dir, summary, error;
};

struct FlightRow {
  std::string id, owner, approval, created;
};

/// \brief The service's tables.
class ServiceStore {
 public:
  /// \throws std::runtime_error naming the file and SQLite's message.
  explicit ServiceStore(const std::string& path);
  ~ServiceStore();
  ServiceStore(const ServiceStore&) = delete;
  ServiceStore& operator=(const ServiceStore&) = delete;

  void addZoneSet(const ZoneSet& z);  ///< with its first version
  void addZoneSetVersion(const std::string& id, const ZoneSetVersion& v);
  [[nodiscard]] std::vector<ZoneSet> zoneSets() const;

  void putApproval(const ApprovalRow& a);
  [[nodiscard]] std::vector<ApprovalRow> approvals() const;

  void addFlight(const FlightRow& f);
  [[nodiscard]] std::vector<FlightRow> flights() const;

 private:
  void exec(const std::string& sql) const;
  [[noreturn]] void fail(const std::string& what) const;
  std::string path_;
  sqlite3* db_ = nullptr;
};

}  // namespace skylane::service
