#include "piezobench/rt/udp.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <linux/sockios.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <limits>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "rt/util.hpp"

namespace piezobench::rt {

namespace {

void put(unsigned char* p, std::uint64_t v, int bytes) noexcept {
  for (int i = 0; i < bytes; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}
std::uint64_t get(const unsigned char* p, int bytes) noexcept {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}
void put_f64(unsigned char* p, double v) noexcept { put(p, std::bit_cast<std::uint64_t>(v), 8); }
double get_f64(const unsigned char* p) noexcept { return std::bit_cast<double>(get(p, 8)); }

void header(unsigned char* p, UdpType type) noexcept {
  put(p, kUdpMagic, 4);
  put(p + 4, kUdpVersion, 2);
  put(p + 6, static_cast<std::uint16_t>(type), 2);
}
bool check_header(const unsigned char* p, std::size_t size, std::size_t expected) noexcept {
  return size == expected && get(p, 4) == kUdpMagic && get(p + 4, 2) == kUdpVersion;
}

sockaddr_in to_sockaddr(const UdpAddress& a) {
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_addr.s_addr = a.host;
  sa.sin_port = htons(a.port);
  return sa;
}

std::string errno_text() { return std::strerror(errno); }

// Waits until fd is readable or the CLOCK_MONOTONIC deadline passes; true when readable.
bool wait_readable(int fd, std::int64_t deadline_ns) noexcept {
  for (;;) {
    const std::int64_t left = deadline_ns - monotonic_ns();
    if (left <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    timespec ts{static_cast<time_t>(left / 1'000'000'000), static_cast<long>(left % 1'000'000'000)};
    const int r = ppoll(&p, 1, &ts, nullptr);
    if (r > 0) return true;
    if (r < 0 && errno != EINTR) return false;
  }
}

}  // namespace

void encode(const UdpRequest& r, unsigned char (&out)[kUdpRequestSize]) noexcept {
  header(out, r.type);
  put(out + 8, r.sequence, 8);
  put_f64(out + 16, r.u);
  put(out + 24, r.flags, 4);
  put(out + 28, 0, 4);
}

void encode(const UdpReply& r, unsigned char (&out)[kUdpReplySize]) noexcept {
  header(out, r.type);
  put(out + 8, r.sequence, 8);
  put(out + 16, r.sample, 8);
  put_f64(out + 24, r.de);
  put_f64(out + 32, r.vs);
  put_f64(out + 40, r.va);
  put(out + 48, r.status, 4);
  put(out + 52, 0, 4);
}

std::optional<UdpRequest> decode_request(const unsigned char* p, std::size_t size) noexcept {
  if (!check_header(p, size, kUdpRequestSize)) return std::nullopt;
  const auto type = static_cast<UdpType>(get(p + 6, 2));
  if (type != UdpType::kHello && type != UdpType::kIo && type != UdpType::kBye && type != UdpType::kSafe) return std::nullopt;
  UdpRequest r;
  r.type = type;
  r.sequence = get(p + 8, 8);
  r.u = get_f64(p + 16);
  r.flags = static_cast<std::uint32_t>(get(p + 24, 4));
  return r;
}

std::optional<UdpReply> decode_reply(const unsigned char* p, std::size_t size) noexcept {
  if (!check_header(p, size, kUdpReplySize)) return std::nullopt;
  const auto type = static_cast<UdpType>(get(p + 6, 2));
  if (type != UdpType::kHelloReply && type != UdpType::kIoReply && type != UdpType::kByeReply) return std::nullopt;
  UdpReply r;
  r.type = type;
  r.sequence = get(p + 8, 8);
  r.sample = get(p + 16, 8);
  r.de = get_f64(p + 24);
  r.vs = get_f64(p + 32);
  r.va = get_f64(p + 40);
  r.status = static_cast<std::uint32_t>(get(p + 48, 4));
  return r;
}

std::string UdpAddress::to_string() const {
  char buf[INET_ADDRSTRLEN] = {};
  in_addr a{};
  a.s_addr = host;
  inet_ntop(AF_INET, &a, buf, sizeof buf);
  return std::string(buf) + ":" + std::to_string(port);
}

UdpAddress parse_udp_address(const std::string& text, const std::string& source, const std::string& field) {
  const auto colon = text.rfind(':');
  const std::string expected = "HOST:PORT with an IPv4 address (e.g. 127.0.0.1:5600) and a port 0..65535";
  if (colon == std::string::npos) throw InputError(source, field, expected, "'" + text + "'");
  std::string host = text.substr(0, colon);
  const std::string port = text.substr(colon + 1);
  if (host == "localhost") host = "127.0.0.1";
  UdpAddress a;
  in_addr addr{};
  if (inet_pton(AF_INET, host.c_str(), &addr) != 1) throw InputError(source, field, expected, "'" + text + "'");
  a.host = addr.s_addr;
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoul(port) > 65535) {
    throw InputError(source, field, expected, "'" + text + "'");
  }
  a.port = static_cast<std::uint16_t>(std::stoul(port));
  return a;
}

// ---------------------------------------------------------------------------------------------

UdpBackend::UdpBackend(const std::string& address, double sample_rate, double timeout)
    : address_(parse_udp_address(address, "udp backend", "address")), sample_rate_(sample_rate), timeout_(timeout) {
  detail::require_positive(sample_rate, "sample_rate", "udp backend");
  detail::require_positive(timeout, "timeout", "udp backend");
}

UdpBackend::~UdpBackend() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpBackend::start() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw InputError("udp backend", "socket", "a UDP socket", errno_text());
  const sockaddr_in sa = to_sockaddr(address_);
  if (::connect(fd_, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0) {
    throw InputError("udp backend", "address", "a reachable target", address_.to_string() + ": " + errno_text());
  }
  stats_ = IoStats{};
  rtt_ = TimingHistogram{};
  sent_ = answered_ = 0;
  safe_ = false;
  last_ = SensorSample{};
  // Hello: the target resets and says its rate.
  for (int attempt = 0; attempt < 3; ++attempt) {
    unsigned char out[kUdpRequestSize];
    encode(UdpRequest{UdpType::kHello, 0, sample_rate_, 0}, out);
    if (::send(fd_, out, sizeof out, 0) < 0 && errno != ECONNREFUSED) {
      throw InputError("udp backend", "address", "a reachable target", address_.to_string() + ": " + errno_text());
    }
    const std::int64_t deadline = monotonic_ns() + 500'000'000;
    while (wait_readable(fd_, deadline)) {
      unsigned char in[kUdpReplySize + 8];
      const ssize_t n = ::recv(fd_, in, sizeof in, MSG_DONTWAIT);
      if (n < 0) break;  // ECONNREFUSED: nobody listens yet; try again
      const auto r = decode_reply(in, static_cast<std::size_t>(n));
      if (!r || r->type != UdpType::kHelloReply) continue;
      if (std::abs(r->de - sample_rate_) > 1e-9 * sample_rate_) {
        throw InputError("udp target " + address_.to_string(), "sample rate", format_number(sample_rate_) + " Hz (the bench file's)",
                         format_number(r->de) + " Hz");
      }
      return;
    }
  }
  throw InputError("udp target " + address_.to_string(), "hello", "an answer within 3 x 0.5 s", "no answer");
}

bool UdpBackend::receive(std::int64_t deadline_ns, std::uint64_t wanted, UdpReply& reply) noexcept {
  for (;;) {
    unsigned char in[kUdpReplySize + 8];
    ssize_t n = ::recv(fd_, in, sizeof in, MSG_DONTWAIT);
    if (n < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR && errno != ECONNREFUSED) ++stats_.errors;
      if (!wait_readable(fd_, deadline_ns)) return false;
      continue;
    }
    const auto r = decode_reply(in, static_cast<std::size_t>(n));
    if (!r || r->type != UdpType::kIoReply) continue;
    if (r->sequence == wanted) {
      reply = *r;
      return true;
    }
    // An answer to an earlier request that a read gave up on.
    if (r->sequence < wanted) ++stats_.late;
  }
}

SensorSample UdpBackend::read() noexcept {
  if (fd_ < 0 || answered_ == sent_) {
    ++stats_.timeouts;
    return last_;  // nothing outstanding: stale
  }
  const std::uint64_t wanted = sent_;
  UdpReply r;
  if (!receive(monotonic_ns() + static_cast<std::int64_t>(timeout_ * 1e9), wanted, r)) {
    ++stats_.timeouts;
    answered_ = wanted;  // its reply, if it comes, is late
    return last_;
  }
  // Round trip: the kernel's arrival time of the reply (not when this cycle got to it) minus the
  // request's send time, both on CLOCK_REALTIME.
  timespec arrival{};
  if (::ioctl(fd_, SIOCGSTAMPNS, &arrival) == 0) {
    rtt_.add(static_cast<double>(arrival.tv_sec * 1'000'000'000LL + arrival.tv_nsec - sent_ns_));
  }
  ++stats_.replies;
  answered_ = wanted;
  const bool fault = (r.status & (kUdpStatusTargetSafe | kUdpStatusSensorFault)) != 0;
  last_.de = fault ? std::numeric_limits<double>::quiet_NaN() : r.de;
  last_.vs = fault ? std::numeric_limits<double>::quiet_NaN() : r.vs;
  last_.va = r.va;
  ++last_.sequence;
  return last_;
}

void UdpBackend::write(double u) noexcept {
  if (fd_ < 0) return;
  unsigned char out[kUdpRequestSize];
  encode(UdpRequest{UdpType::kIo, sent_ + 1, u, safe_ ? 1u : 0u}, out);
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  sent_ns_ = now.tv_sec * 1'000'000'000LL + now.tv_nsec;
  if (::send(fd_, out, sizeof out, 0) < 0) {
    ++stats_.errors;
    return;
  }
  ++sent_;
  ++stats_.exchanges;
}

void UdpBackend::on_watchdog() noexcept {
  if (fd_ < 0) return;
  unsigned char out[kUdpRequestSize];
  encode(UdpRequest{UdpType::kSafe, 0, 0.0, 1u}, out);
  ::send(fd_, out, sizeof out, 0);
}

void UdpBackend::stop() noexcept {
  if (fd_ < 0) return;
  // The replies still on their way (the last writes have no read after them) are answers, not
  // losses: collect them, then say bye.
  const std::int64_t deadline = monotonic_ns() + std::max<std::int64_t>(static_cast<std::int64_t>(timeout_ * 1e9), 50'000'000);
  std::uint64_t pending = sent_ > answered_ ? sent_ - answered_ : 0;
  while (pending > 0 && wait_readable(fd_, deadline)) {
    unsigned char in[kUdpReplySize + 8];
    const ssize_t n = ::recv(fd_, in, sizeof in, MSG_DONTWAIT);
    if (n < 0) continue;
    const auto r = decode_reply(in, static_cast<std::size_t>(n));
    if (!r || r->type != UdpType::kIoReply) continue;
    if (r->sequence > answered_) {
      ++stats_.replies;
      --pending;
    } else {
      ++stats_.late;
    }
  }
  unsigned char out[kUdpRequestSize];
  encode(UdpRequest{UdpType::kBye, sent_ + 1, 0.0, 0}, out);
  ::send(fd_, out, sizeof out, 0);
  const std::int64_t bye_deadline = monotonic_ns() + 100'000'000;
  while (wait_readable(fd_, bye_deadline)) {
    unsigned char in[kUdpReplySize + 8];
    const ssize_t n = ::recv(fd_, in, sizeof in, MSG_DONTWAIT);
    if (n < 0) continue;
    const auto r = decode_reply(in, static_cast<std::size_t>(n));
    if (r && r->type == UdpType::kByeReply) break;
    if (r && r->type == UdpType::kIoReply) ++stats_.late;
  }
  ::close(fd_);
  fd_ = -1;
}

IoStats UdpBackend::io_stats() const {
  IoStats s = stats_;
  const std::uint64_t answered = s.replies + s.late;
  s.lost = s.exchanges > answered ? s.exchanges - answered : 0;
  s.round_trip_us = rtt_.summary_us();
  return s;
}

// ---------------------------------------------------------------------------------------------

UdpServerReport serve_udp(const bench::UnitTruth& unit, const bench::BenchOptions& options, std::uint64_t seed,
                          const UdpServerOptions& server) {
  const UdpAddress address = parse_udp_address(server.address, "bench serve", "--udp");
  bench::VirtualBench bench(unit, options, seed);
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw InputError("bench serve", "socket", "a UDP socket", errno_text());
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  sockaddr_in sa = to_sockaddr(address);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0) {
    throw InputError("bench serve", "--udp", "an address this host can listen on", address.to_string() + ": " + errno_text());
  }
  socklen_t len = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &len);
  UdpAddress bound{sa.sin_addr.s_addr, ntohs(sa.sin_port)};
  if (server.on_listening) server.on_listening(bound.to_string());

  UdpServerReport rep;
  std::uint64_t sample = 0, io_requests = 0;
  bool safe = false;
  std::int64_t last_activity = monotonic_ns();
  const auto idle_ns = static_cast<std::int64_t>(server.idle_timeout * 1e9);
  for (;;) {
    if (server.stop != nullptr && server.stop->load()) break;
    if (!wait_readable(fd, monotonic_ns() + 100'000'000)) {
      if (monotonic_ns() - last_activity > idle_ns) break;
      continue;
    }
    unsigned char in[kUdpRequestSize + 8];
    sockaddr_in from{};
    socklen_t from_len = sizeof from;
    const ssize_t n = ::recvfrom(fd, in, sizeof in, 0, reinterpret_cast<sockaddr*>(&from), &from_len);
    if (n < 0) continue;
    last_activity = monotonic_ns();
    const auto req = decode_request(in, static_cast<std::size_t>(n));
    if (!req) {
      ++rep.rejected;
      continue;
    }
    UdpReply reply;
    reply.sequence = req->sequence;
    switch (req->type) {
      case UdpType::kHello:
        bench.reset(seed);
        sample = 0;
        io_requests = 0;
        safe = false;
        reply.type = UdpType::kHelloReply;
        reply.de = bench.sample_rate();
        break;
      case UdpType::kIo: {
        ++rep.requests;
        ++io_requests;
        const bench::BenchSample s = bench.step(safe ? 0.0 : req->u);
        reply.type = UdpType::kIoReply;
        reply.sample = ++sample;
        reply.de = s.de;
        reply.vs = s.vs;
        reply.va = s.va;
        reply.status = safe ? kUdpStatusTargetSafe : 0u;
        if (server.drop_every > 0 && io_requests % server.drop_every == 0) {
          ++rep.dropped;
          continue;
        }
        break;
      }
      case UdpType::kSafe:
        safe = true;
        rep.target_safe = true;
        continue;
      case UdpType::kBye:
        reply.type = UdpType::kByeReply;
        ++rep.sessions;
        break;
      default:
        continue;
    }
    unsigned char out[kUdpReplySize];
    encode(reply, out);
    if (::sendto(fd, out, sizeof out, 0, reinterpret_cast<const sockaddr*>(&from), from_len) >= 0) ++rep.replies;
    if (req->type == UdpType::kBye && server.sessions > 0 && rep.sessions >= static_cast<std::uint64_t>(server.sessions)) break;
  }
  return rep;
}

}  // namespace piezobench::rt
