#pragma once
/// \file
/// \brief Bytes to and from a vehicle or a receiver: a UDP port (the vehicle's datagrams are
/// read, and replies go back to the address the last one came from), a serial device (raw
/// mode, 8N1, at a chosen baud rate), a file, a FIFO or stdin (read only). The transport under the
/// binary links (MAVLink, UBX).

#include "planner/tracking/datagram_socket.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace skylane::link {

/// \brief A byte stream with an optional way back.
class ByteLink {
 public:
  enum class Status { kData, kTimeout, kEnd };
  virtual ~ByteLink() = default;
  /// \brief Appends what arrives to `out`; kTimeout after `timeout_ms` of quiet on a live link,
  /// kEnd when a file or a closed stream ends.
  [[nodiscard]] virtual Status read(std::vector<std::uint8_t>& out, int timeout_ms) = 0;
  /// \brief Sends bytes back; false when the link has no way back (a file) or no peer yet (UDP
  /// before the first datagram).
  virtual bool write(const std::uint8_t* data, std::size_t n) = 0;
  [[nodiscard]] virtual bool live() const = 0;
  [[nodiscard]] virtual bool rereadable() const = 0;
  [[nodiscard]] virtual const std::string& name() const = 0;
  /// \brief A UDP link: the datagrams the kernel dropped before they could be read
  /// (planner/tracking/datagram_socket.hpp); empty for any other link.
  [[nodiscard]] virtual std::optional<std::uint64_t> droppedDatagrams() const { return std::nullopt; }
};

/// \brief Opens "udp://IPv4:PORT" (binds it, with `udp`'s receive buffer), "-" (stdin), a serial
/// device (a character device: raw mode at `baud`) or a file.
/// \throws maps::ParseError naming --input (or --baud, --udp-buffer) and what was expected.
[[nodiscard]] std::unique_ptr<ByteLink> openByteLink(const std::string& input, int baud = 57600,
                                                     const planner::DatagramOptions& udp = {});

}  // namespace skylane::link
