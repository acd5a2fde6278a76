#include "cli/serve_commands.hpp"

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

void runServe(service::ServeOptions o, bool quiet) {
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
  c->add_flag("--quiet", *quiet, "no log lines on stderr");
  c->callback([o, quiet, timeout_s] {
    o->limits.request_timeout = std::chrono::seconds(*timeout_s);
    runServe(*o, *quiet);
  });
}

}  // namespace skylane::cli
