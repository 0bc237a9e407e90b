#pragma once
// The target side of the UDP protocol (udp.hpp; docs/hardware.md "UDP protocol" and "Threat model"):
// one host's session at a time, the target's own limits, a latched safe state.
//
//   - A hello from a host starts a session bound to that host's address and port and to a session
//     id the reply gives (the host puts it in every request). A hello from another host while a
//     session is open is refused with status bit 3 (busy); io, safe, reset and bye datagrams that
//     are not the session's (another sender, another id, an old sequence) are dropped and counted.
//     A session ends with the host's bye, or when the host has been silent for session_timeout.
//   - Every command goes through the target's own SafetyGuard (clamp to [va_min, va_max] and the
//     slew limit, whatever the host asks): reply status bit 2 when it limited one.
//   - The safe state is latched by the session's "safe" request (the host's watchdog) or by a
//     session that went silent after its first io (the host died mid-run): the output ramps to
//     the safe value at the slew limit and stays there, every reply says so (bit 0), across
//     sessions, until the session that finds it sends a reset (the host does so only after its
//     operator confirmed). A hello never clears it.
//   - With a key, a datagram without its valid HMAC-SHA256 tag is dropped, and each reply is
//     tagged.
#include <atomic>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/rt/safety.hpp"
#include "piezobench/rt/udp.hpp"

namespace piezobench::rt {

// What a target drives: its rate, a reset to the start (a hello, a reset) and one sample with the
// DAC at u (V at the DAC) that returns the sensors of the next sample.
struct UdpTargetIo {
  double sample_rate = 10e3;  // Hz
  std::function<void()> reset;
  // u: V at the DAC.
  std::function<bench::BenchSample(double u)> step;
};

struct UdpTargetOptions {
  ActuatorLimits limits;         // the target's own limits (the bench's)
  std::string key;               // shared key (read_udp_key); empty: none
  double session_timeout = 10.0; // s of silence that ends a session
  std::uint64_t drop_every = 0;  // tests: leave every N-th io request of a session unanswered (0: none)
  std::uint64_t seed = 0;        // of the session ids (0: from std::random_device)
};

struct UdpServerReport {
  std::uint64_t sessions = 0, requests = 0, replies = 0, dropped = 0, rejected = 0;
  std::uint64_t refused = 0;         // hellos refused: another host's session was open
  std::uint64_t limited = 0;         // io commands the target's own limits changed
  std::uint64_t expired = 0;         // sessions ended by silence
  bool target_safe = false;          // the safe state is latched now
  std::string safe_reason;           // why it was latched last ("" if never)
};

// The protocol's target, without a socket: handle() takes one datagram and gives the reply.
// Not thread-safe (one server thread).
class UdpTarget {
 public:
  // Validates the limits (InputError) and needs io.reset and io.step.
  UdpTarget(UdpTargetIo io, UdpTargetOptions options);

  // One datagram of `size` bytes from `from` at `now_ns` (CLOCK_MONOTONIC): the bytes to send back
  // to `from` (empty: no reply). Never throws.
  std::vector<unsigned char> handle(const unsigned char* data, std::size_t size, const UdpAddress& from,
                                    std::int64_t now_ns) noexcept;
  // Ends a session silent for session_timeout (latching the safe state after its first io).
  void tick(std::int64_t now_ns) noexcept;

  [[nodiscard]] const UdpServerReport& report() const noexcept { return report_; }
  [[nodiscard]] bool session_open() const noexcept { return open_; }
  [[nodiscard]] double last_output() const noexcept { return guard_.last_output(); }  // V at the DAC

 private:
  std::vector<unsigned char> reply(const UdpReply& r) const;
  std::vector<unsigned char> hello(const UdpRequest& q, const UdpAddress& from, std::int64_t now_ns);
  std::vector<unsigned char> io(const UdpRequest& q);
  void latch(const std::string& reason) noexcept;
  void restart();
  void end_session() noexcept;
  [[nodiscard]] std::uint32_t status() const noexcept;

  UdpTargetIo io_;
  UdpTargetOptions options_;
  SafetyGuard guard_;
  std::mt19937_64 ids_;
  UdpServerReport report_;
  bool open_ = false;
  UdpAddress peer_;
  std::uint32_t session_ = 0;
  std::uint64_t sample_ = 0, io_requests_ = 0, last_sequence_ = 0;
  std::int64_t last_seen_ns_ = 0;
};

// `piezobench bench serve`: the virtual bench behind the protocol (a UdpTarget on a socket; a
// session's hello resets the bench: same seed, same run). Runs until `sessions` byes have been
// answered (0: no limit), `idle_timeout` s pass without a datagram, or `stop` becomes true.
struct UdpServerOptions {
  std::string address = "127.0.0.1:5600";  // port 0: any free port (see on_listening)
  int sessions = 0;
  double idle_timeout = 60.0;               // s
  UdpTargetOptions target;                  // limits (amplifier gain and range: the bench's), key, ...
  const std::atomic<bool>* stop = nullptr;
  std::function<void(const std::string&)> on_listening;  // called with "HOST:PORT" once bound
  std::function<void(const std::string&)> on_warning;    // a non-loopback address without a key
};
UdpServerReport serve_udp(const bench::UnitTruth& unit, const bench::BenchOptions& options, std::uint64_t seed,
                          const UdpServerOptions& server);

}  // namespace piezobench::rt
