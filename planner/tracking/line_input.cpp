#include "planner/tracking/line_input.hpp"

#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace skylane::planner {

namespace {

using maps::ParseError;

/// Lines from a POSIX file descriptor: a file, stdin, a FIFO or a bound UDP socket.
class PosixLineInput final : public LineInput {
 public:
  PosixLineInput(const std::string& input, const DatagramOptions& udp) : name_(input) {
    if (input == "-") {
      fd_ = STDIN_FILENO;
      live_ = true;
    } else if (input.rfind("udp://", 0) == 0) {
      udp_ = std::make_unique<DatagramSocket>(input.substr(6), name_, udp);
      fd_ = udp_->fd();
      live_ = true;
    } else {
      openFile();
    }
  }
  ~PosixLineInput() override {
    if (fd_ > STDIN_FILENO && !udp_) close(fd_);
  }
  PosixLineInput(const PosixLineInput&) = delete;
  PosixLineInput& operator=(const PosixLineInput&) = delete;

  Status next(std::string& line, int timeout_ms) override;
  [[nodiscard]] bool live() const override { return live_; }
  [[nodiscard]] bool rereadable() const override { return regular_; }
  [[nodiscard]] const std::string& name() const override { return name_; }
  [[nodiscard]] std::optional<std::uint64_t> droppedDatagrams() const override {
    return udp_ ? std::optional<std::uint64_t>(udp_->dropped()) : std::nullopt;
  }

 private:
  void openFile();
  /// The next complete line in the buffer (a line too long is dropped up to its end).
  bool takeLine(std::string& line, Status& status);
  /// Reads more bytes; false on a quiet live input (or a signal).
  bool fill(int timeout_ms);
  /// Forgets the bytes buffered.
  void dropRead();
  /// Takes a line's CR off (a CR LF line end).
  static void dropCarriageReturn(std::string& line);

  std::string name_;
  int fd_ = -1;
  std::unique_ptr<DatagramSocket> udp_;  ///< a UDP input (fd_ is its socket)
  bool live_ = false, eof_ = false, skipping_ = false, regular_ = false;
  std::string buffer_;
  std::size_t start_ = 0;  ///< where the lines not yet taken begin in buffer_
};

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
  const auto nl = buffer_.find('\n', start_);
  if (skipping_) {
    if (nl == std::string::npos) {
      dropRead();
      return false;
    }
    start_ = nl + 1;
    skipping_ = false;
    return takeLine(line, status);
  }
  if (nl == std::string::npos) {
    if (buffer_.size() - start_ <= kMaxLineBytes) return false;
    dropRead();
    skipping_ = true;
    status = Status::kTooLong;
    return true;
  }
  line.assign(buffer_, start_, nl - start_);  // into the caller's storage
  start_ = nl + 1;
  dropCarriageReturn(line);
  status = Status::kLine;
  return true;
}

void PosixLineInput::dropCarriageReturn(std::string& line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
}

void PosixLineInput::dropRead() {
  buffer_.clear();
  start_ = 0;
}

bool PosixLineInput::fill(int timeout_ms) {
  if (live_) {
    pollfd p{fd_, POLLIN, 0};
    const int r = poll(&p, 1, timeout_ms);
    if (r == 0 || (r < 0 && errno == EINTR)) {
      if (udp_) udp_->refreshDrops();  // drops after the last datagram read
      return false;
    }
  }
  char chunk[65536];
  const ssize_t n = udp_ ? udp_->receive(chunk, sizeof chunk, nullptr) : read(fd_, chunk, sizeof chunk);
  if (n < 0 && errno == EINTR) return false;
  if (n <= 0) {
    if (!udp_) eof_ = true;
    return true;
  }
  buffer_.erase(0, start_);  // the lines taken: once per read, not once per line
  start_ = 0;
  buffer_.append(chunk, static_cast<std::size_t>(n));
  if (udp_ && buffer_.back() != '\n') buffer_.push_back('\n');  // a datagram ends its last line
  return true;
}

LineInput::Status PosixLineInput::next(std::string& line, int timeout_ms) {
  for (;;) {
    Status status = Status::kLine;
    if (takeLine(line, status)) return status;
    if (eof_ && !skipping_) {
      if (start_ == buffer_.size()) return Status::kEnd;
      line.assign(buffer_, start_);  // the last line, without its newline (a CR LF cut after the CR too)
      dropCarriageReturn(line);
      dropRead();
      return Status::kLine;
    }
    if (eof_) return Status::kEnd;
    if (!fill(timeout_ms)) return Status::kTimeout;
  }
}

}  // namespace

std::unique_ptr<LineInput> openLineInput(const std::string& input, const DatagramOptions& udp) {
  return std::make_unique<PosixLineInput>(input, udp);
}

LineInput::Status MemoryLineInput::next(std::string& line, int /*timeout_ms*/) {
  if (lines_.empty()) return Status::kEnd;
  line = std::move(lines_.front());
  lines_.pop_front();
  return Status::kLine;
}

}  // namespace skylane::planner
