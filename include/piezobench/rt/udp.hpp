#pragma once
// The network I/O backend: the loop's read/write exchanged as UDP datagrams with a remote I/O
// target (a Speedgoat or dSPACE model with UDP blocks, a microcontroller, `piezobench bench serve`).
// docs/hardware.md "UDP protocol" is the reference for implementers of a target; in short, every
// datagram is little-endian with a fixed layout (version 2):
//
//   request (host -> target), 32 bytes          reply (target -> host), 56 bytes
//     0  u32  magic 0x315A4250 ("PBZ1")           0  u32  magic
//     4  u16  version (2)                          4  u16  version (2)
//     6  u16  type: 1 hello, 3 io, 5 bye, 7 safe,  6  u16  type: 2 hello, 4 io, 6 bye, 10 reset
//             9 reset                              8  u64  sequence (of the request answered)
//     8  u64  sequence (1, 2, ... per session)    16  u64  sample: the target's ADC sample count
//    16  f64  u, V at the DAC (hello: sample      24  f64  de, m (hello: the target's rate, Hz)
//             rate, Hz)                           32  f64  Vs, V
//    24  u32  flags (bit 0: host in safe state)   40  f64  Va, V (NaN: not measured)
//    28  u32  session (0 in a hello; then the     48  u32  status (bit 0 target safe, bit 1 sensor
//             id the hello reply gave)                     fault, bit 2 output limited by the target,
//                                                          bit 3 busy: hello refused)
//                                                  52  u32  session id
// With a shared key (docs/hardware.md "Shared key"), each datagram is followed by its
// HMAC-SHA256 under the key (32 bytes); one without a valid tag is dropped.
//
// An io request sets the DAC to u for the rest of the sample and is answered with the sensors of
// the next sample. The host waits for the answer to its previous request at the start of each cycle
// (up to `timeout`); a reply that does not come in time is a stale input (the safety logic counts
// it and trips after ActuatorLimits::stale_cycles of them), a reply that comes later is counted
// late and dropped, one that never comes is lost. The host checks every reply: its session, its
// sequence and its sample counter (it may not advance by more than the requests sent since the
// previous reply: another host stepping the target is a fault, the safe state). A "safe" request
// (type 7, from the watchdog thread) asks the target to put its output to the safe value at once,
// without waiting for the stalled loop. The target side (sessions, its own limits, the latched
// safe state and its reset) is udp_target.hpp.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "piezobench/rt/backend.hpp"
#include "piezobench/rt/timing.hpp"

namespace piezobench::rt {

inline constexpr std::uint32_t kUdpMagic = 0x315A4250;
inline constexpr std::uint16_t kUdpVersion = 2;
enum class UdpType : std::uint16_t {
  kHello = 1, kHelloReply = 2, kIo = 3, kIoReply = 4, kBye = 5, kByeReply = 6, kSafe = 7, kReset = 9, kResetReply = 10
};
inline constexpr std::uint32_t kUdpStatusTargetSafe = 1u, kUdpStatusSensorFault = 2u, kUdpStatusClamped = 4u,
                               kUdpStatusBusy = 8u;
inline constexpr std::size_t kUdpRequestSize = 32, kUdpReplySize = 56, kUdpTagSize = 32;

struct UdpRequest {
  UdpType type = UdpType::kIo;
  std::uint64_t sequence = 0;
  double u = 0.0;  // V at the DAC
  std::uint32_t flags = 0;
  std::uint32_t session = 0;
};
struct UdpReply {
  UdpType type = UdpType::kIoReply;
  std::uint64_t sequence = 0;
  std::uint64_t sample = 0;
  double de = 0.0, vs = 0.0, va = 0.0;  // m, V, V
  std::uint32_t status = 0;
  std::uint32_t session = 0;
};
// Encoding (little-endian whatever the host) and decoding; decode returns nothing for a datagram of
// the wrong size, magic, version or type.
void encode(const UdpRequest& r, unsigned char (&out)[kUdpRequestSize]) noexcept;
void encode(const UdpReply& r, unsigned char (&out)[kUdpReplySize]) noexcept;
std::optional<UdpRequest> decode_request(const unsigned char* data, std::size_t size) noexcept;
std::optional<UdpReply> decode_reply(const unsigned char* data, std::size_t size) noexcept;

// The shared key: at least 16 bytes (a file's content, trailing white space removed). Empty: none.
// InputError naming `source` and `field` when the file is unreadable or the key shorter.
std::string read_udp_key(const std::filesystem::path& file, const std::string& source, const std::string& field);
// With a key: writes HMAC-SHA256(key, datagram[0, n)) at datagram + n (which must have room for
// kUdpTagSize more bytes) and returns n + kUdpTagSize. Without: returns n.
std::size_t seal(unsigned char* datagram, std::size_t n, const std::string& key) noexcept;
// With a key: the payload's size when the datagram ends in its valid tag, 0 otherwise (compared
// in constant time). Without: n.
std::size_t unseal(const unsigned char* datagram, std::size_t n, const std::string& key) noexcept;

// "HOST:PORT" (IPv4 dotted quad or "localhost") -> InputError naming `field` otherwise.
struct UdpAddress {
  std::uint32_t host = 0;  // network order
  std::uint16_t port = 0;  // host order
  [[nodiscard]] std::string to_string() const;
  [[nodiscard]] bool loopback() const;  // 127.0.0.0/8
  friend bool operator==(const UdpAddress&, const UdpAddress&) = default;
};
UdpAddress parse_udp_address(const std::string& text, const std::string& source, const std::string& field);

struct UdpBackendOptions {
  std::string key;  // shared key (read_udp_key); empty: none
  // Called when the target answers the hello in its latched safe state (a fault of an earlier
  // session): true after the operator confirmed the bench may move (the backend then sends the
  // session's reset). Unset or false: start() refuses the target (InputError).
  std::function<bool(const std::string& target)> confirm_reset;
};

class UdpBackend final : public Backend {
 public:
  // The target at `address`; the loop runs at `sample_rate` (the target must agree: checked by the
  // hello exchange in start()); a reply later than `timeout` s is a stale input.
  UdpBackend(const std::string& address, double sample_rate, double timeout, UdpBackendOptions options = {});
  ~UdpBackend() override;

  [[nodiscard]] std::string name() const override { return "udp"; }
  [[nodiscard]] double sample_rate() const override { return sample_rate_; }
  // Opens the socket and says hello (3 tries, 0.5 s each): InputError when the target does not
  // answer, runs at another rate, serves another host's session (busy), or is in its latched safe
  // state and the reset was not confirmed.
  void start() override;
  // A reply of another session, with a sample counter that went back or advanced by more than
  // the requests sent since the previous reply: NaN sensors (the safe state), counted in `errors`.
  SensorSample read() noexcept override;
  // u: V at the DAC.
  void write(double u) noexcept override;
  // Says bye, waits up to `timeout` for the last replies (counting late ones), closes the socket.
  void stop() noexcept override;
  void on_watchdog() noexcept override;
  [[nodiscard]] IoStats io_stats() const override;

 private:
  bool receive(std::int64_t deadline_ns, std::uint64_t wanted, UdpReply& reply) noexcept;
  bool exchange(UdpType type, UdpType answer, UdpReply& reply);  // hello / reset, 3 tries
  void send_request(const UdpRequest& r) noexcept;
  std::optional<UdpReply> receive_reply() noexcept;  // one datagram, unsealed and decoded
  UdpAddress address_;
  double sample_rate_, timeout_;  // Hz, s
  UdpBackendOptions options_;
  int fd_ = -1;
  std::uint32_t session_ = 0;
  std::uint64_t sent_ = 0, answered_ = 0;  // sequence of the last request sent / answered
  std::uint64_t last_sample_ = 0, last_reply_sequence_ = 0;
  bool counter_fault_ = false;
  std::int64_t sent_ns_ = 0;
  bool safe_ = false;
  SensorSample last_;
  IoStats stats_;
  TimingHistogram rtt_;
};

}  // namespace piezobench::rt
