#pragma once
// The station's HTTP server (docs/station.md, "The live page"): Boost.Beast on one I/O thread of
// its own, asynchronous throughout, so no client (slow, dead or hostile) holds a thread, and the
// code that feeds it (the phase runner, the signals) never waits on it.
//
// What it enforces before a Site sees a request (each refusal is a complete HTTP answer, then the
// connection is closed):
//  - sizes: request line and headers at most max_header_bytes (431), a body at most max_body_bytes
//    (413); a request not complete within request_timeout_s is dropped;
//  - connections: at most max_connections open (the next one is answered 503 and closed), at most
//    max_streams event streams (503 with Retry-After);
//  - methods: GET and HEAD everywhere, POST where the Site accepts it (405 otherwise);
//  - Host: one of the bound address's names with the bound port (a page that a foreign site's
//    DNS points at us is refused: 421), any Host on a non-loopback address (the token guards it);
//  - Origin (when sent, as browsers do): the same origin as Host (403);
//  - token: on a non-loopback address every request must carry view_token or operator_token
//    (`Authorization: Bearer T` or `?token=T`; 401); a POST must carry operator_token wherever it
//    binds (403). Tokens are compared in constant time.
//
// Event streams (Server-Sent Events, text/event-stream): the Site gives an EventStream per client;
// every stream_period_s the server asks it for the next message (a latest-snapshot mailbox: the
// stream says what is new since it last answered, so a slow client skips states, it never queues
// them). At most stream_bytes_per_s are sent per client on average (a token bucket: a message
// waits for its budget); a write not finished within write_timeout_s (a dead client) closes the
// stream. stop() closes every connection and joins the thread at once (open streams included).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace piezobench::web {

struct HttpRequest {
  std::string method;                        // "GET", "HEAD", "POST"
  std::string path;                          // the target without its query, percent-decoded
  std::map<std::string, std::string> query;  // decoded; the token parameter removed
  std::string body;
  bool operator_rights = false;              // the request carried the operator token
};

struct HttpResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // extra ones (Cache-Control, ...)
};
HttpResponse json_response(int status, const std::string& json_text);
HttpResponse error_response(int status, const std::string& message);  // {"error": message}

// One client's event stream: asked every stream period, on the server's thread; must not block.
class EventStream {
 public:
  virtual ~EventStream() = default;
  // The next message (one SSE "data:" payload, no newline inside), or nothing when nothing is new.
  virtual std::optional<std::string> next() = 0;
};

// What the server serves: called on the server's thread.
class Site {
 public:
  virtual ~Site() = default;
  virtual HttpResponse handle(const HttpRequest& request) = 0;
  // The event stream of `request`'s path, or null when the path is not a stream.
  virtual std::unique_ptr<EventStream> open_stream(const HttpRequest& request) = 0;
  // Whether POST is accepted on the path (otherwise 405 before the body is read).
  [[nodiscard]] virtual bool accepts_post(const std::string& path) const = 0;
};

struct HttpServerOptions {
  std::string address = "127.0.0.1";  // IPv4 or IPv6 literal
  unsigned short port = 8080;         // 0: any free port (port() tells)
  std::string view_token;             // required on a non-loopback address (start() refuses without)
  std::string operator_token;         // POST; required (start() refuses without)
  std::size_t max_connections = 64;
  std::size_t max_streams = 16;
  std::size_t max_header_bytes = 8 * 1024;
  std::size_t max_body_bytes = 4 * 1024;
  double request_timeout_s = 10.0;
  double stream_period_s = 0.05;      // 20 messages per second at most
  double stream_bytes_per_s = 50e3;
  double write_timeout_s = 5.0;
  void validate() const;  // InputError naming the field
};

struct HttpServerStats {
  std::uint64_t accepted = 0, refused_over_cap = 0, requests = 0, refused_requests = 0;
  std::uint64_t streams_opened = 0, stream_bytes = 0, streams_dropped_slow = 0;
  std::size_t open_connections = 0, open_streams = 0;
};

class HttpServer {
 public:
  HttpServer(HttpServerOptions options, Site& site);
  ~HttpServer();  // stop()
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Binds and starts the I/O thread. InputError when the address cannot be bound, or when it is
  // not a loopback address and there is no view token.
  void start();
  void stop();
  [[nodiscard]] unsigned short port() const { return port_; }
  [[nodiscard]] bool loopback() const { return loopback_; }
  [[nodiscard]] HttpServerStats stats() const;

  struct Impl;

 private:
  HttpServerOptions options_;
  Site& site_;
  std::unique_ptr<Impl> impl_;
  unsigned short port_ = 0;
  bool loopback_ = true;
};

// One request handled as the server handles it on a new connection, without a socket (the fuzz
// target fuzz_http_request drives the server's request handling through it; docs/fuzzing.md):
// `bytes` are what the client sent before it stopped sending (end of file), read by the same
// parser with the same limits, checked by the same rules (sizes, method, path, query, Host, Origin,
// tokens: the list above) and given to `site` the same way, for a server listening on
// options.address:options.port (nothing is bound). The first request only; no stream is open yet.
// InputError when the options are invalid (HttpServerOptions::validate) or the address is not an IP.
struct HttpExchange {
  enum class Outcome {
    kClosed,    // closed without an answer (the bytes ended before any request started)
    kAnswered,  // `response` answers
    kStream,    // the site's event stream would follow
  } outcome = Outcome::kClosed;
  HttpResponse response;
  bool by_site = false;     // the site answered (or opened the stream); false: refused by the server
  bool keep_alive = false;  // the connection stays open for the next request
  HttpRequest request;      // what the site saw (by_site)
};
HttpExchange exchange_request(const HttpServerOptions& options, Site& site, std::string_view bytes);

// 128 random bits as 32 hexadecimal digits (getrandom).
std::string random_token();
// Whether `address` (an IP literal) is a loopback address (127.0.0.0/8, ::1).
bool is_loopback_address(const std::string& address);

}  // namespace piezobench::web
