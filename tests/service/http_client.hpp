#pragma once
/// \file
/// \brief A small blocking HTTP/1.1 client over a loopback socket, for the service tests and the
/// load generator: one request per call on a kept-alive connection (Content-Length bodies), and
/// an event-stream reader.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace skylane::test {

struct HttpReply {
  int status = 0;
  std::map<std::string, std::string> headers;  ///< lower-case names
  std::string body;
  [[nodiscard]] std::string header(const std::string& lower_name) const {
    const auto it = headers.find(lower_name);
    return it == headers.end() ? std::string() : it->second;
  }
};

/// \brief One connection to 127.0.0.1:port.
class HttpClient {
 public:
  explicit HttpClient(int port) : port_(port) {}
  ~HttpClient() { disconnect(); }
  HttpClient(const HttpClient&) = delete;
  HttpClient& operator=(const HttpClient&) = delete;

  /// \brief A request; `headers` as "Name: value" lines. Reconnects when the server closed.
  HttpReply request(const std::string& method, const std::string& target, const std::string& body = {},
                    const std::vector<std::string>& headers = {}) {
    for (int attempt = 0; attempt < 2; ++attempt) {
      if (fd_ < 0) connectNow();
      std::string req = method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n";
      for (const std::string& h : headers) req += h + "\r\n";
      if (!body.empty() || method == "POST" || method == "PUT") req += "Content-Length: " + std::to_string(body.size()) + "\r\n";
      req += "\r\n" + body;
      if (sendAll(req)) {
        HttpReply r;
        if (readReply(r)) return r;
      }
      disconnect();  // the server had closed a kept-alive connection: once more on a new one
    }
    throw std::runtime_error("no reply to " + method + " " + target);
  }
  /// \brief Sends raw bytes (malformed requests) and reads whatever comes back until close.
  std::string raw(const std::string& bytes, int timeout_ms = 5000) {
    disconnect();
    connectNow();
    sendAll(bytes);
    std::string out;
    char buf[4096];
    pollfd p{fd_, POLLIN, 0};
    while (poll(&p, 1, timeout_ms) > 0) {
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) break;
      out.append(buf, static_cast<std::size_t>(n));
    }
    disconnect();
    return out;
  }
  /// \brief Opens an event stream: sends the request and returns; read with readFor().
  void openStream(const std::string& target, const std::vector<std::string>& headers) {
    disconnect();
    connectNow();
    std::string req = "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n";
    for (const std::string& h : headers) req += h + "\r\n";
    sendAll(req + "\r\n");
  }
  /// \brief What the stream sent within `ms` (all of it so far is kept in streamed()).
  const std::string& readFor(int ms) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    char buf[65536];
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now()).count();
      if (left <= 0) break;
      pollfd p{fd_, POLLIN, 0};
      if (poll(&p, 1, static_cast<int>(left)) <= 0) break;
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) break;
      streamed_.append(buf, static_cast<std::size_t>(n));
    }
    return streamed_;
  }
  /// \brief Takes what the stream has sent so far without waiting.
  const std::string& readAvailable() {
    char buf[65536];
    for (;;) {
      pollfd p{fd_, POLLIN, 0};
      if (fd_ < 0 || poll(&p, 1, 0) <= 0) break;
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) break;
      streamed_.append(buf, static_cast<std::size_t>(n));
    }
    return streamed_;
  }
  /// \brief Reads until `needle` appears in the stream or `ms` pass; whether it did.
  bool waitFor(const std::string& needle, int ms) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    while (streamed_.find(needle) == std::string::npos && std::chrono::steady_clock::now() < end) readFor(10);
    return streamed_.find(needle) != std::string::npos;
  }
  [[nodiscard]] const std::string& streamed() const { return streamed_; }
  void disconnect() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    in_.clear();
  }

 private:
  void connectNow() {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(port_));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
      disconnect();
      throw std::runtime_error("cannot connect to 127.0.0.1:" + std::to_string(port_));
    }
    int one = 1;
    setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  }
  bool sendAll(const std::string& s) {
    for (std::size_t off = 0; off < s.size();) {
      const ssize_t n = ::send(fd_, s.data() + off, s.size() - off, MSG_NOSIGNAL);
      if (n <= 0) return false;
      off += static_cast<std::size_t>(n);
    }
    return true;
  }
  bool fill() {
    char buf[65536];
    const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
    if (n <= 0) return false;
    in_.append(buf, static_cast<std::size_t>(n));
    return true;
  }
  bool readReply(HttpReply& r) {
    std::size_t end;
    while ((end = in_.find("\r\n\r\n")) == std::string::npos) {
      if (!fill()) return false;
    }
    const std::string head = in_.substr(0, end);
    in_.erase(0, end + 4);
    r.status = std::stoi(head.substr(9, 3));
    std::size_t pos = head.find("\r\n");
    while (pos != std::string::npos && pos + 2 < head.size()) {
      const std::size_t next = head.find("\r\n", pos + 2);
      const std::string line = head.substr(pos + 2, next == std::string::npos ? std::string::npos : next - pos - 2);
      const std::size_t colon = line.find(':');
      std::string name = line.substr(0, colon);
      for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      r.headers[name] = line.substr(colon + 2);
      pos = next;
    }
    const auto cl = r.headers.find("content-length");
    if (cl == r.headers.end()) {  // until close
      while (fill()) {
      }
      r.body = std::exchange(in_, {});
      disconnect();
      return true;
    }
    const std::size_t n = std::stoul(cl->second);
    while (in_.size() < n) {
      if (!fill()) return false;
    }
    r.body = in_.substr(0, n);
    in_.erase(0, n);
    if (r.headers.count("connection") && r.headers["connection"] == "close") disconnect();
    return true;
  }
  int port_;
  int fd_ = -1;
  std::string in_;
  std::string streamed_;
};

}  // namespace skylane::test
