#pragma once
/// \file
/// \brief `skylane serve`: route approval, no-fly-zone enforcement and live corridor tracking as
/// an HTTP service for many operators (docs/service.md). Zone sets are uploaded and versioned
/// (public ones by the authority, private keep-in/keep-out sets by an operator for its own
/// missions); approvals run on a pool of workers with a bounded queue; approved flights are
/// tracked by one tracking engine whose events stream to their operator (Server-Sent Events,
/// resumable). Everything is kept in one SQLite database and a folder beside it, so a restarted
/// service has its zone sets, approvals, flights, their state and events back.

#include "service/http_server.hpp"

#include <functional>
#include <memory>
#include <string>

namespace skylane::planner {
class FixSource;
}

namespace skylane::service {

/// \brief How the service runs.
struct ServeOptions {
  std::string host = "127.0.0.1";
  unsigned short port = 8080;
  std::string db;          ///< the SQLite database; its files go in `<db>.files/`
  std::string tokens;      ///< the tokens file (auth.hpp)
  std::string orbits_dir;  ///< almanacs and ephemerides a mission may name
  std::string web_dir;     ///< the built web map (empty: none)
  std::string program;     ///< the skylane executable the approvals run
  int approval_workers = 1;
  std::size_t approval_queue = 16;
  double rate_per_s = 200.0;  ///< requests per second per token
  double rate_burst = 400.0;
  std::size_t max_fixes_per_request = 20000;
  HttpLimits limits;
  /// NATS server(s) (nats://host:port, comma-separated): approvals and tracking go to the
  /// JetStream workers (docs/nats.md); empty: everything runs in this process.
  std::string nats_url;
};

class ServiceImpl;

/// \brief The service.
class Service {
 public:
  using Log = std::function<void(const std::string&)>;
  /// \throws maps::ParseError for a bad tokens file; std::runtime_error for a database or folder
  /// that cannot be opened or is damaged, or an address it cannot listen on.
  Service(ServeOptions options, Log log);
  ~Service();
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;
  [[nodiscard]] unsigned short port() const;
  /// \brief A fix input besides HTTP (a UDP port of JSON lines, a MAVLink or UBX link): read on
  /// a thread of its own, each record judged by the service's engine on the service's thread
  /// and committed. `flight`: the flight every fix of it belongs to (a MAVLink or UBX link is one
  /// vehicle), or empty when each record names its flight. An input given on the command line
  /// is the provider's own and may feed any flight.
  void addInput(std::unique_ptr<planner::FixSource> source, const std::string& flight);
  /// \brief Serves until stop().
  void run();
  /// \brief Ends run() (thread-safe).
  void stop();

 private:
  std::unique_ptr<ServiceImpl> impl_;
};

}  // namespace skylane::service
