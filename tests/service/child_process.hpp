#pragma once
/// \file
/// \brief Child processes of the tests: any command with its output in a log (skylane workers),
/// and a real `nats-server -js` on a free loopback port with a file store in the test's folder
/// (killed and restarted by the test on the same store).

#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace skylane::test {

// (Shared by the service and NATS tests and the load generator bench/nats_load.cpp.)

/// A port of `type` (SOCK_STREAM, SOCK_DGRAM) free on 127.0.0.1 now (bound and released: the
/// kernel does not hand it out again at once).
inline int freePort(int type) {
  const int fd = ::socket(AF_INET, type, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}
inline int freeTcpPort() { return freePort(SOCK_STREAM); }
inline int freeUdpPort() { return freePort(SOCK_DGRAM); }

inline bool tcpAccepts(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(fd);
  return ok;
}

/// Sends `sig` to a child and waits for it: its exit status (128 + signal when killed); −1 when
/// there is none. `pid` is cleared.
inline int killAndWait(pid_t& pid, int sig) {
  if (pid <= 0) return -1;
  ::kill(pid, sig);
  int st = 0;
  waitpid(pid, &st, 0);
  pid = -1;
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

/// A child process with its standard error (and output) in a log file.
class ChildProcess {
 public:
  ChildProcess(std::vector<std::string> args, const std::string& log) : args_(std::move(args)), log_(log) { start(); }
  ~ChildProcess() { kill(SIGKILL); }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  void start() {
    pid_ = fork();
    if (pid_ == 0) {
      FILE* f = std::fopen(log_.c_str(), "a");
      if (f) {
        dup2(fileno(f), STDOUT_FILENO);
        dup2(fileno(f), STDERR_FILENO);
      }
      std::vector<char*> argv;
      for (std::string& a : args_) argv.push_back(a.data());
      argv.push_back(nullptr);
      execvp(argv[0], argv.data());
      _exit(127);
    }
  }
  /// Sends `sig` and waits; the exit status (128 + signal when killed).
  int kill(int sig) { return killAndWait(pid_, sig); }
  [[nodiscard]] pid_t pid() const { return pid_; }
  [[nodiscard]] bool running() const { return pid_ > 0 && ::waitpid(pid_, nullptr, WNOHANG) == 0; }
  [[nodiscard]] std::string log() const {
    std::ifstream in(log_);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

 private:
  std::vector<std::string> args_;
  std::string log_;
  pid_t pid_ = -1;
};

/// nats-server with JetStream, the skylane fix mapping for `partitions`, a file store in `dir`.
class NatsServer {
 public:
  NatsServer(const std::filesystem::path& dir, int partitions) : dir_(dir), port_(freeTcpPort()) {
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "nats.conf") << "listen: 127.0.0.1:" << port_ << "\nmax_payload: 8MB\njetstream { store_dir: \""
                                     << (dir / "store").string() << "\" }\nmappings = {\n  \"skylane.fix.*.*\": \"skylane.fixp.{{partition("
                                     << partitions << ",1,2)}}.{{wildcard(1)}}.{{wildcard(2)}}\"\n}\n";
    start();
  }
  void start() {
    process_ = std::make_unique<ChildProcess>(std::vector<std::string>{"nats-server", "-c", (dir_ / "nats.conf").string()},
                                              (dir_ / "nats.log").string());
    for (int i = 0; i < 200 && !tcpAccepts(port_); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(25));
    if (!tcpAccepts(port_)) throw std::runtime_error("nats-server did not start: " + process_->log());
  }
  void kill() { process_->kill(SIGKILL); }
  [[nodiscard]] pid_t pid() const { return process_->pid(); }
  [[nodiscard]] std::string url() const { return "nats://127.0.0.1:" + std::to_string(port_); }
  /// Whether nats-server is installed (the tests skip without it only outside CI).
  static bool installed() { return std::system("command -v nats-server > /dev/null 2>&1") == 0; }

 private:
  std::filesystem::path dir_;
  int port_;
  std::unique_ptr<ChildProcess> process_;
};

}  // namespace skylane::test
