// The station's HTTP server (http_server.hpp) on Boost.Beast: one I/O thread, every operation
// asynchronous, one Session per connection, the send queue of an event stream reduced to one
// message in flight (the EventStream is a mailbox: what is new replaces what was not sent).
#include "piezobench/web/http_server.hpp"

#include <fmt/format.h>
#include <sys/random.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <nlohmann/json.hpp>
#include <thread>

#include "piezobench/core/error.hpp"

namespace piezobench::web {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

HttpResponse json_response(int status, const std::string& json_text) { return {status, "application/json", json_text, {}}; }

namespace {

// {"error": message}. A message may quote the client's bytes (a path, a Host header) that are not
// UTF-8: they are replaced (U+FFFD) rather than thrown on, which on the server's thread would end
// the process (fuzz/regression/http_request/not_utf8_*).
std::string error_json(const std::string& message) {
  return nlohmann::json{{"error", message}}.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

HttpResponse error_response(int status, const std::string& message) { return json_response(status, error_json(message)); }

std::string random_token() {
  unsigned char bytes[16];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n <= 0) throw InputError("web", "token", "random bytes from getrandom()", "an error");
    got += static_cast<std::size_t>(n);
  }
  std::string out;
  for (unsigned char b : bytes) out += fmt::format("{:02x}", b);
  return out;
}

bool is_loopback_address(const std::string& address) {
  beast::error_code ec;
  const asio::ip::address a = asio::ip::make_address(address, ec);
  return !ec && a.is_loopback();
}

void HttpServerOptions::validate() const {
  const auto positive = [](double x, const char* field) {
    if (!(x > 0.0) || !std::isfinite(x)) throw InputError("web", field, "a finite number > 0", fmt::format("{}", x));
  };
  positive(request_timeout_s, "request_timeout_s");
  positive(stream_period_s, "stream_period_s");
  positive(stream_bytes_per_s, "stream_bytes_per_s");
  positive(write_timeout_s, "write_timeout_s");
  if (max_connections < 1 || max_streams < 1 || max_streams > max_connections) {
    throw InputError("web", "max_streams", "1 <= max_streams <= max_connections", fmt::format("{} and {}", max_streams, max_connections));
  }
  if (operator_token.size() < 16) throw InputError("web", "operator_token", "a token of at least 16 characters", "a shorter one");
  if (!view_token.empty() && view_token.size() < 16) throw InputError("web", "view_token", "a token of at least 16 characters", "a shorter one");
}

namespace {

bool equal_constant_time(const std::string& a, const std::string& b) {
  if (a.size() != b.size() || a.empty()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Percent-decoding; nothing when an escape is malformed or decodes to a NUL.
std::optional<std::string> percent_decode(std::string_view s, bool plus_is_space) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%') {
      if (i + 2 >= s.size()) return std::nullopt;
      const int hi = hex_digit(s[i + 1]), lo = hex_digit(s[i + 2]);
      if (hi < 0 || lo < 0 || (hi == 0 && lo == 0)) return std::nullopt;
      out += static_cast<char>(hi * 16 + lo);
      i += 2;
    } else if (plus_is_space && s[i] == '+') {
      out += ' ';
    } else {
      out += s[i];
    }
  }
  return out;
}

// A path the site may see: absolute, no "." or ".." segment, no backslash or control character.
bool acceptable_path(const std::string& path) {
  if (path.empty() || path.front() != '/' || path.size() > 1024) return false;
  for (char c : path) {
    if (static_cast<unsigned char>(c) < 0x20 || c == '\\' || c == 0x7f) return false;
  }
  std::size_t start = 1;
  while (start <= path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string_view seg(path.data() + start, end - start);
    if (seg == "." || seg == "..") return false;
    start = end + 1;
  }
  return true;
}

std::string reason_phrase(int status) { return std::string(http::obsolete_reason(static_cast<http::status>(status))); }

// A complete answer written on a raw socket, then closed (refusals before any parsing).
std::string canned_response(int status, const std::string& message, const std::string& extra_headers = "") {
  const std::string body = error_json(message);
  return fmt::format("HTTP/1.1 {} {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n{}\r\n{}", status,
                     reason_phrase(status), body.size(), extra_headers, body);
}

// The rules every request meets before the Site sees it: the options, whether the server listens on
// a loopback address and the Host headers it then accepts (empty: any).
struct RequestRules {
  const HttpServerOptions& opt;
  bool loopback = true;
  std::vector<std::string> hosts;
};

// The Host headers a server on `address`:`port` accepts (loopback: its own names; otherwise any,
// the token guards it).
std::vector<std::string> accepted_hosts(const asio::ip::address& address, const std::string& literal, unsigned short port) {
  if (!address.is_loopback()) return {};
  const std::string p = std::to_string(port);
  const std::string name = address.is_v6() ? "[" + literal + "]" : literal;
  return {name + ":" + p, "localhost:" + p, "127.0.0.1:" + p, "[::1]:" + p};
}

using Parser = http::request_parser<http::string_body>;

// A parser of one request with the options' limits; the read buffer that goes with it.
void limit(Parser& parser, const HttpServerOptions& o) {
  parser.header_limit(static_cast<std::uint32_t>(o.max_header_bytes));
  parser.body_limit(o.max_body_bytes);
}
std::size_t read_buffer_bytes(const HttpServerOptions& o) { return o.max_header_bytes + o.max_body_bytes; }

// The answer to a read that failed: nothing when the connection is just closed (the client left,
// or timed out), else the refusal.
std::optional<HttpResponse> read_refusal(beast::error_code ec) {
  if (ec == http::error::end_of_stream || ec == beast::error::timeout || ec == asio::error::operation_aborted ||
      ec == asio::error::connection_reset || ec == asio::error::eof) {
    return std::nullopt;
  }
  if (ec == http::error::header_limit || ec == http::error::buffer_overflow) return error_response(431, "request line and headers too large");
  if (ec == http::error::body_limit) return error_response(413, "request body too large");
  return error_response(400, "malformed request: " + ec.message());
}

// What the server does with a request it has read.
struct Handled {
  HttpResponse response;
  std::unique_ptr<EventStream> stream;  // set: the site's event stream, sent instead of `response`
  bool refused = false;                 // answered by the server's rules; the site's handle() never saw it
  bool keep_alive = false;              // false: the connection closes after the answer
  bool head = false;                    // HEAD: the answer's headers without its body
};

// The checks of the path, query, Host, Origin and tokens (http_server.hpp); fills `out` or says why not.
bool check_security(const RequestRules& s, const http::request<http::string_body>& req, HttpRequest& out, int& status, std::string& why) {
  const std::string target(req.target());
  const std::size_t q = target.find('?');
  const auto path = percent_decode(std::string_view(target).substr(0, q), false);
  if (!path || !acceptable_path(*path)) {
    status = 400, why = "a path of the station's pages (no '..', no control characters)";
    return false;
  }
  out.path = *path;
  std::string token;
  if (q != std::string::npos) {
    std::string_view rest = std::string_view(target).substr(q + 1);
    while (!rest.empty()) {
      const std::size_t amp = std::min(rest.find('&'), rest.size());
      const std::string_view pair = rest.substr(0, amp);
      const std::size_t eq = std::min(pair.find('='), pair.size());
      const auto key = percent_decode(pair.substr(0, eq), true);
      const auto value = percent_decode(eq < pair.size() ? pair.substr(eq + 1) : std::string_view(), true);
      if (!key || !value) {
        status = 400, why = "a well-formed query";
        return false;
      }
      if (*key == "token") token = *value;
      else out.query[*key] = *value;
      rest = amp < rest.size() ? rest.substr(amp + 1) : std::string_view();
    }
  }
  const std::string host(req[http::field::host]);
  if (host.empty()) {
    status = 400, why = "a Host header";
    return false;
  }
  if (!s.hosts.empty() && std::find(s.hosts.begin(), s.hosts.end(), host) == s.hosts.end()) {
    status = 421, why = "the station's own host name (" + s.hosts.front() + "), not '" + host + "'";
    return false;
  }
  const std::string origin(req[http::field::origin]);
  if (!origin.empty() && origin != "http://" + host) {
    status = 403, why = "a request from the station's own page, not from " + origin;
    return false;
  }
  const std::string authorization(req[http::field::authorization]);
  if (authorization.rfind("Bearer ", 0) == 0) token = authorization.substr(7);
  out.operator_rights = equal_constant_time(token, s.opt.operator_token);
  const bool viewer = out.operator_rights || equal_constant_time(token, s.opt.view_token);
  if (!s.loopback && !viewer) {
    status = 401, why = "the station's token (printed when it started)";
    return false;
  }
  if (req.method() == http::verb::post && !out.operator_rights) {
    status = 403, why = "the operator token to answer or act";
    return false;
  }
  return true;
}

Handled refusal(int status, const std::string& message) { return {error_response(status, message), nullptr, true, false, false}; }

// One request read in full, with `open_streams` event streams open: the rules, then the site.
Handled handle_request(const RequestRules& rules, Site& site, const http::request<http::string_body>& req, std::size_t open_streams,
                       HttpRequest* seen) {
  const http::verb m = req.method();
  if (m != http::verb::get && m != http::verb::head && m != http::verb::post) return refusal(405, "GET, HEAD or POST");
  HttpRequest r;
  r.method = std::string(req.method_string());
  int status = 0;
  std::string why;
  if (!check_security(rules, req, r, status, why)) return refusal(status, "expected " + why);
  if (m == http::verb::post && !site.accepts_post(r.path)) return refusal(405, "GET on " + r.path);
  r.body = req.body();
  if (seen != nullptr) *seen = r;
  if (m == http::verb::get) {
    if (std::unique_ptr<EventStream> events = site.open_stream(r)) {
      if (open_streams >= rules.opt.max_streams) {
        Handled busy = refusal(503, fmt::format("at most {} pages may follow the station at once", rules.opt.max_streams));
        busy.response.headers.emplace_back("Retry-After", "5");
        return busy;
      }
      return {{}, std::move(events), false, false, false};
    }
  }
  return {site.handle(r), nullptr, false, req.keep_alive(), m == http::verb::head};
}

// The client's bytes as a socket that has them all, then end of file (exchange_request).
class BytesStream {
 public:
  explicit BytesStream(std::string_view bytes) : rest_(bytes) {}
  template <class Buffers>
  std::size_t read_some(const Buffers& buffers, beast::error_code& ec) {
    if (rest_.empty()) {
      ec = asio::error::eof;
      return 0;
    }
    ec = {};
    const std::size_t n = asio::buffer_copy(buffers, asio::buffer(rest_.data(), rest_.size()));
    rest_.remove_prefix(n);
    return n;
  }
  template <class Buffers>
  std::size_t read_some(const Buffers& buffers) {
    beast::error_code ec;
    const std::size_t n = read_some(buffers, ec);
    if (ec) throw beast::system_error(ec);
    return n;
  }

 private:
  std::string_view rest_;
};

}  // namespace

HttpExchange exchange_request(const HttpServerOptions& options, Site& site, std::string_view bytes) {
  options.validate();
  beast::error_code ec;
  const asio::ip::address address = asio::ip::make_address(options.address, ec);
  if (ec) throw InputError("web", "address", "an IP address", "'" + options.address + "'");
  const RequestRules rules{options, address.is_loopback(), accepted_hosts(address, options.address, options.port)};
  BytesStream stream(bytes);
  beast::flat_buffer buffer(read_buffer_bytes(options));
  Parser parser;
  limit(parser, options);
  http::read(stream, buffer, parser, ec);
  HttpExchange out;
  if (ec) {
    const std::optional<HttpResponse> refused = read_refusal(ec);
    if (refused) out.outcome = HttpExchange::Outcome::kAnswered, out.response = *refused;
    return out;
  }
  HttpRequest seen;
  Handled h = handle_request(rules, site, parser.get(), 0, &seen);
  out.outcome = h.stream ? HttpExchange::Outcome::kStream : HttpExchange::Outcome::kAnswered;
  out.response = std::move(h.response);
  out.by_site = !h.refused;
  out.keep_alive = h.keep_alive;
  if (out.by_site) out.request = std::move(seen);
  return out;
}

struct HttpServer::Impl {
  // Counters first: Sessions destroyed with the io_context (below) still decrement them.
  std::atomic<std::uint64_t> accepted{0}, refused_over_cap{0}, requests{0}, refused_requests{0}, streams_opened{0}, stream_bytes{0},
      streams_dropped_slow{0};
  std::atomic<std::size_t> connections{0}, streams{0};
  const HttpServerOptions& opt;
  Site& site;
  RequestRules rules;
  asio::io_context io{1};
  tcp::acceptor acceptor{io};
  asio::steady_timer accept_retry{io};
  std::thread thread;

  Impl(const HttpServerOptions& o, Site& s, RequestRules r) : opt(o), site(s), rules(std::move(r)) {}
  void accept();
  void refuse(tcp::socket socket, int status, const std::string& message, const std::string& headers = "");
};

namespace {

class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(HttpServer::Impl& server, tcp::socket socket)
      : s_(server), stream_(std::move(socket)), buffer_(read_buffer_bytes(server.opt)), timer_(s_.io) {
    ++s_.connections;
  }
  ~Session() {
    --s_.connections;
    if (events_) --s_.streams;
  }
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  void start() { read(); }

 private:
  void read();
  void on_read(beast::error_code ec);
  void handle();
  void write(HttpResponse r, bool keep_alive, bool head);
  void start_stream(std::unique_ptr<EventStream> events);
  void tick();
  void send_event(std::string text);
  void watch_close();
  void close() {
    closed_ = true;
    beast::error_code ec;
    timer_.cancel();
    stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
    stream_.close();
  }

  HttpServer::Impl& s_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<Parser> parser_;
  std::shared_ptr<http::response<http::string_body>> response_;
  asio::steady_timer timer_;
  std::unique_ptr<EventStream> events_;
  std::string out_;           // the event being written
  bool writing_ = false, closed_ = false;
  double budget_ = 0.0;       // bytes the stream may send now
  Clock::time_point last_tick_, last_write_;
  char discard_[256];
};

void Session::read() {
  parser_.emplace();
  limit(*parser_, s_.opt);
  stream_.expires_after(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s_.opt.request_timeout_s)));
  http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
}

void Session::on_read(beast::error_code ec) {
  if (!ec) return handle();
  std::optional<HttpResponse> refused = read_refusal(ec);
  if (!refused) return close();
  ++s_.refused_requests;
  write(std::move(*refused), false, false);
}

void Session::handle() {
  ++s_.requests;
  Handled h = handle_request(s_.rules, s_.site, parser_->get(), s_.streams.load(), nullptr);
  if (h.stream) return start_stream(std::move(h.stream));
  if (h.refused) ++s_.refused_requests;
  write(std::move(h.response), h.keep_alive, h.head);
}

void Session::write(HttpResponse r, bool keep_alive, bool head) {
  response_ = std::make_shared<http::response<http::string_body>>(static_cast<http::status>(r.status), 11);
  auto& res = *response_;
  res.set(http::field::server, "piezobench");
  res.set(http::field::content_type, r.content_type);
  res.set(http::field::cache_control, "no-store");
  res.set("X-Content-Type-Options", "nosniff");
  res.set("X-Frame-Options", "DENY");
  res.set("Referrer-Policy", "no-referrer");
  res.set("Content-Security-Policy",
          "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; connect-src 'self'; "
          "frame-ancestors 'none'; base-uri 'none'; form-action 'none'");
  for (auto& [k, v] : r.headers) res.set(k, v);
  res.body() = std::move(r.body);
  res.prepare_payload();
  if (head) res.body().clear();  // Content-Length stays the GET's
  res.keep_alive(keep_alive);
  http::async_write(stream_, res, [self = shared_from_this(), keep_alive](beast::error_code ec, std::size_t) {
    if (ec || !keep_alive) return self->close();
    self->read();
  });
}

void Session::start_stream(std::unique_ptr<EventStream> events) {
  events_ = std::move(events);
  ++s_.streams;
  ++s_.streams_opened;
  budget_ = s_.opt.stream_bytes_per_s;  // one second's worth at once, then the average rate
  last_tick_ = last_write_ = Clock::now();
  send_event(
      "HTTP/1.1 200 OK\r\nServer: piezobench\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n"
      "X-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\nretry: 2000\n\n");
  watch_close();
  tick();
}

// A client of a stream sends nothing more: a read that ends means it left (or misbehaves).
void Session::watch_close() {
  stream_.socket().async_read_some(asio::buffer(discard_), [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) return self->close();
    self->watch_close();
  });
}

void Session::tick() {
  if (closed_) return;
  const Clock::time_point now = Clock::now();
  budget_ = std::min(budget_ + s_.opt.stream_bytes_per_s * std::chrono::duration<double>(now - last_tick_).count(), s_.opt.stream_bytes_per_s);
  last_tick_ = now;
  if (writing_) {
    if (now - last_write_ > std::chrono::duration<double>(s_.opt.write_timeout_s)) {
      ++s_.streams_dropped_slow;
      return close();
    }
  } else if (budget_ > 0.0) {
    if (std::optional<std::string> message = events_->next()) {
      send_event("data: " + *message + "\n\n");
    } else if (now - last_write_ > std::chrono::seconds(15)) {
      send_event(": keep-alive\n\n");
    }
  }
  timer_.expires_after(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s_.opt.stream_period_s)));
  timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
    if (!ec) self->tick();
  });
}

void Session::send_event(std::string text) {
  out_ = std::move(text);
  budget_ -= static_cast<double>(out_.size());
  s_.stream_bytes += out_.size();
  writing_ = true;
  last_write_ = Clock::now();
  asio::async_write(stream_.socket(), asio::buffer(out_), [self = shared_from_this()](beast::error_code ec, std::size_t) {
    self->writing_ = false;
    if (ec) self->close();
  });
}

}  // namespace

void HttpServer::Impl::refuse(tcp::socket socket, int status, const std::string& message, const std::string& headers) {
  auto sock = std::make_shared<tcp::socket>(std::move(socket));
  auto text = std::make_shared<std::string>(canned_response(status, message, headers));
  asio::async_write(*sock, asio::buffer(*text), [sock, text](beast::error_code, std::size_t) {
    beast::error_code ec;
    sock->shutdown(tcp::socket::shutdown_both, ec);
    sock->close(ec);
  });
}

void HttpServer::Impl::accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted) return;
    if (ec) {
      // Out of file descriptors or a transient error: try again shortly rather than spin.
      accept_retry.expires_after(std::chrono::milliseconds(50));
      accept_retry.async_wait([this](beast::error_code e) {
        if (!e) accept();
      });
      return;
    }
    ++accepted;
    if (connections.load() >= opt.max_connections) {
      ++refused_over_cap;
      refuse(std::move(socket), 503, fmt::format("the station serves at most {} connections at once", opt.max_connections),
             "Retry-After: 5\r\n");
    } else {
      std::make_shared<Session>(*this, std::move(socket))->start();
    }
    accept();
  });
}

HttpServer::HttpServer(HttpServerOptions options, Site& site) : options_(std::move(options)), site_(site) { options_.validate(); }

HttpServer::~HttpServer() { stop(); }

void HttpServer::start() {
  if (impl_) return;
  beast::error_code ec;
  const asio::ip::address address = asio::ip::make_address(options_.address, ec);
  if (ec) throw InputError("--ui", "address", "an IP address (127.0.0.1, ::1, 0.0.0.0, ...)", "'" + options_.address + "'");
  loopback_ = address.is_loopback();
  if (!loopback_ && options_.view_token.empty()) {
    throw InputError("--ui", "token", "a token on an address other than the loopback one", "none for " + options_.address);
  }
  auto impl = std::make_unique<Impl>(options_, site_, RequestRules{options_, loopback_, {}});
  const tcp::endpoint endpoint(address, options_.port);
  impl->acceptor.open(endpoint.protocol(), ec);
  if (!ec) impl->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) impl->acceptor.bind(endpoint, ec);
  if (!ec) impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) throw InputError("--ui", "address", "an address and port this process can listen on",
                           fmt::format("{}:{} ({})", options_.address, options_.port, ec.message()));
  port_ = impl->acceptor.local_endpoint().port();
  impl->rules.hosts = accepted_hosts(address, options_.address, port_);
  impl->accept();
  Impl* raw = impl.get();
  impl->thread = std::thread([raw] { raw->io.run(); });
  impl_ = std::move(impl);
}

void HttpServer::stop() {
  if (!impl_) return;
  impl_->io.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
  impl_.reset();  // closes the acceptor and, with the io_context, every connection
}

HttpServerStats HttpServer::stats() const {
  HttpServerStats s;
  if (!impl_) return s;
  s.accepted = impl_->accepted, s.refused_over_cap = impl_->refused_over_cap, s.requests = impl_->requests;
  s.refused_requests = impl_->refused_requests, s.streams_opened = impl_->streams_opened, s.stream_bytes = impl_->stream_bytes;
  s.streams_dropped_slow = impl_->streams_dropped_slow;
  s.open_connections = impl_->connections, s.open_streams = impl_->streams;
  return s;
}

}  // namespace piezobench::web
