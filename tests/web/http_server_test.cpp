// The station's HTTP server against hostile and careless clients (issue 29): raw sockets, so every
// byte of a request is the test's.
#include "piezobench/web/http_server.hpp"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "piezobench/core/error.hpp"

namespace piezobench::web {
namespace {

using Clock = std::chrono::steady_clock;

// A site of two pages, a POST endpoint and a stream whose every message is `message_bytes` long.
class TestSite final : public Site {
 public:
  std::size_t message_bytes = 100;
  HttpResponse handle(const HttpRequest& r) override {
    if (r.path == "/") return {200, "text/html", "<p>station</p>", {}};
    if (r.path == "/api/answer") return json_response(200, R"({"ok":true})");
    return error_response(404, "no such page");
  }
  std::unique_ptr<EventStream> open_stream(const HttpRequest& r) override {
    if (r.path != "/events") return nullptr;
    struct Stream final : EventStream {
      std::size_t n;
      explicit Stream(std::size_t bytes) : n(bytes) {}
      std::optional<std::string> next() override { return std::string(n, 'x'); }
    };
    return std::make_unique<Stream>(message_bytes);
  }
  [[nodiscard]] bool accepts_post(const std::string& path) const override { return path == "/api/answer"; }
};

int connect_to(unsigned short port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

void send_all(int fd, const std::string& bytes) {
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return;  // the server may close early (a refused request)
    sent += static_cast<std::size_t>(n);
  }
}

// Everything the server sends until it closes or `timeout` passes.
std::string read_all(int fd, std::chrono::milliseconds timeout) {
  std::string out;
  const auto end = Clock::now() + timeout;
  char buf[65536];
  while (Clock::now() < end) {
    pollfd p{fd, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now()).count();
    if (::poll(&p, 1, static_cast<int>(std::max<long>(1, left))) <= 0) continue;
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
  }
  return out;
}

std::string http_exchange(unsigned short port, const std::string& request, std::chrono::milliseconds timeout = std::chrono::milliseconds(3000)) {
  const int fd = connect_to(port);
  if (fd < 0) return "";
  send_all(fd, request);
  std::string out = read_all(fd, timeout);
  ::close(fd);
  return out;
}

int status_of(const std::string& response) {
  if (response.rfind("HTTP/1.1 ", 0) != 0 || response.size() < 12) return 0;
  return std::stoi(response.substr(9, 3));
}

std::string http_get(unsigned short port, const std::string& target, const std::string& extra = "") {
  return fmt::format("GET {} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nConnection: close\r\n{}\r\n", target, port, extra);
}

HttpServerOptions loopback_options() {
  HttpServerOptions o;
  o.port = 0;
  o.operator_token = "0123456789abcdef0123456789abcdef";
  return o;
}

// A started server of a TestSite.
struct Running {
  TestSite site;
  HttpServerOptions options;
  std::unique_ptr<HttpServer> server;
  unsigned short port = 0;
  explicit Running(HttpServerOptions o = loopback_options(), std::size_t message_bytes = 100) : options(std::move(o)) {
    site.message_bytes = message_bytes;
    server = std::make_unique<HttpServer>(options, site);
    server->start();
    port = server->port();
  }
};

TEST(HttpServer, ServesPagesAndRefusesUnknownOrEscapingPaths) {
  Running r;
  const unsigned short p = r.port;
  const std::string ok = http_exchange(p, http_get(p, "/"));
  EXPECT_EQ(status_of(ok), 200) << ok;
  EXPECT_NE(ok.find("<p>station</p>"), std::string::npos);
  EXPECT_NE(ok.find("Content-Security-Policy: default-src 'self'"), std::string::npos);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/etc/passwd"))), 404);
  for (const char* escaping : {"/../etc/passwd", "/a/%2e%2e/b", "/%2E%2E/x", "/./", "/a%00b", "/a\\..\\b", "/x/%2", "/x/%zz"}) {
    EXPECT_EQ(status_of(http_exchange(p, http_get(p, escaping))), 400) << escaping;
  }
  EXPECT_EQ(status_of(http_exchange(p, "DELETE / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(p) + "\r\n\r\n")), 405);
  EXPECT_EQ(status_of(http_exchange(p, "NONSENSE\r\n\r\n")), 400);
}

// Issue 35 (fuzz_http_request's first finding): a refusal quoting a path or Host header that is not
// UTF-8 threw from the JSON writer on the server's thread, which ended the process.
TEST(HttpServer, BytesThatAreNotUtf8AreAnsweredAndTheServerStaysUp) {
  Running r;
  const unsigned short p = r.port;
  const std::string foreign = http_exchange(p, "GET / HTTP/1.1\r\nHost: 127.0.0.1:\xff\xff\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(status_of(foreign), 421) << foreign;
  EXPECT_NE(foreign.find("\xef\xbf\xbd"), std::string::npos);  // U+FFFD where the Host's bytes were
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/", "Origin: http://\xc3\x28\r\n"))), 403);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/\xe2\xe2\xe2"))), 404);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/%e2%ff"))), 404);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/"))), 200);
}

TEST(HttpServer, RefusesOversizedRequests) {
  Running r;
  const HttpServerOptions& o = r.options;
  const unsigned short p = r.port;
  const std::string big_header = "X-Pad: " + std::string(o.max_header_bytes + 10, 'a') + "\r\n";
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/", big_header))), 431);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/" + std::string(o.max_header_bytes + 10, 'a')))), 431);
  const std::string body(o.max_body_bytes + 1, '{');
  const std::string post = fmt::format(
      "POST /api/answer HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nAuthorization: Bearer {}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{}", p,
      o.operator_token, body.size(), body);
  EXPECT_EQ(status_of(http_exchange(p, post)), 413);
  // A body announced larger than the limit is refused before it is sent.
  EXPECT_EQ(status_of(http_exchange(p, fmt::format("POST /api/answer HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Length: 100000000\r\n\r\n", p))), 413);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/"))), 200);
}

TEST(HttpServer, RefusesForeignHostAndOrigin) {
  Running r;
  const unsigned short p = r.port;
  // DNS rebinding: a page of evil.example whose name now points at 127.0.0.1.
  EXPECT_EQ(status_of(http_exchange(p, fmt::format("GET / HTTP/1.1\r\nHost: evil.example:{}\r\nConnection: close\r\n\r\n", p))), 421);
  EXPECT_EQ(status_of(http_exchange(p, "GET / HTTP/1.1\r\nConnection: close\r\n\r\n")), 400);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/", "Origin: http://evil.example\r\n"))), 403);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/", fmt::format("Origin: http://127.0.0.1:{}\r\n", p)))), 200);
  EXPECT_EQ(status_of(http_exchange(p, fmt::format("GET / HTTP/1.1\r\nHost: localhost:{}\r\nConnection: close\r\n\r\n", p))), 200);
}

TEST(HttpServer, PostNeedsTheOperatorToken) {
  Running r;
  const HttpServerOptions& o = r.options;
  const unsigned short p = r.port;
  const auto post = [&](const std::string& auth, const std::string& path = "/api/answer") {
    return status_of(http_exchange(p, fmt::format("POST {} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n{}Content-Length: 2\r\nConnection: close\r\n\r\n{{}}", path, p,
                                             auth)));
  };
  EXPECT_EQ(post(""), 403);
  EXPECT_EQ(post("Authorization: Bearer 0123456789abcdef0123456789abcdee\r\n"), 403);
  EXPECT_EQ(post("Authorization: Bearer " + o.operator_token + "\r\n"), 200);
  EXPECT_EQ(post("Authorization: Bearer " + o.operator_token + "\r\n", "/"), 405);
  EXPECT_EQ(status_of(http_exchange(p, fmt::format("POST /api/answer?token={} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
                                              o.operator_token, p))),
            200);
}

TEST(HttpServer, AnyOtherAddressNeedsATokenOnEveryRequest) {
  TestSite site;
  HttpServerOptions o = loopback_options();
  o.address = "0.0.0.0";
  {
    HttpServer refused(o, site);
    EXPECT_THROW(refused.start(), InputError);
  }
  o.view_token = "fedcba9876543210fedcba9876543210";
  HttpServer server(o, site);
  server.start();
  EXPECT_FALSE(server.loopback());
  const unsigned short p = server.port();
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/"))), 401);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/?token=fedcba9876543210fedcba987654321f"))), 401);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/?token=" + o.view_token))), 200);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/", "Authorization: Bearer " + o.operator_token + "\r\n"))), 200);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/events"))), 401);
}

TEST(HttpServer, OneClientMoreThanTheCapIsAnswered503) {
  HttpServerOptions o = loopback_options();
  o.max_connections = 4;
  o.max_streams = 2;
  Running r(o);
  const unsigned short p = r.port;
  std::vector<int> idle;
  for (int i = 0; i < 4; ++i) idle.push_back(connect_to(p));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const std::string over = http_exchange(p, http_get(p, "/"));
  EXPECT_EQ(status_of(over), 503) << over;
  EXPECT_NE(over.find("Retry-After: 5"), std::string::npos);
  for (int fd : idle) ::close(fd);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/"))), 200);
  // Streams: two follow, the third is told to come back.
  std::vector<int> streams;
  for (int i = 0; i < 2; ++i) {
    streams.push_back(connect_to(p));
    send_all(streams.back(), http_get(p, "/events"));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/events"))), 503);
  EXPECT_EQ(r.server->stats().open_streams, 2u);
  for (int fd : streams) ::close(fd);
}

TEST(HttpServer, AThousandConcurrentConnectionsAreRefusedCleanlyAndTheServerStaysUp) {
  HttpServerOptions o = loopback_options();
  o.max_connections = 64;
  Running r(o);
  const unsigned short p = r.port;
  std::vector<int> fds;
  for (int i = 0; i < 1000; ++i) {
    const int fd = connect_to(p);
    if (fd >= 0) {
      send_all(fd, http_get(p, "/"));
      fds.push_back(fd);
    }
  }
  int ok = 0, busy = 0, other = 0;
  for (int fd : fds) {
    const int s = status_of(read_all(fd, std::chrono::milliseconds(2000)));
    (s == 200 ? ok : s == 503 ? busy : other) += 1;
    ::close(fd);
  }
  EXPECT_EQ(fds.size(), 1000u);
  EXPECT_EQ(ok + busy, 1000) << ok << " served, " << busy << " busy, " << other << " other";
  EXPECT_GE(ok, 64);
  EXPECT_EQ(status_of(http_exchange(p, http_get(p, "/"))), 200);
  EXPECT_EQ(r.server->stats().refused_over_cap, static_cast<std::uint64_t>(busy));
}

TEST(HttpServer, AStreamSendsAtMostItsByteRate) {
  Running r(loopback_options(), 10000);  // 200 kB/s if every tick sent one
  const HttpServerOptions& o = r.options;
  const unsigned short p = r.port;
  const int fd = connect_to(p);
  send_all(fd, http_get(p, "/events"));
  const auto start = Clock::now();
  const std::string got = read_all(fd, std::chrono::milliseconds(3000));
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  ::close(fd);
  EXPECT_NE(got.find("Content-Type: text/event-stream"), std::string::npos);
  // The bucket: one second's worth at once, then the rate.
  const double limit = o.stream_bytes_per_s * (1.0 + seconds) + r.site.message_bytes + 1000;
  EXPECT_LE(static_cast<double>(got.size()), limit);
  EXPECT_GE(static_cast<double>(got.size()), 0.8 * o.stream_bytes_per_s * seconds);
}

TEST(HttpServer, StopsWithinASecondWithStreamsOpen) {
  Running r;
  const unsigned short p = r.port;
  std::vector<int> fds;
  for (int i = 0; i < 5; ++i) {
    fds.push_back(connect_to(p));
    send_all(fds.back(), http_get(p, "/events"));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(r.server->stats().open_streams, 5u);
  const auto start = Clock::now();
  r.server->stop();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_LT(seconds, 1.0);
  for (int fd : fds) {
    read_all(fd, std::chrono::milliseconds(500));  // the server closed it: EOF, not a hang
    ::close(fd);
  }
}

// exchange_request: the server's handling of one request without a socket, as fuzz_http_request
// drives it; the same answers as over a socket above.
TEST(HttpServer, ExchangeRequestHandlesOneRequestAsTheServerDoes) {
  TestSite site;
  HttpServerOptions o = loopback_options();
  o.port = 8080;
  const auto get = [](const std::string& target, const std::string& extra = "") {
    return fmt::format("GET {} HTTP/1.1\r\nHost: 127.0.0.1:8080\r\n{}\r\n", target, extra);
  };
  HttpExchange x = exchange_request(o, site, get("/"));
  EXPECT_EQ(x.outcome, HttpExchange::Outcome::kAnswered);
  EXPECT_EQ(x.response.status, 200);
  EXPECT_EQ(x.response.body, "<p>station</p>");
  EXPECT_TRUE(x.by_site);
  EXPECT_TRUE(x.keep_alive);  // HTTP/1.1 without Connection: close
  EXPECT_EQ(x.request.path, "/");
  x = exchange_request(o, site, get("/a/%2e%2e/b"));
  EXPECT_EQ(x.response.status, 400);
  EXPECT_FALSE(x.by_site);
  EXPECT_FALSE(x.keep_alive);
  EXPECT_EQ(exchange_request(o, site, get("/", "X-Pad: " + std::string(o.max_header_bytes + 10, 'a') + "\r\n")).response.status, 431);
  EXPECT_EQ(exchange_request(o, site, "GET / HTTP/1.1\r\nHost: 127.0.0.1:8081\r\n\r\n").response.status, 421);  // another port
  EXPECT_EQ(exchange_request(o, site, "POST /api/answer HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nContent-Length: 100000000\r\n\r\n").response.status,
            413);
  const std::string post = "POST /api/answer?token=" + o.operator_token + " HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nContent-Length: 2\r\n\r\n{}";
  x = exchange_request(o, site, post);
  EXPECT_EQ(x.response.status, 200);
  EXPECT_TRUE(x.request.operator_rights);
  EXPECT_EQ(x.request.body, "{}");
  EXPECT_TRUE(x.request.query.empty());  // the token is taken out
  EXPECT_EQ(exchange_request(o, site, "POST /api/answer HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nContent-Length: 2\r\n\r\n{}").response.status, 403);
  EXPECT_EQ(exchange_request(o, site, get("/events")).outcome, HttpExchange::Outcome::kStream);
  // The bytes end: before a request (closed without an answer) or inside one (400, as a client
  // that stops sending mid-request).
  EXPECT_EQ(exchange_request(o, site, "").outcome, HttpExchange::Outcome::kClosed);
  EXPECT_EQ(exchange_request(o, site, "GET / HTTP/1.1\r\nHost: 127.0").response.status, 400);
  // Any other address: a token on every request.
  o.address = "0.0.0.0";
  o.view_token = "fedcba9876543210fedcba9876543210";
  EXPECT_EQ(exchange_request(o, site, get("/")).response.status, 401);
  EXPECT_EQ(exchange_request(o, site, get("/?token=" + o.view_token)).response.status, 200);
  o.address = "not an address";
  EXPECT_THROW((void)exchange_request(o, site, get("/")), InputError);
}

TEST(HttpServer, TokensAreRandomAndLoopbackIsRecognised) {
  const std::string a = random_token(), b = random_token();
  EXPECT_EQ(a.size(), 32u);
  EXPECT_NE(a, b);
  EXPECT_TRUE(is_loopback_address("127.0.0.1"));
  EXPECT_TRUE(is_loopback_address("127.1.2.3"));
  EXPECT_TRUE(is_loopback_address("::1"));
  EXPECT_FALSE(is_loopback_address("0.0.0.0"));
  EXPECT_FALSE(is_loopback_address("192.168.1.10"));
  EXPECT_FALSE(is_loopback_address("localhost"));  // not an IP literal
}

}  // namespace
}  // namespace piezobench::web
