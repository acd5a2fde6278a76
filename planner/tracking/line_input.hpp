#pragma once
/// \file
/// \brief Lines of text from an input: a file, stdin, a FIFO, a UDP port (one or more lines per
/// datagram) or memory — the transport under the text fix sources (JSON lines, NMEA). A live
/// input (stdin, FIFO, socket, UDP) returns kTimeout when it is quiet, so that a stop request and
/// stale flights are noticed.

#include "planner/tracking/datagram_socket.hpp"

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace skylane::planner {

/// \brief The longest input line taken [bytes]: a fix is a few hundred bytes, with pseudoranges
/// a few kB.
constexpr std::size_t kMaxLineBytes = 1 << 20;

/// \brief A source of lines.
class LineInput {
 public:
  enum class Status { kLine, kTimeout, kEnd, kTooLong };
  virtual ~LineInput() = default;
  /// \brief The next line (without its line end); kTimeout after `timeout_ms` without one on a
  /// live input; kTooLong once for a line longer than kMaxLineBytes (the rest of it is dropped).
  [[nodiscard]] virtual Status next(std::string& line, int timeout_ms) = 0;
  /// \brief Whether the input can go quiet and come back (stdin, FIFO, socket, UDP).
  [[nodiscard]] virtual bool live() const = 0;
  /// \brief Whether the same lines can be read again after a restart (a regular file).
  [[nodiscard]] virtual bool rereadable() const = 0;
  /// \brief The input's name in messages and in the resume table ("-", a path, udp://…).
  [[nodiscard]] virtual const std::string& name() const = 0;
  /// \brief A UDP input: the datagrams the kernel dropped before they could be read, as of the
  /// last datagram read or quiet poll (datagram_socket.hpp); empty for any other input.
  [[nodiscard]] virtual std::optional<std::uint64_t> droppedDatagrams() const { return std::nullopt; }
};

/// \brief Opens "-" (stdin), "udp://IPv4:PORT" (binds the port, with `udp`'s receive buffer) or
/// a file path.
/// \throws maps::ParseError naming --input (an address, a readable file) or --udp-buffer.
[[nodiscard]] std::unique_ptr<LineInput> openLineInput(const std::string& input, const DatagramOptions& udp = {});

/// \brief Lines held in memory (tests, a service's request body). Not live, not rereadable.
class MemoryLineInput final : public LineInput {
 public:
  MemoryLineInput(std::string name, std::vector<std::string> lines) : name_(std::move(name)), lines_(lines.begin(), lines.end()) {}
  Status next(std::string& line, int timeout_ms) override;
  [[nodiscard]] bool live() const override { return false; }
  [[nodiscard]] bool rereadable() const override { return false; }
  [[nodiscard]] const std::string& name() const override { return name_; }

 private:
  std::string name_;
  std::deque<std::string> lines_;
};

}  // namespace skylane::planner
