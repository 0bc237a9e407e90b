#pragma once
// The network I/O backend: the loop's read/write exchanged as UDP datagrams with a remote I/O
// target (a Speedgoat or dSPACE model with UDP blocks, a microcontroller, `piezobench bench serve`).
// docs/hardware.md "UDP protocol" is the reference for implementers of a target; in short, every
// datagram is little-endian with a fixed layout:
//
//   request (host -> target), 32 bytes          reply (target -> host), 56 bytes
//     0  u32  magic 0x315A4250 ("PBZ1")           0  u32  magic
//     4  u16  version (1)                          4  u16  version (1)
//     6  u16  type: 1 hello, 3 io, 5 bye, 7 safe   6  u16  type: 2 hello, 4 io, 6 bye
//     8  u64  sequence (1, 2, ... per session)     8  u64  sequence (of the request answered)
//    16  f64  u, V at the DAC (hello: sample      16  u64  sample: the target's ADC sample count
//             rate, Hz)                            24  f64  de, m (hello: the target's rate, Hz)
//    24  u32  flags (bit 0: host in safe state)    32  f64  Vs, V
//    28  u32  reserved (0)                         40  f64  Va, V (NaN: not measured)
//                                                  48  u32  status (bit 0 target safe, bit 1 sensor
//                                                           fault, bit 2 output clamped)
//                                                  52  u32  reserved (0)
//
// An io request sets the DAC to u for the rest of the sample and is answered with the sensors of
// the next sample. The host waits for the answer to its previous request at the start of each cycle
// (up to `timeout`); a reply that does not come in time is a stale input (the safety logic counts
// it and trips after ActuatorLimits::stale_cycles of them), a reply that comes later is counted
// late and dropped, one that never comes is lost. A "safe" request (type 7, from the watchdog
// thread) asks the target to put its output to the safe value at once, without waiting for the
// stalled loop.
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/rt/backend.hpp"

namespace piezobench::rt {

inline constexpr std::uint32_t kUdpMagic = 0x315A4250;
inline constexpr std::uint16_t kUdpVersion = 1;
enum class UdpType : std::uint16_t { kHello = 1, kHelloReply = 2, kIo = 3, kIoReply = 4, kBye = 5, kByeReply = 6, kSafe = 7 };
inline constexpr std::uint32_t kUdpStatusTargetSafe = 1u, kUdpStatusSensorFault = 2u, kUdpStatusClamped = 4u;
inline constexpr std::size_t kUdpRequestSize = 32, kUdpReplySize = 56;

struct UdpRequest {
  UdpType type = UdpType::kIo;
  std::uint64_t sequence = 0;
  double u = 0.0;
  std::uint32_t flags = 0;
};
struct UdpReply {
  UdpType type = UdpType::kIoReply;
  std::uint64_t sequence = 0;
  std::uint64_t sample = 0;
  double de = 0.0, vs = 0.0, va = 0.0;
  std::uint32_t status = 0;
};
// Encoding (little-endian whatever the host) and decoding; decode returns nothing for a datagram of
// the wrong size, magic, version or type.
void encode(const UdpRequest& r, unsigned char (&out)[kUdpRequestSize]) noexcept;
void encode(const UdpReply& r, unsigned char (&out)[kUdpReplySize]) noexcept;
std::optional<UdpRequest> decode_request(const unsigned char* data, std::size_t size) noexcept;
std::optional<UdpReply> decode_reply(const unsigned char* data, std::size_t size) noexcept;

// "HOST:PORT" (IPv4 dotted quad or "localhost") -> InputError naming `field` otherwise.
struct UdpAddress {
  std::uint32_t host = 0;  // network order
  std::uint16_t port = 0;  // host order
  [[nodiscard]] std::string to_string() const;
};
UdpAddress parse_udp_address(const std::string& text, const std::string& source, const std::string& field);

class UdpBackend final : public Backend {
 public:
  // The target at `address`; the loop runs at `sample_rate` (the target must agree: checked by the
  // hello exchange in start()); a reply later than `timeout` s is a stale input.
  UdpBackend(const std::string& address, double sample_rate, double timeout);
  ~UdpBackend() override;

  [[nodiscard]] std::string name() const override { return "udp"; }
  [[nodiscard]] double sample_rate() const override { return sample_rate_; }
  // Opens the socket and says hello (3 tries, 0.5 s each): InputError when the target does not
  // answer or runs at another rate.
  void start() override;
  SensorSample read() noexcept override;
  void write(double u) noexcept override;
  // Says bye, waits up to `timeout` for the last replies (counting late ones), closes the socket.
  void stop() noexcept override;
  void on_watchdog() noexcept override;
  [[nodiscard]] IoStats io_stats() const override;

 private:
  bool receive(std::int64_t deadline_ns, std::uint64_t wanted, UdpReply& reply) noexcept;
  UdpAddress address_;
  double sample_rate_, timeout_;
  int fd_ = -1;
  std::uint64_t sent_ = 0, answered_ = 0;  // sequence of the last request sent / answered
  std::int64_t sent_ns_ = 0;
  bool safe_ = false;
  SensorSample last_;
  IoStats stats_;
  TimingHistogram rtt_;
};

// `piezobench bench serve`: the virtual bench behind the UDP protocol. One client at a time; a hello
// resets the bench (same seed, same session). Runs until `sessions` byes have been answered (0: no
// limit), `idle_timeout` s pass without a datagram, or `stop` becomes true.
struct UdpServerOptions {
  std::string address = "127.0.0.1:5600";  // port 0: any free port (see on_listening)
  int sessions = 0;
  double idle_timeout = 60.0;               // s
  std::uint64_t drop_every = 0;             // tests: leave every N-th io request unanswered (0: none)
  const std::atomic<bool>* stop = nullptr;
  std::function<void(const std::string&)> on_listening;  // called with "HOST:PORT" once bound
};
struct UdpServerReport {
  std::uint64_t sessions = 0, requests = 0, replies = 0, dropped = 0, rejected = 0;
  bool target_safe = false;  // a safe request was received in the last session
};
UdpServerReport serve_udp(const bench::UnitTruth& unit, const bench::BenchOptions& options, std::uint64_t seed,
                          const UdpServerOptions& server);

}  // namespace piezobench::rt
