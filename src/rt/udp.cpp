#include "piezobench/rt/udp.hpp"

#include <arpa/inet.h>
#include <nettle/hmac.h>
#include <nettle/memops.h>
#include <netinet/in.h>
#include <linux/sockios.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <sstream>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "udp_socket.hpp"
#include "util.hpp"

namespace piezobench::rt {

using detail::to_sockaddr;
using detail::wait_readable;

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

std::string errno_text() { return std::strerror(errno); }

}  // namespace

void encode(const UdpRequest& r, unsigned char (&out)[kUdpRequestSize]) noexcept {
  header(out, r.type);
  put(out + 8, r.sequence, 8);
  put_f64(out + 16, r.u);
  put(out + 24, r.flags, 4);
  put(out + 28, r.session, 4);
}

void encode(const UdpReply& r, unsigned char (&out)[kUdpReplySize]) noexcept {
  header(out, r.type);
  put(out + 8, r.sequence, 8);
  put(out + 16, r.sample, 8);
  put_f64(out + 24, r.de);
  put_f64(out + 32, r.vs);
  put_f64(out + 40, r.va);
  put(out + 48, r.status, 4);
  put(out + 52, r.session, 4);
}

std::optional<UdpRequest> decode_request(const unsigned char* p, std::size_t size) noexcept {
  if (!check_header(p, size, kUdpRequestSize)) return std::nullopt;
  const auto type = static_cast<UdpType>(get(p + 6, 2));
  if (type != UdpType::kHello && type != UdpType::kIo && type != UdpType::kBye && type != UdpType::kSafe && type != UdpType::kReset) {
    return std::nullopt;
  }
  UdpRequest r;
  r.type = type;
  r.sequence = get(p + 8, 8);
  r.u = get_f64(p + 16);
  r.flags = static_cast<std::uint32_t>(get(p + 24, 4));
  r.session = static_cast<std::uint32_t>(get(p + 28, 4));
  return r;
}

std::optional<UdpReply> decode_reply(const unsigned char* p, std::size_t size) noexcept {
  if (!check_header(p, size, kUdpReplySize)) return std::nullopt;
  const auto type = static_cast<UdpType>(get(p + 6, 2));
  if (type != UdpType::kHelloReply && type != UdpType::kIoReply && type != UdpType::kByeReply && type != UdpType::kResetReply) {
    return std::nullopt;
  }
  UdpReply r;
  r.type = type;
  r.sequence = get(p + 8, 8);
  r.sample = get(p + 16, 8);
  r.de = get_f64(p + 24);
  r.vs = get_f64(p + 32);
  r.va = get_f64(p + 40);
  r.status = static_cast<std::uint32_t>(get(p + 48, 4));
  r.session = static_cast<std::uint32_t>(get(p + 52, 4));
  return r;
}

std::string read_udp_key(const std::filesystem::path& file, const std::string& source, const std::string& field) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(source, field, "a readable key file", "'" + file.string() + "': " + errno_text());
  std::ostringstream text;
  text << in.rdbuf();
  std::string key = text.str();
  while (!key.empty() && std::isspace(static_cast<unsigned char>(key.back()))) key.pop_back();
  if (key.size() < 16 || key.size() > 4096) {
    throw InputError(source, field, "a key of 16 to 4096 bytes (e.g. `head -c 32 /dev/urandom | base64`)",
                     std::to_string(key.size()) + " bytes in '" + file.string() + "'");
  }
  return key;
}

namespace {
// HMAC-SHA256 (nettle) of data[0, n) under key into tag (kUdpTagSize bytes).
void hmac_sha256(const std::string& key, const unsigned char* data, std::size_t n, unsigned char* tag) noexcept {
  hmac_sha256_ctx ctx;
  hmac_sha256_set_key(&ctx, key.size(), reinterpret_cast<const std::uint8_t*>(key.data()));
  hmac_sha256_update(&ctx, n, data);
  hmac_sha256_digest(&ctx, kUdpTagSize, tag);
}
}  // namespace

std::size_t seal(unsigned char* datagram, std::size_t n, const std::string& key) noexcept {
  if (key.empty()) return n;
  hmac_sha256(key, datagram, n, datagram + n);
  return n + kUdpTagSize;
}

std::size_t unseal(const unsigned char* datagram, std::size_t n, const std::string& key) noexcept {
  if (key.empty()) return n;
  if (n < kUdpTagSize) return 0;
  const std::size_t payload = n - kUdpTagSize;
  unsigned char tag[kUdpTagSize];
  hmac_sha256(key, datagram, payload, tag);
  return memeql_sec(tag, datagram + payload, kUdpTagSize) != 0 ? payload : 0;  // constant time
}

std::string UdpAddress::to_string() const {
  char buf[INET_ADDRSTRLEN] = {};
  in_addr a{};
  a.s_addr = host;
  inet_ntop(AF_INET, &a, buf, sizeof buf);
  return std::string(buf) + ":" + std::to_string(port);
}

bool UdpAddress::loopback() const { return (ntohl(host) >> 24) == 127; }

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

UdpBackend::UdpBackend(const std::string& address, double sample_rate, double timeout, UdpBackendOptions options)
    : address_(parse_udp_address(address, "udp backend", "address")),
      sample_rate_(sample_rate),
      timeout_(timeout),
      options_(std::move(options)) {
  detail::require_positive(sample_rate, "sample_rate", "udp backend");
  detail::require_positive(timeout, "timeout", "udp backend");
}

UdpBackend::~UdpBackend() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpBackend::send_request(const UdpRequest& r) noexcept {
  unsigned char out[kUdpRequestSize + kUdpTagSize];
  encode(r, reinterpret_cast<unsigned char(&)[kUdpRequestSize]>(out));
  if (::send(fd_, out, seal(out, kUdpRequestSize, options_.key), 0) < 0) ++stats_.errors;
}

std::optional<UdpReply> UdpBackend::receive_reply() noexcept {
  unsigned char in[kUdpReplySize + kUdpTagSize + 8];
  const ssize_t n = ::recv(fd_, in, sizeof in, MSG_DONTWAIT);
  if (n < 0) return std::nullopt;
  const std::size_t payload = unseal(in, static_cast<std::size_t>(n), options_.key);
  auto r = payload > 0 ? decode_reply(in, payload) : std::nullopt;
  // A reply of another session (an earlier one's late datagram, a forged one): not ours.
  if (!r || (session_ != 0 && r->session != session_)) {
    ++stats_.rejected;
    return std::nullopt;
  }
  return r;
}

// Sends `type` (hello or reset) until its answer comes: 3 tries, 0.5 s each.
bool UdpBackend::exchange(UdpType type, UdpType answer, UdpReply& reply) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    unsigned char out[kUdpRequestSize + kUdpTagSize];
    encode(UdpRequest{type, 0, type == UdpType::kHello ? sample_rate_ : 0.0, 0, session_},
           reinterpret_cast<unsigned char(&)[kUdpRequestSize]>(out));
    if (::send(fd_, out, seal(out, kUdpRequestSize, options_.key), 0) < 0 && errno != ECONNREFUSED) {
      throw InputError("udp backend", "address", "a reachable target", address_.to_string() + ": " + errno_text());
    }
    const std::int64_t deadline = monotonic_ns() + 500'000'000;
    while (wait_readable(fd_, deadline)) {
      const auto r = receive_reply();
      if (!r) continue;  // ECONNREFUSED (nobody listens yet: try again), or not a reply of ours
      if (r->type != answer) continue;
      reply = *r;
      return true;
    }
  }
  return false;
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
  sent_ = answered_ = last_sample_ = last_reply_sequence_ = 0;
  session_ = 0;
  counter_fault_ = safe_ = false;
  last_ = SensorSample{};
  const std::string target = "udp target " + address_.to_string();
  // Hello: the target opens this host's session (or refuses: busy) and says its rate.
  UdpReply r;
  if (!exchange(UdpType::kHello, UdpType::kHelloReply, r)) throw InputError(target, "hello", "an answer within 3 x 0.5 s", "no answer");
  if ((r.status & kUdpStatusBusy) != 0) {
    throw InputError(target, "hello", "a target free for this host",
                     "busy: it serves another host's session (one at a time; docs/hardware.md \"UDP protocol\")");
  }
  if (r.session == 0) throw InputError(target, "hello", "a session id (protocol version 2)", "0");
  session_ = r.session;
  // From here on a refusal closes the session it opened (a bye), so the target is free at once.
  const auto refuse = [this](const InputError& e) {
    stop();
    throw e;
  };
  if (std::abs(r.de - sample_rate_) > 1e-9 * sample_rate_) {
    refuse(InputError(target, "sample rate", format_number(sample_rate_) + " Hz (the bench file's)", format_number(r.de) + " Hz"));
  }
  if ((r.status & kUdpStatusTargetSafe) == 0) return;
  // The safe state a fault latched (in this or an earlier session): only this session's reset,
  // after the operator's confirmation, clears it.
  if (!options_.confirm_reset || !options_.confirm_reset(target)) {
    refuse(InputError(target, "safe state",
                      "a target ready to move (its latched safe state is cleared by `measure --reset-target` after the "
                      "operator checked the bench)",
                      "the safe state latched by an earlier fault"));
  }
  if (!exchange(UdpType::kReset, UdpType::kResetReply, r) || (r.status & kUdpStatusTargetSafe) != 0) {
    refuse(InputError(target, "reset", "the target out of its safe state", "no answer or still safe"));
  }
}

bool UdpBackend::receive(std::int64_t deadline_ns, std::uint64_t wanted, UdpReply& reply) noexcept {
  for (;;) {
    errno = 0;
    const auto r = receive_reply();
    if (!r) {
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR || errno == ECONNREFUSED) {
        if (!wait_readable(fd_, deadline_ns)) return false;
      } else if (errno != 0) {
        ++stats_.errors;
        if (!wait_readable(fd_, deadline_ns)) return false;
      }
      continue;
    }
    if (r->type != UdpType::kIoReply) continue;
    if (r->sequence == wanted) {
      reply = *r;
      return true;
    }
    // An answer to an earlier request that a read gave up on.
    if (r->sequence < wanted) ++stats_.late;
  }
}

SensorSample UdpBackend::read() noexcept {
  if (fd_ < 0 || answered_ == sent_ || counter_fault_) {
    ++stats_.timeouts;
    return last_;  // nothing outstanding (or the target broke the protocol): stale
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
  // The target steps once per io request of this session: its sample counter advances, by at most
  // the requests sent since the previous reply (fewer when a request was lost). More, or less
  // than one, is another host stepping it or a broken target: the safe state.
  const std::uint64_t requests = wanted - last_reply_sequence_;
  if (r.sample <= last_sample_ || r.sample - last_sample_ > requests) {
    counter_fault_ = true;
    ++stats_.errors;
  }
  last_sample_ = r.sample;
  last_reply_sequence_ = wanted;
  const bool fault = counter_fault_ || (r.status & (kUdpStatusTargetSafe | kUdpStatusSensorFault)) != 0;
  last_.de = fault ? std::numeric_limits<double>::quiet_NaN() : r.de;
  last_.vs = fault ? std::numeric_limits<double>::quiet_NaN() : r.vs;
  last_.va = r.va;
  ++last_.sequence;
  return last_;
}

void UdpBackend::write(double u) noexcept {
  if (fd_ < 0) return;
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  sent_ns_ = now.tv_sec * 1'000'000'000LL + now.tv_nsec;
  unsigned char out[kUdpRequestSize + kUdpTagSize];
  encode(UdpRequest{UdpType::kIo, sent_ + 1, u, safe_ ? 1u : 0u, session_}, reinterpret_cast<unsigned char(&)[kUdpRequestSize]>(out));
  if (::send(fd_, out, seal(out, kUdpRequestSize, options_.key), 0) < 0) {
    ++stats_.errors;
    return;
  }
  ++sent_;
  ++stats_.exchanges;
}

void UdpBackend::on_watchdog() noexcept {
  if (fd_ < 0) return;
  send_request(UdpRequest{UdpType::kSafe, 0, 0.0, 1u, session_});
}

void UdpBackend::stop() noexcept {
  if (fd_ < 0) return;
  // The replies still on their way (the last writes have no read after them) are answers, not
  // losses: collect them, then say bye.
  const std::int64_t deadline = monotonic_ns() + std::max<std::int64_t>(static_cast<std::int64_t>(timeout_ * 1e9), 50'000'000);
  std::uint64_t pending = sent_ > answered_ ? sent_ - answered_ : 0;
  while (pending > 0 && wait_readable(fd_, deadline)) {
    const auto r = receive_reply();
    if (!r || r->type != UdpType::kIoReply) continue;
    if (r->sequence > answered_) {
      ++stats_.replies;
      --pending;
    } else {
      ++stats_.late;
    }
  }
  // Bye (3 tries): a lost bye would keep the session open on the target until its time-out.
  for (int attempt = 0; attempt < 3; ++attempt) {
    send_request(UdpRequest{UdpType::kBye, sent_ + 1, 0.0, 0, session_});
    const std::int64_t bye_deadline = monotonic_ns() + 100'000'000;
    bool done = false;
    while (!done && wait_readable(fd_, bye_deadline)) {
      const auto r = receive_reply();
      if (r && r->type == UdpType::kByeReply) done = true;
      if (r && r->type == UdpType::kIoReply) ++stats_.late;
    }
    if (done) break;
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

}  // namespace piezobench::rt
