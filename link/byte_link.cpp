#include "link/byte_link.hpp"

#include "maps/parse_error.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace skylane::link {
namespace {

using maps::ParseError;

/// The termios speed of a baud rate; B0 when it is not one.
speed_t speedOf(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    default: return B0;
  }
}

class PosixByteLink final : public ByteLink {
 public:
  PosixByteLink(const std::string& input, int baud, const planner::DatagramOptions& udp) : name_(input) {
    if (input == "-") {
      fd_ = STDIN_FILENO;
      live_ = true;
    } else if (input.rfind("udp://", 0) == 0) {
      udp_ = std::make_unique<planner::DatagramSocket>(input.substr(6), name_, udp);
      fd_ = udp_->fd();
      live_ = writable_ = true;
    } else {
      openPath(baud);
    }
  }
  ~PosixByteLink() override {
    if (fd_ > STDIN_FILENO && !udp_) close(fd_);
  }
  PosixByteLink(const PosixByteLink&) = delete;
  PosixByteLink& operator=(const PosixByteLink&) = delete;

  Status read(std::vector<std::uint8_t>& out, int timeout_ms) override;
  bool write(const std::uint8_t* data, std::size_t n) override;
  [[nodiscard]] bool live() const override { return live_; }
  [[nodiscard]] bool rereadable() const override { return regular_; }
  [[nodiscard]] const std::string& name() const override { return name_; }
  [[nodiscard]] std::optional<std::uint64_t> droppedDatagrams() const override {
    return udp_ ? std::optional<std::uint64_t>(udp_->dropped()) : std::nullopt;
  }

 private:
  void openPath(int baud);
  void makeRaw(int baud);

  std::string name_;
  int fd_ = -1;
  std::unique_ptr<planner::DatagramSocket> udp_;  ///< a UDP link (fd_ is its socket)
  bool live_ = false, regular_ = false, writable_ = false;
  sockaddr_in peer_{};
  bool have_peer_ = false;
};

void PosixByteLink::openPath(int baud) {
  struct stat info {};
  const bool exists = stat(name_.c_str(), &info) == 0;
  const bool device = exists && S_ISCHR(info.st_mode);
  fd_ = open(name_.c_str(), device ? (O_RDWR | O_NOCTTY) : O_RDONLY);
  if (fd_ < 0) throw ParseError(name_, 0, "--input", name_, std::string("a readable file or device (") + std::strerror(errno) + ")");
  live_ = exists && (S_ISFIFO(info.st_mode) || device || S_ISSOCK(info.st_mode));
  regular_ = exists && S_ISREG(info.st_mode);
  if (device) makeRaw(baud);
}

void PosixByteLink::makeRaw(int baud) {
  termios tio{};
  if (tcgetattr(fd_, &tio) != 0) {  // a character device that is not a terminal (e.g. /dev/null): read as is
    writable_ = true;
    return;
  }
  const speed_t speed = speedOf(baud);
  if (speed == B0) throw ParseError("--baud", 0, "--baud", std::to_string(baud), "9600, 19200, 38400, 57600, 115200, 230400, 460800 or 921600");
  cfmakeraw(&tio);  // 8N1, no echo, no line discipline
  tio.c_cflag |= CLOCAL | CREAD;
  cfsetispeed(&tio, speed);
  cfsetospeed(&tio, speed);
  if (tcsetattr(fd_, TCSANOW, &tio) != 0) {
    throw ParseError(name_, 0, "--input", name_, std::string("a serial device in raw mode (") + std::strerror(errno) + ")");
  }
  writable_ = true;
}

ByteLink::Status PosixByteLink::read(std::vector<std::uint8_t>& out, int timeout_ms) {
  if (live_) {
    pollfd p{fd_, POLLIN, 0};
    const int r = poll(&p, 1, timeout_ms);
    if (r == 0 || (r < 0 && errno == EINTR)) {
      if (udp_) udp_->refreshDrops();  // drops after the last datagram read
      return Status::kTimeout;
    }
  }
  std::uint8_t chunk[65536];
  ssize_t n = 0;
  if (udp_) {
    sockaddr_in from{};
    n = udp_->receive(chunk, sizeof chunk, &from);
    if (n > 0) {
      peer_ = from;  // replies go to where the vehicle's datagrams come from
      have_peer_ = true;
    }
  } else {
    n = ::read(fd_, chunk, sizeof chunk);
  }
  if (n < 0 && errno == EINTR) return Status::kTimeout;
  if (n <= 0) return udp_ ? Status::kTimeout : Status::kEnd;
  out.insert(out.end(), chunk, chunk + n);
  return Status::kData;
}

bool PosixByteLink::write(const std::uint8_t* data, std::size_t n) {
  if (!writable_) return false;
  if (udp_) {
    if (!have_peer_) return false;
    return sendto(fd_, data, n, 0, reinterpret_cast<const sockaddr*>(&peer_), sizeof peer_) == static_cast<ssize_t>(n);
  }
  return ::write(fd_, data, n) == static_cast<ssize_t>(n);
}

}  // namespace

std::unique_ptr<ByteLink> openByteLink(const std::string& input, int baud, const planner::DatagramOptions& udp) {
  return std::make_unique<PosixByteLink>(input, baud, udp);
}

}  // namespace skylane::link
