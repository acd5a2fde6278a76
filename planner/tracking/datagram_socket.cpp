#include "planner/tracking/datagram_socket.hpp"

#include "maps/parse_error.hpp"

#include <arpa/inet.h>
#include <linux/sock_diag.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace skylane::planner {

namespace {

using maps::ParseError;

sockaddr_in parseAddress(const std::string& hostport, const std::string& input) {
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
  return addr;
}

}  // namespace

DatagramSocket::DatagramSocket(const std::string& hostport, const std::string& input, const DatagramOptions& options) {
  const int want = options.receive_buffer_bytes;
  if (want != 0 && (want < kMinReceiveBufferBytes || want > kMaxReceiveBufferBytes)) {
    throw ParseError("--udp-buffer", 0, "--udp-buffer", std::to_string(want), "bytes in [1024, 1073741824]");
  }
  sockaddr_in addr = parseAddress(hostport, input);
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  const int on = 1;
  // The buffer is sized before bind(): no datagram is queued against the default size first.
  const bool ok = fd_ >= 0 && setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on) == 0 &&
                  (want == 0 || setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &want, sizeof want) == 0) &&
                  bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
  if (!ok) {
    const std::string why = std::strerror(errno);
    if (fd_ >= 0) close(fd_);
    fd_ = -1;
    throw ParseError("--input", 0, "--input", input, "a UDP port to listen on (" + why + ")");
  }
  int granted = 0;
  socklen_t len = sizeof granted;
  if (getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &granted, &len) == 0) granted_bytes_ = granted / 2;  // socket(7): the kernel doubles it
  if (want != 0 && granted_bytes_ < want && options.log) {
    options.log(input + ": --udp-buffer " + std::to_string(want) + " bytes asked, the kernel granted " +
                std::to_string(granted_bytes_) + " (at most net.core.rmem_max; raise it with sysctl for more)");
  }
}

DatagramSocket::~DatagramSocket() {
  if (fd_ >= 0) close(fd_);
}

ssize_t DatagramSocket::receive(void* buffer, std::size_t capacity, sockaddr_in* from) {
  iovec iov{buffer, capacity};
  alignas(cmsghdr) std::array<char, CMSG_SPACE(sizeof(std::uint32_t))> control{};
  msghdr msg{};
  msg.msg_name = from;
  msg.msg_namelen = from ? sizeof(sockaddr_in) : 0;
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control.data();
  msg.msg_controllen = control.size();
  const ssize_t n = recvmsg(fd_, &msg, 0);
  if (n < 0) return n;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL && c->cmsg_len >= CMSG_LEN(sizeof(std::uint32_t))) {
      std::uint32_t counter = 0;
      std::memcpy(&counter, CMSG_DATA(c), sizeof counter);
      takeCounter(counter);
    }
  }
  return n;
}

void DatagramSocket::refreshDrops() {
  std::array<std::uint32_t, SK_MEMINFO_VARS> info{};
  socklen_t len = sizeof info;
  if (getsockopt(fd_, SOL_SOCKET, SO_MEMINFO, info.data(), &len) == 0 && len > SK_MEMINFO_DROPS * sizeof(std::uint32_t)) {
    takeCounter(info[SK_MEMINFO_DROPS]);
  }
}

void DatagramSocket::takeCounter(std::uint32_t counter) {
  // The kernel's counter only grows (unsigned 32-bit arithmetic takes a wrap); a datagram queued
  // before a refresh carries an older value, which adds nothing.
  const std::uint32_t step = counter - last_counter_;
  if (step == 0 || step > (1u << 31)) return;
  dropped_ += step;
  last_counter_ = counter;
}

}  // namespace skylane::planner
