#pragma once
/// \file
/// \brief A bound UDP socket that counts the datagrams the kernel dropped for it — the transport
/// under every `udp://` input (JSON lines, NMEA, MAVLink, UBX; `skylane track` and `skylane serve`).
///
/// A datagram that arrives while the socket's receive buffer is full is thrown away by the kernel
/// and the sender is not told. Linux counts these drops per socket (`sk_drops`); with the socket
/// option SO_RXQ_OVFL set, each datagram read with recvmsg() carries that counter, as it stood
/// when the datagram was queued, in its ancillary data (socket(7), "SO_RXQ_OVFL"). Drops after the
/// last datagram read are seen by asking the kernel for the socket's memory information
/// (SO_MEMINFO, the SK_MEMINFO_DROPS entry: the same counter, now) when the input is quiet or a
/// caller asks. The counter is 32 bits wide and wraps; it is widened here to 64 bits.
///
/// The receive buffer can be sized (SO_RCVBUF). Linux doubles the value asked for (its own
/// bookkeeping) and caps the request at net.core.rmem_max; `receiveBufferBytes()` is the usable
/// half of what the kernel granted, so a caller can say when it got less than it asked for.

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

struct sockaddr_in;

namespace skylane::planner {

/// \brief Options of a UDP input.
struct DatagramOptions {
  /// The receive buffer asked for [bytes]; 0: the system default (net.core.rmem_default).
  int receive_buffer_bytes = 0;
  /// Told, in one line, when the kernel granted a smaller buffer than asked for (may be empty).
  std::function<void(const std::string&)> log;
};

/// \brief The smallest and largest receive buffer an option may ask for [bytes]: below a few kB
/// not even one large datagram fits; above 1 GiB is a typo.
constexpr int kMinReceiveBufferBytes = 1024;
constexpr int kMaxReceiveBufferBytes = 1 << 30;

/// \brief A UDP socket bound to IPv4:PORT with the kernel's drop counter.
class DatagramSocket {
 public:
  /// \param hostport "IPv4:PORT"
  /// \param input the input's name in errors ("udp://…")
  /// \throws maps::ParseError naming --input (a bad address, a port that cannot be bound) or
  /// --udp-buffer (a size outside [kMinReceiveBufferBytes, kMaxReceiveBufferBytes]).
  DatagramSocket(const std::string& hostport, const std::string& input, const DatagramOptions& options);
  ~DatagramSocket();
  DatagramSocket(const DatagramSocket&) = delete;
  DatagramSocket& operator=(const DatagramSocket&) = delete;

  [[nodiscard]] int fd() const { return fd_; }
  /// \brief One datagram into `buffer` (recvmsg; the sender's address into `from` when not
  /// null); the drop counter is taken from its ancillary data. Returns recvmsg's result.
  ssize_t receive(void* buffer, std::size_t capacity, sockaddr_in* from);
  /// \brief Asks the kernel for the drop counter now (SO_MEMINFO): drops after the last
  /// datagram read.
  void refreshDrops();
  /// \brief Datagrams the kernel dropped for this socket since it was bound.
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }
  /// \brief The usable receive buffer the kernel granted [bytes] (half of SO_RCVBUF's value).
  [[nodiscard]] int receiveBufferBytes() const { return granted_bytes_; }

 private:
  /// Widens the kernel's 32-bit counter (it only grows, modulo 2³²).
  void takeCounter(std::uint32_t counter);

  int fd_ = -1;
  std::uint32_t last_counter_ = 0;
  std::uint64_t dropped_ = 0;
  int granted_bytes_ = 0;
};

}  // namespace skylane::planner
