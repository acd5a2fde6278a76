#pragma once
/// \file
/// \brief Output files written whole or not at all. Each output is written to a temporary file
/// in its own folder; when the command has succeeded the file is flushed, synced to the disk
/// (fsync), checked, and renamed over the name asked for — rename(2) within one file system
/// replaces the name in one step, so a reader sees the old file or the whole new one, never a
/// part. A command stages all its outputs in one OutputSet and commits them together at the
/// end: a command that fails (bad input, a full disk) leaves earlier outputs as they were.
///
/// Written to a name that is not a regular file (a character device such as /dev/null or a
/// terminal, a FIFO), the output goes straight to it: nothing can be renamed over a device.
/// A process killed before its commit leaves a hidden `.NAME.tmp.XXXXXX` beside the output.

#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace skylane::maps {

/// \brief An output that could not be written: a missing folder, a folder in the way, no
/// permission, a full disk. The message names the file, the option that asked for it and the
/// system's reason, on one line.
class OutputError : public std::runtime_error {
 public:
  OutputError(const std::string& path, const std::string& option, const std::string& reason);
  /// \brief The output file (or "standard output").
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// \brief One output file: a stream to a temporary file beside `path`; commit() makes it `path`.
/// Destroyed without a commit, the temporary file is removed and `path` is untouched.
class AtomicFile {
 public:
  /// \brief Creates the temporary file (or opens a device or FIFO named `path`).
  /// \throws OutputError when the folder is missing or not writable, or `path` is a folder.
  AtomicFile(std::string path, std::string option);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// \brief Where the contents are written.
  [[nodiscard]] std::ostream& stream();
  /// \brief Flushes, syncs and closes the temporary file (step one of commit()).
  /// \throws OutputError naming the file when any write, the sync or the close failed.
  void finish();
  /// \brief Renames the finished temporary file over `path` (step two of commit()).
  /// \throws OutputError when the rename fails.
  void publish();
  /// \brief finish() and publish().
  void commit();
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  class Buffer;
  [[noreturn]] void fail(int error) const;
  std::string path_, option_, temp_;
  int fd_ = -1;
  bool direct_ = false;  ///< a device or FIFO: written in place
  bool finished_ = false, published_ = false;
  std::unique_ptr<Buffer> buffer_;
  std::unique_ptr<std::ostream> stream_;
};

/// \brief The outputs of one command, written to temporary files as the command goes and
/// committed together when it has succeeded.
class OutputSet {
 public:
  /// \brief A new output `path` (asked for by `option`, for messages); its stream.
  /// \throws OutputError when its folder is missing or not writable.
  std::ostream& add(const std::string& path, const std::string& option);
  /// \brief The stream of the `index`-th output added.
  [[nodiscard]] std::ostream& stream(std::size_t index) { return files_.at(index)->stream(); }
  /// \brief A file to delete at the commit (an output of an earlier run that this one does not write).
  void removeOnCommit(const std::string& path) { stale_.push_back(path); }
  /// \brief Finishes every output (all flushed, synced, checked), then renames them all into
  /// place and deletes the stale ones. A failed write throws before any name is replaced.
  /// \throws OutputError naming the file.
  void commit();
  [[nodiscard]] bool empty() const { return files_.empty(); }

 private:
  std::vector<std::unique_ptr<AtomicFile>> files_;
  std::vector<std::string> stale_;
};

/// \brief `text` written to `path` as one AtomicFile.
/// \throws OutputError naming the file.
void writeFileAtomically(const std::string& path, const std::string& text, const std::string& option);

/// \brief Creates a folder for outputs (and its parents).
/// \throws OutputError naming it when it cannot be made (a file in the way, no permission).
void createOutputFolder(const std::string& path, const std::string& option);

/// \brief Makes std::cout keep the reason (errno) of its first failed write, for the message of
/// flushStandardOutput(); called once at the start of a program.
void watchStandardOutput();

/// \brief Flushes standard output (the C++ and the C stream) at the end of a command.
/// \throws OutputError ("standard output") when a write to it failed (a full disk, /dev/full);
/// a closed pipe (EPIPE: the reader has gone) is not an error here.
void flushStandardOutput();

/// \brief The system's message for an errno value ("No space left on device").
[[nodiscard]] std::string systemReason(int error);

}  // namespace skylane::maps
