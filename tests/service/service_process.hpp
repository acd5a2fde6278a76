#pragma once
/// \file
/// \brief `skylane serve` as a child process of a test: started on a free loopback port with a
/// database and tokens in a folder of the test's own, stopped (or killed) by the test.

#include "tests/service/child_process.hpp"
#include "tests/test_util.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace skylane::test {

/// The three tokens of the tests and the file listing their SHA-256 digests.
struct TestTokens {
  static constexpr const char* kAuthority = "Bearer authority-token-for-tests";
  static constexpr const char* kAcme = "Bearer acme-token-for-tests";
  static constexpr const char* kOther = "Bearer other-token-for-tests";
  /// Writes the tokens file (digests computed by sha256sum, independently of skylane) into `dir`.
  static std::string write(const std::filesystem::path& dir) {
    auto digest = [](const std::string& token) {
      const CommandResult r = runCommand("printf '%s' '" + token + "' | sha256sum");
      return r.out.substr(0, 64);
    };
    const std::string path = (dir / "tokens.json").string();
    std::ofstream(path) << R"({"tokens": [{"sha256": ")" << digest("authority-token-for-tests")
                        << R"(", "role": "authority"}, {"sha256": ")" << digest("acme-token-for-tests")
                        << R"(", "operator": "acme"}, {"sha256": ")" << digest("other-token-for-tests")
                        << R"(", "operator": "other"}]})";
    return path;
  }
};

/// A running service.
class ServiceProcess {
 public:
  /// Starts `skylane serve` on the database `db` with `extra` options; waits for its port.
  ServiceProcess(const std::filesystem::path& dir, const std::vector<std::string>& extra = {}) : dir_(dir) {
    std::filesystem::create_directories(dir / "orbits");
    std::filesystem::copy_file(dataPath("gnss/alm01jan2020.txt"), dir / "orbits" / "alm01jan2020.txt",
                               std::filesystem::copy_options::overwrite_existing);
    tokens_ = TestTokens::write(dir);
    start(extra);
  }
  ~ServiceProcess() { kill(SIGKILL); }
  ServiceProcess(const ServiceProcess&) = delete;
  ServiceProcess& operator=(const ServiceProcess&) = delete;

  void start(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {SKYLANE_BINARY, "serve", "--db", (dir_ / "service.sqlite").string(), "--tokens", tokens_,
                                     "--orbits", (dir_ / "orbits").string(), "--port", "0", "--web", "none", "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe");
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);
      ::close(fds[0]);
      ::close(fds[1]);
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    ::close(fds[1]);
    std::string line;
    char c;
    while (::read(fds[0], &c, 1) == 1 && c != '\n') line += c;
    ::close(fds[0]);
    const std::size_t colon = line.rfind(':');
    if (line.find("serving on") == std::string::npos || colon == std::string::npos) {
      throw std::runtime_error("skylane serve did not start: \"" + line + "\"");
    }
    port_ = std::stoi(line.substr(colon + 1));
  }
  /// Sends `sig` and waits for the process; its exit status (128 + signal when killed).
  int kill(int sig) { return killAndWait(pid_, sig); }
  [[nodiscard]] int port() const { return port_; }
  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  std::string tokens_;
  pid_t pid_ = -1;
  int port_ = 0;
};

}  // namespace skylane::test
