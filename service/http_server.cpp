#include "service/http_server.hpp"

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

#include <nlohmann/json.hpp>

#include <cctype>
#include <optional>
#include <stdexcept>

namespace skylane::service {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = net::ip::tcp;

// --- the types of http.hpp ---------------------------------------------------------------

bool EventStream::push(const std::string& text) {
  if (closed_) return false;
  if (pending_.size() + text.size() > max_pending) {
    close();
    return false;
  }
  pending_ += text;
  if (wake) wake();
  return true;
}

void EventStream::close() {
  if (closed_) return;
  closed_ = true;
  if (wake) wake();
  if (on_close) std::exchange(on_close, nullptr)();
}

HttpResponse errorResponse(int status, const std::string& message) {
  HttpResponse r;
  r.status = status;
  r.body = nlohmann::json{{"error", message}}.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  return r;
}

HttpResponse jsonResponse(int status, const std::string& json_text) {
  HttpResponse r;
  r.status = status;
  r.body = json_text;
  return r;
}

const char* reasonPhrase(int status) {
  const auto s = http::obsolete_reason(static_cast<http::status>(status));
  return s.empty() ? "Unknown" : s.data();
}

namespace {

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// Percent-decoding ('+' is a space in a query); a bad escape is kept as written.
std::string percentDecode(std::string_view s, bool query) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && hexValue(s[i + 1]) >= 0 && hexValue(s[i + 2]) >= 0) {
      out += static_cast<char>(hexValue(s[i + 1]) * 16 + hexValue(s[i + 2]));
      i += 2;
    } else {
      out += (query && s[i] == '+') ? ' ' : s[i];
    }
  }
  return out;
}

std::map<std::string, std::string> parseQuery(std::string_view q) {
  std::map<std::string, std::string> out;
  while (!q.empty()) {
    const std::size_t amp = q.find('&');
    const std::string_view part = q.substr(0, amp);
    const std::size_t eq = part.find('=');
    if (!part.empty()) {
      out[percentDecode(part.substr(0, eq), true)] =
          eq == std::string_view::npos ? std::string() : percentDecode(part.substr(eq + 1), true);
    }
    if (amp == std::string_view::npos) break;
    q.remove_prefix(amp + 1);
  }
  return out;
}

HttpRequest toRequest(http::request<http::string_body>&& r, const std::string& peer) {
  HttpRequest req;
  req.method = std::string(r.method_string());
  req.target = std::string(r.target());
  const std::string_view t(req.target);
  const std::size_t qm = t.find('?');
  req.path = percentDecode(t.substr(0, qm), false);
  if (qm != std::string_view::npos) req.query = parseQuery(t.substr(qm + 1));
  for (const auto& f : r) {
    std::string name(f.name_string());
    for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    req.headers[name] = std::string(f.value());
  }
  req.body = std::move(r.body());
  req.peer = peer;
  return req;
}

/// The status for a request the parser refused.
std::optional<int> parseFailureStatus(const beast::error_code& ec) {
  if (ec == http::error::body_limit) return 413;
  if (ec == http::error::header_limit) return 431;
  if (ec == http::error::end_of_stream || ec == http::error::partial_message) return std::nullopt;  // the client left
  if (ec.category() == http::make_error_code(http::error::bad_method).category()) return 400;  // any other parse error
  return std::nullopt;  // a timeout, a reset: nothing to answer
}

}  // namespace

// --- the server ----------------------------------------------------------------------------

struct HttpServer::Impl {
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  Handler handler;
  HttpLimits limits;
  std::size_t connections = 0;
  std::vector<std::unique_ptr<net::steady_timer>> timers;
  void accept();
  void tick(net::steady_timer& timer, std::chrono::milliseconds period, const std::function<void()>& work);
};

namespace {

/// One client connection: requests read one at a time (keep-alive), a response each, or an
/// event stream that lasts until either side closes it.
class Connection : public std::enable_shared_from_this<Connection> {
 public:
  Connection(tcp::socket socket, HttpServer::Impl& server) : stream_(std::move(socket)), server_(server) {
    ++server_.connections;
    beast::error_code ec;
    const auto ep = stream_.socket().remote_endpoint(ec);
    if (!ec) peer_ = ep.address().to_string();
  }
  ~Connection() { --server_.connections; }
  void start() { readHeader(); }

 private:
  void readHeader();
  void onHeader(beast::error_code ec);
  void readBody();
  void onBody(beast::error_code ec);
  void respond(HttpResponse res, bool keep_alive);
  void refuse(int status, const std::string& message);
  void startStream(HttpResponse res);
  void writeStream();
  void watchClose();
  void close();

  beast::tcp_stream stream_;
  HttpServer::Impl& server_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::string peer_;
  std::shared_ptr<EventStream> events_;
  std::string out_;  ///< the text being written
  bool writing_ = false;
  char probe_[256];
};

void Connection::readHeader() {
  parser_.emplace();
  parser_->header_limit(static_cast<std::uint32_t>(server_.limits.header_bytes));
  parser_->body_limit(server_.limits.body_bytes);
  stream_.expires_after(server_.limits.request_timeout);
  http::async_read_header(stream_, buffer_, *parser_,
                          [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onHeader(ec); });
}

void Connection::onHeader(beast::error_code ec) {
  if (ec) {
    const auto status = parseFailureStatus(ec);
    if (status) return refuse(*status, *status == 413 ? "the request body is larger than the limit of " +
                                                           std::to_string(server_.limits.body_bytes) + " bytes"
                                                     : "the request could not be read as HTTP/1.1 (" + ec.message() + ")");
    return close();
  }
  // A client that waits for "100 Continue" before sending its body (curl does) gets it now.
  if (beast::iequals(parser_->get()[http::field::expect], "100-continue")) {
    auto text = std::make_shared<std::string>("HTTP/1.1 100 Continue\r\n\r\n");
    net::async_write(stream_, net::buffer(*text), [self = shared_from_this(), text](beast::error_code e, std::size_t) {
      if (e) return self->close();
      self->readBody();
    });
    return;
  }
  readBody();
}

void Connection::readBody() {
  http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onBody(ec); });
}

void Connection::onBody(beast::error_code ec) {
  if (ec) {
    const auto status = parseFailureStatus(ec);
    if (status) return refuse(*status, "the request body could not be read (" + ec.message() + ")");
    return close();
  }
  http::request<http::string_body> msg = parser_->release();
  const bool keep_alive = msg.keep_alive();
  HttpResponse res;
  try {
    res = server_.handler(toRequest(std::move(msg), peer_));
  } catch (const std::exception& e) {
    res = errorResponse(500, std::string("internal error: ") + e.what());
  }
  if (res.stream) return startStream(std::move(res));
  respond(std::move(res), keep_alive);
}

void Connection::respond(HttpResponse r, bool keep_alive) {
  auto res = std::make_shared<http::response<http::string_body>>(static_cast<http::status>(r.status), 11);
  res->set(http::field::server, "skylane");
  res->set(http::field::content_type, r.content_type);
  for (const auto& [k, v] : r.headers) res->set(k, v);
  res->body() = std::move(r.body);
  res->keep_alive(keep_alive);
  res->prepare_payload();
  stream_.expires_after(server_.limits.request_timeout);
  http::async_write(stream_, *res, [self = shared_from_this(), res, keep_alive](beast::error_code ec, std::size_t) {
    if (ec || !keep_alive) return self->close();
    self->stream_.expires_after(self->server_.limits.idle_timeout);
    self->readHeader();
  });
}

void Connection::refuse(int status, const std::string& message) { respond(errorResponse(status, message), false); }

void Connection::startStream(HttpResponse res) {
  events_ = res.stream;
  // The body runs until the connection closes (no length, no chunking): any HTTP/1.1 reader takes it.
  out_ = "HTTP/1.1 " + std::to_string(res.status) + " " + reasonPhrase(res.status) + "\r\nServer: skylane\r\nContent-Type: " +
         res.content_type + "\r\nCache-Control: no-cache\r\nConnection: close\r\nX-Accel-Buffering: no\r\n";
  for (const auto& [k, v] : res.headers) out_ += k + ": " + v + "\r\n";
  out_ += "\r\n" + res.body;
  stream_.expires_never();
  std::weak_ptr<Connection> weak = shared_from_this();
  events_->wake = [weak] {
    if (auto self = weak.lock()) self->writeStream();
  };
  writing_ = true;
  net::async_write(stream_, net::buffer(out_), [self = shared_from_this()](beast::error_code ec, std::size_t) {
    self->writing_ = false;
    if (ec) return self->close();
    self->writeStream();
  });
  watchClose();
}

void Connection::writeStream() {
  if (writing_ || !events_) return;
  if (!events_->hasPending()) {
    if (events_->closed()) close();
    return;
  }
  out_ = events_->take();
  writing_ = true;
  net::async_write(stream_, net::buffer(out_), [self = shared_from_this()](beast::error_code ec, std::size_t) {
    self->writing_ = false;
    if (ec) return self->close();
    self->writeStream();
  });
}

void Connection::watchClose() {
  // A reader of an event stream sends nothing more: a read that ends means it has gone.
  stream_.socket().async_read_some(net::buffer(probe_), [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) return self->close();
    self->watchClose();
  });
}

void Connection::close() {
  if (events_) {
    events_->wake = nullptr;
    std::exchange(events_, nullptr)->close();
  }
  beast::error_code ec;
  stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
  stream_.socket().close(ec);
}

}  // namespace

void HttpServer::Impl::accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted) return;
    if (!ec) {
      if (connections >= limits.max_connections) {
        beast::error_code ignored;
        socket.close(ignored);  // over the limit: refused at once
      } else {
        std::make_shared<Connection>(std::move(socket), *this)->start();
      }
    }
    accept();
  });
}

void HttpServer::Impl::tick(net::steady_timer& timer, std::chrono::milliseconds period, const std::function<void()>& work) {
  timer.expires_after(period);
  timer.async_wait([this, &timer, period, work](beast::error_code ec) {
    if (ec) return;
    work();
    tick(timer, period, work);
  });
}

HttpServer::HttpServer(const std::string& host, unsigned short port, Handler handler, HttpLimits limits)
    : impl_(std::make_unique<Impl>()) {
  impl_->handler = std::move(handler);
  impl_->limits = limits;
  beast::error_code ec;
  const auto address = net::ip::make_address(host, ec);
  if (ec) throw std::runtime_error("--host " + host + ": not an IP address");
  const tcp::endpoint ep(address, port);
  impl_->acceptor.open(ep.protocol(), ec);
  if (!ec) impl_->acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) impl_->acceptor.bind(ep, ec);
  if (!ec) impl_->acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) throw std::runtime_error("cannot listen on " + host + ":" + std::to_string(port) + ": " + ec.message());
  impl_->accept();
}

HttpServer::~HttpServer() = default;

unsigned short HttpServer::port() const { return impl_->acceptor.local_endpoint().port(); }

void HttpServer::run() { impl_->ioc.run(); }

void HttpServer::poll() {
  impl_->ioc.restart();
  impl_->ioc.poll();
}

void HttpServer::stop() { impl_->ioc.stop(); }

void HttpServer::post(std::function<void()> work) { net::post(impl_->ioc, std::move(work)); }

void HttpServer::every(std::chrono::milliseconds period, std::function<void()> work) {
  impl_->timers.push_back(std::make_unique<net::steady_timer>(impl_->ioc));
  impl_->tick(*impl_->timers.back(), period, work);
}

std::size_t HttpServer::connections() const { return impl_->connections; }

}  // namespace skylane::service
