// UDP inputs count the datagrams the kernel drops (issue 23 item 5): a flood into a small
// receive buffer loses datagrams, and every datagram sent is either read or counted as dropped;
// a big buffer at a modest rate loses none; a buffer larger than the kernel allows is said.
#include "link/byte_link.hpp"
#include "maps/parse_error.hpp"
#include "planner/tracking/datagram_socket.hpp"
#include "planner/tracking/line_input.hpp"
#include "tests/service/child_process.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

namespace skylane::planner {
namespace {

using test::freeUdpPort;

/// Sends `n` datagrams of one line each ("datagram k" padded to `bytes`) to 127.0.0.1:port,
/// pausing `pause` after every `every` datagrams (every 0: flat out).
void sendDatagrams(int port, int n, std::size_t bytes, int every = 0, std::chrono::microseconds pause = {}) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  for (int k = 0; k < n; ++k) {
    std::string line = "datagram " + std::to_string(k);
    line.resize(bytes, ' ');
    line.back() = '\n';
    ASSERT_EQ(sendto(fd, line.data(), line.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to), static_cast<ssize_t>(line.size()));
    if (every > 0 && (k + 1) % every == 0) std::this_thread::sleep_for(pause);
  }
  close(fd);
}

/// Lines read until the input stays quiet for 300 ms.
int readUntilQuiet(LineInput& in) {
  int lines = 0;
  std::string line;
  while (in.next(line, 300) == LineInput::Status::kLine) ++lines;
  return lines;
}

int rmemMax() {
  int v = 0;
  std::ifstream("/proc/sys/net/core/rmem_max") >> v;
  return v;
}

TEST(DatagramInput, AFloodIntoASmallBufferIsCountedDatagramForDatagram) {
  // GIVEN a UDP line input with the smallest buffer the option allows
  const int port = freeUdpPort();
  const auto in = openLineInput("udp://127.0.0.1:" + std::to_string(port), DatagramOptions{1024, {}});
  ASSERT_EQ(in->droppedDatagrams(), std::optional<std::uint64_t>(0));
  // WHEN 3000 datagrams arrive before it reads any
  constexpr int kSent = 3000;
  sendDatagrams(port, kSent, 200);
  const int read = readUntilQuiet(*in);
  // THEN most were dropped, and every one is either read or counted
  const std::uint64_t dropped = *in->droppedDatagrams();
  EXPECT_GT(dropped, 0u);
  EXPECT_GT(read, 0);
  EXPECT_EQ(read + static_cast<int>(dropped), kSent) << read << " read, " << dropped << " dropped";
  // AND a second burst adds to the count
  sendDatagrams(port, kSent, 200);
  const int again = readUntilQuiet(*in);
  EXPECT_EQ(read + again + static_cast<int>(*in->droppedDatagrams()), 2 * kSent);
}

TEST(DatagramInput, ABigBufferAtAModestRateDropsNothing) {
  const int port = freeUdpPort();
  const int buffer = std::min(4 << 20, rmemMax());
  const auto in = openLineInput("udp://127.0.0.1:" + std::to_string(port), DatagramOptions{buffer, {}});
  // 2000 datagrams, 200 at a time with a pause, read after they were all sent
  constexpr int kSent = 2000;
  sendDatagrams(port, kSent, 200, 200, std::chrono::microseconds(2000));
  EXPECT_EQ(readUntilQuiet(*in), kSent);
  EXPECT_EQ(in->droppedDatagrams(), std::optional<std::uint64_t>(0));
}

TEST(DatagramInput, ALinkOverUdpCountsItsDropsToo) {
  const int port = freeUdpPort();
  const auto link = link::openByteLink("udp://127.0.0.1:" + std::to_string(port), 57600, DatagramOptions{1024, {}});
  constexpr int kSent = 2000;
  sendDatagrams(port, kSent, 100);
  int read = 0;
  std::vector<std::uint8_t> bytes;
  while (link->read(bytes, 300) == link::ByteLink::Status::kData) ++read;  // one datagram per read
  EXPECT_GT(*link->droppedDatagrams(), 0u);
  EXPECT_EQ(read + static_cast<int>(*link->droppedDatagrams()), kSent);
}

TEST(DatagramInput, ABufferLargerThanTheKernelAllowsIsSaidAndAnOutOfRangeOneNamesTheOption) {
  const int port = freeUdpPort();
  std::string said;
  DatagramOptions o{kMaxReceiveBufferBytes, [&](const std::string& m) { said = m; }};
  const DatagramSocket s("127.0.0.1:" + std::to_string(port), "udp://x", o);
  EXPECT_EQ(s.receiveBufferBytes(), rmemMax());  // capped at net.core.rmem_max (SO_RCVBUF's value halved)
  EXPECT_NE(said.find("granted " + std::to_string(rmemMax())), std::string::npos) << said;
  EXPECT_NE(said.find("--udp-buffer 1073741824"), std::string::npos) << said;
  const std::string m = test::messageOf<maps::ParseError>([&] { (void)DatagramSocket("127.0.0.1:" + std::to_string(port), "udp://x", {100, {}}); });
  EXPECT_NE(m.find("--udp-buffer"), std::string::npos) << m;
  EXPECT_NE(m.find("100"), std::string::npos) << m;
  EXPECT_NE(m.find("[1024, 1073741824]"), std::string::npos) << m;
  // A file is no datagram input: nothing to count.
  EXPECT_FALSE(openLineInput("/dev/null")->droppedDatagrams().has_value());
}

}  // namespace
}  // namespace skylane::planner
