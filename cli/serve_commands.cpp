#include "cli/serve_commands.hpp"

#include "link/byte_link.hpp"
#include "link/mavlink/fix_source.hpp"
#include "link/ubx/fix_source.hpp"
#include "maps/parse_error.hpp"
#include "planner/tracking/fix_source.hpp"
#include "planner/tracking/line_input.hpp"
#include "service/service.hpp"

#include <csignal>
#include <iostream>
#include <memory>
#include <thread>

#include <sys/resource.h>
#include <unistd.h>

namespace skylane::cli {

namespace {

service::Service* g_service = nullptr;

/// The first SIGINT/SIGTERM stops the service (run() returns); the database is committed after
/// every request, so nothing accepted is lost either way.
void onSignal(int) {
  if (g_service) g_service->stop();
}

std::string selfExecutable() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error("cannot find the skylane executable (/proc/self/exe)");
  return std::string(buf, static_cast<std::size_t>(n));
}

/// Open files up to the hard limit: every connection and event stream holds a socket.
void raiseOpenFileLimit() {
  rlimit r{};
  if (getrlimit(RLIMIT_NOFILE, &r) == 0 && r.rlim_cur < r.rlim_max) {
    r.rlim_cur = r.rlim_max;
    setrlimit(RLIMIT_NOFILE, &r);
  }
}

/// One --input: FORMAT:ADDRESS[#FLIGHT] → its source and the flight it feeds (empty: named per record).
std::pair<std::unique_ptr<planner::FixSource>, std::string> openInput(const std::string& spec, const planner::DatagramOptions& udp) {
  const std::size_t colon = spec.find(':');
  const std::size_t hash = spec.rfind('#');
  const std::string format = spec.substr(0, colon);
  const std::string flight = hash == std::string::npos ? std::string() : spec.substr(hash + 1);
  const std::string address = colon == std::string::npos ? std::string() : spec.substr(colon + 1, hash == std::string::npos ? std::string::npos : hash - colon - 1);
  const char* expected = "FORMAT:ADDRESS[#FLIGHT]: jsonl:udp://IP:PORT (lines name their flight), mavlink:ADDRESS#FLIGHT or ubx:ADDRESS#FLIGHT";
  if (address.empty()) throw maps::ParseError("--input", 0, "--input", spec, expected);
  if (format == "jsonl") return {std::make_unique<planner::JsonLinesFixSource>(planner::openLineInput(address, udp)), flight};
  if ((format == "mavlink" || format == "ubx") && !flight.empty()) {
    auto link = link::openByteLink(address, 57600, udp);
    if (format == "ubx") return {std::make_unique<link::ubx::UbxFixSource>(std::move(link), flight), flight};
    return {std::make_unique<link::mavlink::MavlinkFixSource>(std::move(link), flight), flight};
  }
  throw maps::ParseError("--input", 0, "--input", spec, expected);
}

void runServe(service::ServeOptions o, const std::vector<std::string>& inputs, int udp_buffer, bool quiet) {
  o.program = selfExecutable();
  raiseOpenFileLimit();
  if (o.web_dir == "none") o.web_dir.clear();
  auto log = [quiet](const std::string& m) {
    if (!quiet) std::cerr << "skylane: serve: " << m << "\n";
  };
  std::unique_ptr<service::Service> made;
  try {
    made = std::make_unique<service::Service>(o, log);
  } catch (const std::runtime_error& e) {  // a database, folder or address it cannot use: the caller's to fix
    throw std::invalid_argument(e.what());
  }
  service::Service& s = *made;
  for (const std::string& spec : inputs) {
    auto [source, flight] = openInput(spec, planner::DatagramOptions{udp_buffer, log});
    s.addInput(std::move(source), flight);
  }
  g_service = &s;
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::signal(SIGPIPE, SIG_IGN);
  // The line a script waits for: the port actually listened on (with --port 0, a free one).
  std::cout << "skylane: serving on http://" << o.host << ":" << s.port() << "/" << std::endl;
  s.run();
  g_service = nullptr;
  log("stopped");
}

}  // namespace

void addServeCommands(CLI::App& app) {
  auto o = std::make_shared<service::ServeOptions>();
  auto quiet = std::make_shared<bool>(false);
  o->web_dir = SKYLANE_WEB_DIR;
  CLI::App* c = app.add_subcommand("serve", "the approval and tracking service: HTTP API, operators, event streams, web map");
  c->add_option("--db", o->db, "SQLite database (created when missing); its files go in DB.files/")->required();
  c->add_option("--tokens", o->tokens, "tokens file: {\"tokens\": [{\"sha256\": HEX, \"operator\": NAME} | {\"sha256\": HEX, \"role\": \"authority\"}]}")
      ->required()
      ->check(CLI::ExistingFile);
  c->add_option("--host", o->host, "address to listen on (default 127.0.0.1)");
  c->add_option("--port", o->port, "port to listen on (default 8080; 0: any free port, printed)");
  c->add_option("--orbits", o->orbits_dir, "folder of almanacs and ephemerides a mission may name")->check(CLI::ExistingDirectory);
  c->add_option("--web", o->web_dir, "folder of the built web map (\"none\": no map)");
  c->add_option("--approval-workers", o->approval_workers, "approvals computed at once (default 1)")->check(CLI::Range(1, 64));
  c->add_option("--approval-queue", o->approval_queue, "approvals waiting at most (then 429; default 16)")->check(CLI::Range(1, 100000));
  c->add_option("--rate", o->rate_per_s, "requests per second per token (default 200)")->check(CLI::Range(0.01, 1e7));
  c->add_option("--burst", o->rate_burst, "requests a token may send at once (default 400)")->check(CLI::Range(1.0, 1e7));
  c->add_option("--max-body", o->limits.body_bytes, "largest request body in bytes (then 413; default 16 MiB)")
      ->check(CLI::Range(std::size_t{1024}, std::size_t{1} << 30));
  auto timeout_s = std::make_shared<int>(30);
  c->add_option("--request-timeout", *timeout_s, "seconds a client has to send a whole request (default 30)")->check(CLI::Range(1, 3600));
  c->add_option("--max-connections", o->limits.max_connections, "open connections at most (default 10000)")->check(CLI::Range(1, 1000000));
  auto inputs = std::make_shared<std::vector<std::string>>();
  c->add_option("--input", *inputs,
                "a fix input besides HTTP, judged by the same engine: jsonl:udp://IP:PORT (or a file or FIFO; each line names "
                "its flight), mavlink:ADDRESS#FLIGHT, ubx:ADDRESS#FLIGHT (ADDRESS: udp://IP:PORT or a serial device)");
  auto udp_buffer = std::make_shared<int>(0);
  c->add_option("--udp-buffer", *udp_buffer,
                "each udp:// input's socket receive buffer in bytes (default: the system's; capped by net.core.rmem_max, "
                "the granted size said when smaller); kernel drops are input_dropped events and a metric")
      ->check(CLI::Range(planner::kMinReceiveBufferBytes, planner::kMaxReceiveBufferBytes));
  c->add_option("--nats", o->nats_url,
                "NATS server(s) set up by `skylane nats setup`: approvals go to the approve workers' queue, fixes to the track "
                "workers, events come back from the event stream (docs/nats.md); without it everything runs in this process");
  c->add_flag("--quiet", *quiet, "no log lines on stderr");
  c->callback([o, quiet, timeout_s, inputs, udp_buffer] {
    o->limits.request_timeout = std::chrono::seconds(*timeout_s);
    runServe(*o, *inputs, *udp_buffer, *quiet);
  });
}

}  // namespace skylane::cli
