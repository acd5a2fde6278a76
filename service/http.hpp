#pragma once
/// \file
/// \brief The HTTP requests and responses of `skylane serve`, free of the server library (Boost.Beast
/// stays inside service/http_server.cpp): what the routes see and return. An event stream
/// (Server-Sent Events) is a response whose body goes on for as long as the stream is open.

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace skylane::service {

/// \brief One request, read whole (the body is bounded by the server's limits).
struct HttpRequest {
  std::string method;  ///< "GET", "POST", …
  std::string target;  ///< as sent: path and query
  std::string path;    ///< percent-decoded path
  std::map<std::string, std::string> query;    ///< decoded query parameters
  std::map<std::string, std::string> headers;  ///< names in lower case
  std::string body;
  std::string peer;  ///< the client's address
  /// \brief A header's value, or empty.
  [[nodiscard]] std::string header(const std::string& lower_name) const {
    const auto it = headers.find(lower_name);
    return it == headers.end() ? std::string() : it->second;
  }
  /// \brief A query parameter's value, or empty.
  [[nodiscard]] std::string param(const std::string& name) const {
    const auto it = query.find(name);
    return it == query.end() ? std::string() : it->second;
  }
};

/// \brief The body of an open event stream: the service pushes text, the connection writes it.
/// Used on the server's one thread only.
class EventStream {
 public:
  /// \brief Appends text to send; false when the stream has closed or its reader is so far behind
  /// that `max_pending` bytes wait (the stream is then closed: the reader resumes with Last-Event-ID).
  bool push(const std::string& text);
  /// \brief Ends the stream.
  void close();
  [[nodiscard]] bool closed() const { return closed_; }
  /// \brief The connection's side: takes what waits to be sent.
  [[nodiscard]] std::string take() { return std::exchange(pending_, {}); }
  [[nodiscard]] bool hasPending() const { return !pending_.empty(); }
  /// \brief Called when text arrives or the stream closes (set by the connection).
  std::function<void()> wake;
  /// \brief Called once when the stream ends, from either side (set by the service).
  std::function<void()> on_close;
  std::size_t max_pending = 8u << 20;

 private:
  std::string pending_;
  bool closed_ = false;
};

/// \brief One response.
struct HttpResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  ///< extra headers
  std::shared_ptr<EventStream> stream;  ///< set: an event stream; `body` is its first text
};

/// \brief A JSON error body: {"error": message}.
[[nodiscard]] HttpResponse errorResponse(int status, const std::string& message);
/// \brief A JSON body.
[[nodiscard]] HttpResponse jsonResponse(int status, const std::string& json_text);

/// \brief The standard reason phrase of a status code.
[[nodiscard]] const char* reasonPhrase(int status);

}  // namespace skylane::service
