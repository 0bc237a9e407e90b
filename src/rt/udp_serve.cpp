#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/rt/timing.hpp"
#include "piezobench/rt/udp_target.hpp"
#include "udp_socket.hpp"

// `piezobench bench serve`: rt::UdpTarget on a socket, driving the virtual bench.
namespace piezobench::rt {


UdpServerReport serve_udp(const bench::UnitTruth& unit, const bench::BenchOptions& options, std::uint64_t seed,
                          const UdpServerOptions& server) {
  const UdpAddress address = parse_udp_address(server.address, "bench serve", "--udp");
  const std::int64_t idle_ns = checked_duration_ns(server.idle_timeout, 1e-3, 1e6, NumberOrigin::file("bench serve", "idle_timeout"));
  bench::VirtualBench bench(unit, options, seed);
  UdpTargetOptions to = server.target;
  to.limits.amplifier_gain = options.amplifier_gain;
  to.limits.va_min = options.va_min;
  to.limits.va_max = options.va_max;
  UdpTarget target({bench.sample_rate(), [&] { bench.reset(seed); }, [&](double u) { return bench.step(u); }}, to);
  if (!address.loopback() && to.key.empty() && server.on_warning) {
    server.on_warning("bench serve on " + address.to_string() +
                      " without a shared key: any host that can reach this port can open a session and drive the "
                      "actuator within the limits (docs/hardware.md \"Threat model\"); give --key-file");
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw InputError("bench serve", "socket", "a UDP socket", std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  sockaddr_in sa = detail::to_sockaddr(address);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0) {
    throw InputError("bench serve", "--udp", "an address this host can listen on", address.to_string() + ": " + std::strerror(errno));
  }
  socklen_t len = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &len);
  if (server.on_listening) server.on_listening(UdpAddress{sa.sin_addr.s_addr, ntohs(sa.sin_port)}.to_string());

  std::int64_t last_activity = monotonic_ns();
  std::uint64_t replies = 0;
  for (;;) {
    if (server.stop != nullptr && server.stop->load()) break;
    if (!detail::wait_readable(fd, monotonic_ns() + 100'000'000)) {
      target.tick(monotonic_ns());
      if (monotonic_ns() - last_activity > idle_ns) break;
      continue;
    }
    unsigned char in[kUdpRequestSize + kUdpTagSize + 8];
    sockaddr_in from{};
    socklen_t from_len = sizeof from;
    const ssize_t n = ::recvfrom(fd, in, sizeof in, 0, reinterpret_cast<sockaddr*>(&from), &from_len);
    if (n < 0) continue;
    last_activity = monotonic_ns();
    const std::uint64_t sessions = target.report().sessions;
    const std::vector<unsigned char> out =
        target.handle(in, static_cast<std::size_t>(n), UdpAddress{from.sin_addr.s_addr, ntohs(from.sin_port)}, last_activity);
    if (!out.empty() && ::sendto(fd, out.data(), out.size(), 0, reinterpret_cast<const sockaddr*>(&from), from_len) >= 0) ++replies;
    if (target.report().sessions > sessions && server.sessions > 0 &&
        target.report().sessions >= static_cast<std::uint64_t>(server.sessions)) {
      break;
    }
  }
  UdpServerReport rep = target.report();
  rep.replies = replies;
  return rep;
}

}  // namespace piezobench::rt
