#pragma once
// Shared helpers for skylane's tests.

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace skylane::test {

/// Path of a file under tests/data.
inline std::string dataPath(const std::string& rel) { return std::string(SKYLANE_TEST_DATA) + "/" + rel; }

/// Path of a scratch file in a directory of this test process alone: ctest runs every test as
/// its own process, two at a time, so a fixed name under TempDir() would be written by one test
/// while another reads it.
/// The directory goes when the process ends.
inline std::string scratchPath(const std::string& name) {
  struct Dir {
    std::filesystem::path path =
        std::filesystem::path(::testing::TempDir()) / ("skylane-test-" + std::to_string(::getpid()));
    Dir() { std::filesystem::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return (dir.path / name).string();
}

/// Even–odd crossing test of a point against a ring, in doubles: an independent check for
/// points not on the boundary.
inline bool insideByCrossings(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& ring) {
  bool in = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) in = !in;
  }
  return in;
}

/// Whole file as text.
inline std::string readData(const std::string& rel) {
  std::ifstream in(dataPath(rel), std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Compares vectors element-wise with an absolute tolerance and names the component.
inline ::testing::AssertionResult nearVec(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double tol) {
  if (a.size() != b.size()) return ::testing::AssertionFailure() << "sizes " << a.size() << " vs " << b.size();
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (!(std::abs(a[i] - b[i]) <= tol)) {
      return ::testing::AssertionFailure() << "component " << i << ": " << a[i] << " vs " << b[i] << " (tol " << tol << ")";
    }
  }
  return ::testing::AssertionSuccess();
}

/// Runs `fn` and returns the message of the exception of type E it throws ("" if none).
template <typename E>
std::string messageOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const E& e) {
    return e.what();
  }
  return "";
}

/// An NMEA 0183 sentence "$body*hh" with its checksum (XOR of the body's bytes).
inline std::string nmeaSentence(const std::string& body) {
  unsigned char x = 0;
  for (char ch : body) x ^= static_cast<unsigned char>(ch);
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X", x);
  return "$" + body + tail;
}

/// Degrees as NMEA writes them: ddmm.mmmmmmm,N (latitude) or dddmm.mmmmmmm,E.
inline std::string nmeaAngle(double deg, bool lat) {
  const double a = std::abs(deg);
  const int d = static_cast<int>(a);
  char buf[32];
  std::snprintf(buf, sizeof buf, lat ? "%02d%010.7f,%c" : "%03d%010.7f,%c", d, (a - d) * 60.0,
                lat ? (deg >= 0 ? 'N' : 'S') : (deg >= 0 ? 'E' : 'W'));
  return buf;
}

/// What a shell command did: its exit status (−1 when it did not exit) and its standard output.
struct CommandResult {
  int status = -1;
  std::string out;
};

/// Runs `command` with /bin/sh and collects its standard output.
inline CommandResult runCommand(const std::string& command) {
  CommandResult r;
  FILE* p = popen(command.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (fgets(buf, sizeof buf, p)) r.out += buf;
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// A small tmpfs mounted on a scratch folder for full-disk cases, when this process may mount
/// (root, or a container with CAP_SYS_ADMIN); mounted() is false otherwise and the test skips.
class SmallDisk {
 public:
  explicit SmallDisk(const std::string& name, const std::string& size = "64k") : path_(scratchPath(name)) {
    std::filesystem::create_directories(path_);
    mounted_ = ::geteuid() == 0 && ::mount("tmpfs", path_.c_str(), "tmpfs", 0, ("size=" + size).c_str()) == 0;
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(path_.c_str(), MNT_DETACH);
  }
  SmallDisk(const SmallDisk&) = delete;
  SmallDisk& operator=(const SmallDisk&) = delete;
  [[nodiscard]] bool mounted() const { return mounted_; }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
  bool mounted_ = false;
};

/// The whole file as text ("" when it cannot be read).
inline std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The names in a folder that start with '.' (an output's temporary files), for checks that
/// none is left behind.
inline std::vector<std::string> hiddenFiles(const std::string& folder) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = e.path().filename().string();
    if (!name.empty() && name[0] == '.') out.push_back(name);
  }
  return out;
}

}  // namespace skylane::test
