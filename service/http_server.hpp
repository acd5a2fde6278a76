#pragma once
/// \file
/// \brief The HTTP/1.1 server of `skylane serve` (Boost.Beast over Asio, one thread): requests are
/// read asynchronously, so thousands of open event streams cost a socket and a buffer each, no
/// thread. Limits protect it from any client: the header size (431), the body size (413), the
/// time to send a request (slow clients are cut off), the number of connections; a request the
/// parser cannot read is answered 400 and the connection closed. Work from other threads (the
/// approval workers) comes in through post().

#include "service/http.hpp"

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

namespace skylane::service {

/// \brief What the server accepts.
struct HttpLimits {
  std::size_t header_bytes = 16 * 1024;
  std::size_t body_bytes = 16u << 20;
  std::chrono::seconds request_timeout{30};  ///< to send a whole request (header and body)
  std::chrono::seconds idle_timeout{120};    ///< a kept-alive connection with no request
  std::size_t max_connections = 10000;
};

/// \brief The server and its event loop.
class HttpServer {
 public:
  using Handler = std::function<HttpResponse(const HttpRequest&)>;
  /// \brief Listens on `host`:`port` (0: any free port).
  /// \throws std::runtime_error naming the address when it cannot listen.
  HttpServer(const std::string& host, unsigned short port, Handler handler, HttpLimits limits = {});
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// \brief The port listened on.
  [[nodiscard]] unsigned short port() const;
  /// \brief Runs the event loop on this thread until stop().
  void run();
  /// \brief Runs the handlers that are ready now, without waiting (a caller driving the service
  /// without run(): tests, the fuzz target).
  void poll();
  /// \brief Ends run() (thread-safe, async-signal-unsafe).
  void stop();
  /// \brief Runs `work` on the server's thread (thread-safe).
  void post(std::function<void()> work);
  /// \brief Runs `work` on the server's thread every `period` until stop().
  void every(std::chrono::milliseconds period, std::function<void()> work);
  /// \brief Open connections now.
  [[nodiscard]] std::size_t connections() const;

  struct Impl;  ///< the Asio side (http_server.cpp)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace skylane::service
