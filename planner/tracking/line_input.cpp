#include "planner/tracking/line_input.hpp"

#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>

namespace skylane::planner {

namespace {

using maps::ParseError;

/// Lines from a POSIX file descriptor: a file, stdin, a FIFO or a bound UDP socket.
class PosixLineInput final : public LineInput {
 public:
  explicit PosixLineInput(const std::string& input) : name_(input) {
    if (input == "-") {
      fd_ = STDIN_FILENO;
      live_ = true;
    } else if (input.rfind("udp://", 0) == 0) {
      bindUdp(input.substr(6));
    } else {
      openFile();
    }
  }
  ~PosixLineInput() override {
    if (fd_ > STDIN_FILENO) close(fd_);
  }
  PosixLineInput(const PosixLineInput&) = delete;
  PosixLineInput& operator=(const PosixLineInput&) = delete;

  Status next(std::string& line, int timeout_ms) override;
  [[nodiscard]] bool live() const override { return live_; }
  [[nodiscard]] bool rereadable() const override { return regular_; }
  [[nodiscard]] const std::string& name() const override { return name_; }

 private:
  void bindUdp(const std::string& hostport);
  void openFile();
  /// The next complete line in the buffer (a line too long is dropped up to its end).
  bool takeLine(std::string& line, Status& status);
  /// Reads more bytes; false on a quiet live input (or a signal).
  bool fill(int timeout_ms);

  std::string name_;
  int fd_ = -1;
  bool live_ = false, udp_ = false, eof_ = false, skipping_ = false, regular_ = false;
  std::string buffer_;
};

void PosixLineInput::bindUdp(const std::string& hostport) {
  fd_ = bindUdpSocket(hostport, name_);
  udp_ = live_ = true;
}

void PosixLineInput::openFile() {
  maps::requireNotAFolder(name_, "--input");
  fd_ = open(name_.c_str(), O_RDONLY);
  if (fd_ < 0) throw ParseError(name_, 0, "--input", name_, std::string("a readable file (") + std::strerror(errno) + ")");
  struct stat info {};
  const bool known = fstat(fd_, &info) == 0;
  live_ = known && (S_ISFIFO(info.st_mode) || S_ISCHR(info.st_mode) || S_ISSOCK(info.st_mode));
  regular_ = known && S_ISREG(info.st_mode);
}

bool PosixLineInput::takeLine(std::string& line, Status& status) {
  const auto nl = buffer_.find('\n');
  if (skipping_) {
    if (nl == std::string::npos) {
      buffer_.clear();
      return false;
    }
    buffer_.erase(0, nl + 1);
    skipping_ = false;
    return takeLine(line, status);
  }
  if (nl == std::string::npos) {
    if (buffer_.size() <= kMaxLineBytes) return false;
    buffer_.clear();
    skipping_ = true;
    status = Status::kTooLong;
    return true;
  }
  line = buffer_.substr(0, nl);
  buffer_.erase(0, nl + 1);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  status = Status::kLine;
  return true;
}

bool PosixLineInput::fill(int timeout_ms) {
  if (live_) {
    pollfd p{fd_, POLLIN, 0};
    const int r = poll(&p, 1, timeout_ms);
    if (r == 0 || (r < 0 && errno == EINTR)) return false;
  }
  char chunk[65536];
  const ssize_t n = udp_ ? recv(fd_, chunk, sizeof chunk, 0) : read(fd_, chunk, sizeof chunk);
  if (n < 0 && errno == EINTR) return false;
  if (n <= 0) {
    if (!udp_) eof_ = true;
    return true;
  }
  buffer_.append(chunk, static_cast<std::size_t>(n));
  if (udp_ && buffer_.back() != '\n') buffer_.push_back('\n');  // a datagram ends its last line
  return true;
}

LineInput::Status PosixLineInput::next(std::string& line, int timeout_ms) {
  for (;;) {
    Status status = Status::kLine;
    if (takeLine(line, status)) return status;
    if (eof_ && !skipping_) {
      if (buffer_.empty()) return Status::kEnd;
      line.swap(buffer_);
      buffer_.clear();
      return Status::kLine;
    }
    if (eof_) return Status::kEnd;
    if (!fill(timeout_ms)) return Status::kTimeout;
  }
}

}  // namespace

int bindUdpSocket(const std::string& hostport, const std::string& input) {
  const auto colon = hostport.rfind(':');
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  const std::string host = colon == std::string::npos ? "" : hostport.substr(0, colon);
  const std::string port = colon == std::string::npos ? "" : hostport.substr(colon + 1);
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (host.empty() || port.empty() || *end != '\0' || p < 1 || p > 65535 || inet_pton(AF_INET, host.c_str(), &addr.sin_addr) != 1) {
    throw ParseError("--input", 0, "--input", input, "udp://IPv4:PORT, e.g. udp://127.0.0.1:5005");
  }
  addr.sin_port = htons(static_cast<std::uint16_t>(p));
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) close(fd);
    throw ParseError("--input", 0, "--input", input, "a UDP port to listen on (" + why + ")");
  }
  return fd;
}

std::unique_ptr<LineInput> openLineInput(const std::string& input) { return std::make_unique<PosixLineInput>(input); }

LineInput::Status MemoryLineInput::next(std::string& line, int /*timeout_ms*/) {
  if (lines_.empty()) return Status::kEnd;
  line = std::move(lines_.front());
  lines_.pop_front();
  return Status::kLine;
}

}  // namespace skylane::planner
