#include "planner/tracking/event_file_sink.hpp"

#include "maps/atomic_file.hpp"
#include "maps/parse_error.hpp"
#include "planner/tracking/track_store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>

namespace skylane::planner {

namespace {

/// The name under which the database keeps a file's mark: the same file however it is named.
std::string markName(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : p.string();
}

}  // namespace

EventFileSink::EventFileSink(std::string path, TrackStore& store) : path_(std::move(path)), store_(store) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0666);
  if (fd_ < 0) throw maps::OutputError(path_, "--out", maps::systemReason(errno));
  try {
    repair();
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

EventFileSink::~EventFileSink() {
  if (fd_ >= 0) ::close(fd_);
}

void EventFileSink::repair() {
  struct stat info {};
  if (::fstat(fd_, &info) != 0) throw maps::OutputError(path_, "--out", maps::systemReason(errno));
  // A device or a FIFO (/dev/null, a pipe to a reader) has no length to compare: written as is.
  regular_ = S_ISREG(info.st_mode);
  if (!regular_) return;
  const auto size = static_cast<std::uint64_t>(info.st_size);
  bytes_ = size;
  const std::optional<OutputMark> mark = store_.outputMark(markName(path_));
  if (!mark || size == mark->bytes_after || size < mark->bytes_before) return;  // whole, or a new file
  if (size > mark->bytes_after) {
    throw maps::ParseError(path_, 0, "--out", std::to_string(size) + " bytes",
                           "at most the " + std::to_string(mark->bytes_after) + " bytes the tracker database " +
                               store_.path() + " recorded (another program wrote to it: give a new --out file)");
  }
  // Cut inside the last batch: back to its start, and its lines again from the database.
  if (::ftruncate(fd_, static_cast<off_t>(mark->bytes_before)) != 0) {
    throw maps::OutputError(path_, "--out", maps::systemReason(errno));
  }
  bytes_ = mark->bytes_before;
  std::string lines;
  for (const std::string& line : store_.eventLines(mark->first_seq, mark->last_seq)) {
    lines += line + '\n';
    ++repaired_lines_;
  }
  append(lines);
}

void EventFileSink::write(const TrackEvent& /*event*/, const std::string& json_line) {
  pending_ += json_line;
  pending_ += '\n';
  const std::int64_t seq = store_.lastEventSeq();  // the store, the first sink, stored it just now
  if (first_seq_ == 0) first_seq_ = seq;
  last_seq_ = seq;
}

void EventFileSink::beforeCommit() {
  if (pending_.empty() || !regular_) return;
  store_.setOutputMark(markName(path_), {bytes_, bytes_ + pending_.size(), first_seq_, last_seq_});
}

void EventFileSink::flush() {
  if (pending_.empty()) return;
  append(pending_);
  pending_.clear();
  first_seq_ = last_seq_ = 0;
}

void EventFileSink::append(const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw maps::OutputError(path_, "--out", maps::systemReason(n < 0 ? errno : EIO));
    done += static_cast<std::size_t>(n);
  }
  bytes_ += bytes.size();
}

}  // namespace skylane::planner
