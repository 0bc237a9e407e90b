#pragma once
// Socket helpers shared by the UDP backend and `bench serve` (private to src/rt).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>

#include <cerrno>
#include <cstdint>
#include <ctime>

#include "piezobench/rt/timing.hpp"
#include "piezobench/rt/udp.hpp"

namespace piezobench::rt::detail {

inline sockaddr_in to_sockaddr(const UdpAddress& a) {
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_addr.s_addr = a.host;
  sa.sin_port = htons(a.port);
  return sa;
}

// Waits until fd is readable or the CLOCK_MONOTONIC deadline passes; true when readable.
inline bool wait_readable(int fd, std::int64_t deadline_ns) noexcept {
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

}  // namespace piezobench::rt::detail
