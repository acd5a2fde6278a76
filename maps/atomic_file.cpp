#include "maps/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <streambuf>
#include <system_error>

namespace skylane::maps {

namespace fs = std::filesystem;

namespace {

/// Bytes buffered before a write(2): large enough that writing costs no more than an ofstream's.
constexpr std::size_t kBufferBytes = 64 * 1024;

/// The longest part of the output's name kept in its temporary's name (NAME_MAX is 255).
constexpr std::size_t kTempNameChars = 200;

/// The process's file-creation mask (read once; umask(2) can only be read by setting it).
mode_t processUmask() {
  static const mode_t mask = [] {
    const mode_t m = ::umask(0);
    ::umask(m);
    return m;
  }();
  return mask;
}

/// Syncs a folder after a rename in it, so that the new name survives a power loss (best effort:
/// some file systems refuse to sync a folder, and the data are already synced).
void syncFolder(const fs::path& folder) {
  const int fd = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  (void)::fsync(fd);
  ::close(fd);
}

}  // namespace

OutputError::OutputError(const std::string& path, const std::string& option, const std::string& reason)
    : std::runtime_error(path + ": cannot write" + (option.empty() ? std::string() : " (" + option + ")") + ": " + reason),
      path_(path) {}

std::string systemReason(int error) { return std::error_code(error, std::generic_category()).message(); }

/// \brief A stream buffer writing to a file descriptor, keeping the first write error (errno).
class AtomicFile::Buffer final : public std::streambuf {
 public:
  explicit Buffer(int fd) : fd_(fd), data_(kBufferBytes) { setp(data_.data(), data_.data() + data_.size()); }
  [[nodiscard]] int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  /// Writes what is buffered; false once a write has failed (the rest is then dropped).
  bool drain() {
    const char* p = pbase();
    std::size_t n = static_cast<std::size_t>(pptr() - pbase());
    while (n > 0 && error_ == 0) {
      const ssize_t w = ::write(fd_, p, n);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) {
        error_ = w < 0 ? errno : EIO;
        break;
      }
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    setp(data_.data(), data_.data() + data_.size());
    return error_ == 0;
  }
  int fd_;
  std::vector<char> data_;
  int error_ = 0;
};

AtomicFile::AtomicFile(std::string path, std::string option) : path_(std::move(path)), option_(std::move(option)) {
  struct stat info {};
  const bool exists = ::stat(path_.c_str(), &info) == 0;
  if (exists && S_ISDIR(info.st_mode)) throw OutputError(path_, option_, "it is a folder, expected a file name");
  if (exists && !S_ISREG(info.st_mode)) {
    direct_ = true;
    fd_ = ::open(path_.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (fd_ < 0) fail(errno);
  } else {
    const fs::path p(path_);
    temp_ = (p.parent_path() / ("." + p.filename().string().substr(0, kTempNameChars) + ".tmp.XXXXXX")).string();
    fd_ = ::mkostemp(temp_.data(), O_CLOEXEC);
    if (fd_ < 0) {
      const int error = errno;
      temp_.clear();
      if (error == ENOENT || error == ENOTDIR) {
        throw OutputError(path_, option_, "its folder " + p.parent_path().string() + " does not exist");
      }
      fail(error);
    }
    // A new file gets the usual permissions (0666 less the umask), a replaced one keeps its own.
    (void)::fchmod(fd_, exists ? (info.st_mode & 07777) : (0666 & ~processUmask()));
  }
  buffer_ = std::make_unique<Buffer>(fd_);
  stream_ = std::make_unique<std::ostream>(buffer_.get());
}

AtomicFile::~AtomicFile() {
  stream_.reset();
  if (fd_ >= 0) ::close(fd_);
  if (!published_ && !temp_.empty()) ::unlink(temp_.c_str());
}

void AtomicFile::fail(int error) const { throw OutputError(path_, option_, systemReason(error)); }

std::ostream& AtomicFile::stream() { return *stream_; }

void AtomicFile::finish() {
  if (finished_) return;
  stream_->flush();
  int error = buffer_->error();
  if (error == 0 && !*stream_) error = EIO;
  // A device (a terminal, /dev/null) cannot be synced; a file's data must be on the disk before
  // its name replaces the old one.
  if (error == 0 && !direct_ && ::fsync(fd_) != 0) error = errno;
  if (::close(fd_) != 0 && error == 0 && errno != EINTR) error = errno;
  fd_ = -1;
  if (error != 0) fail(error);
  finished_ = true;
}

void AtomicFile::publish() {
  finish();
  if (direct_ || published_) return;
  if (::rename(temp_.c_str(), path_.c_str()) != 0) fail(errno);
  published_ = true;
  syncFolder(fs::path(path_).parent_path());
}

void AtomicFile::commit() {
  finish();
  publish();
}

std::ostream& OutputSet::add(const std::string& path, const std::string& option) {
  files_.push_back(std::make_unique<AtomicFile>(path, option));
  return files_.back()->stream();
}

void OutputSet::commit() {
  for (const auto& f : files_) f->finish();
  for (const auto& f : files_) f->publish();
  for (const std::string& path : stale_) {
    if (::unlink(path.c_str()) != 0 && errno != ENOENT) throw OutputError(path, "", "cannot delete: " + systemReason(errno));
  }
  files_.clear();
  stale_.clear();
}

void writeFileAtomically(const std::string& path, const std::string& text, const std::string& option) {
  AtomicFile f(path, option);
  f.stream() << text;
  f.commit();
}

void createOutputFolder(const std::string& path, const std::string& option) {
  std::error_code ec;
  fs::create_directories(path, ec);
  if (ec) throw OutputError(path, option, "cannot make the folder: " + ec.message());
  if (!fs::is_directory(path, ec)) throw OutputError(path, option, "not a folder (a file is in the way)");
}

namespace {

/// std::cout's buffer once watchStandardOutput() has run: every write goes to C's stdout (so that
/// printf and std::cout keep their order, as with the standard synchronised buffer) and the
/// first failed write's errno is kept for the message at the end.
class StdoutBuffer final : public std::streambuf {
 public:
  [[nodiscard]] int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    const char ch = traits_type::to_char_type(c);
    return put(&ch, 1) == 1 ? c : traits_type::eof();
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override { return put(s, n); }
  int sync() override {
    errno = 0;
    return check(std::fflush(stdout) == 0) ? 0 : -1;
  }

 private:
  std::streamsize put(const char* s, std::streamsize n) {
    errno = 0;
    const std::size_t written = std::fwrite(s, 1, static_cast<std::size_t>(n), stdout);
    check(written == static_cast<std::size_t>(n));
    return static_cast<std::streamsize>(written);
  }
  bool check(bool ok) {
    if (!ok && error_ == 0) error_ = errno != 0 ? errno : EIO;
    return ok;
  }
  int error_ = 0;
};

StdoutBuffer& stdoutBuffer() {
  static StdoutBuffer buffer;
  return buffer;
}

}  // namespace

void watchStandardOutput() { std::cout.rdbuf(&stdoutBuffer()); }

void flushStandardOutput() {
  errno = 0;
  std::cout.flush();
  const bool flushed = std::fflush(stdout) == 0;
  const int error = stdoutBuffer().error() != 0 ? stdoutBuffer().error() : errno;
  if (flushed && std::cout.good() && !std::ferror(stdout) && stdoutBuffer().error() == 0) return;
  if (error == EPIPE) return;  // the reader has gone: nothing left to write to
  throw OutputError("standard output", "", error != 0 ? systemReason(error) : "a write failed");
}

}  // namespace skylane::maps
