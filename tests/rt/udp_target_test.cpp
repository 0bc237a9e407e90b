// The target side of the UDP protocol without a socket (rt::UdpTarget): one host's session at a
// time, its own limits, the latched safe state cleared only by a session's reset, the shared key.
#include "piezobench/rt/udp_target.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <vector>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
namespace {

const UdpAddress kHostA{0x0100007F, 40001}, kHostB{0x0100007F, 40002};
constexpr std::int64_t kMs = 1'000'000;

// A target whose "bench" records the commands it was given and answers d_e = u * 1e-6.
struct Fixture {
  std::vector<double> applied;
  int resets = 0;
  UdpTarget target;
  std::int64_t now = 0;
  explicit Fixture(UdpTargetOptions o = {})
      : target({10e3, [this] { ++resets; }, [this](double u) {
                  applied.push_back(u);
                  return bench::BenchSample{1e-6 * u, 0.0, 20.0 * u};
                }},
               [&] {
                 o.seed = 7;
                 return o;
               }()) {}
  std::optional<UdpReply> send(const UdpRequest& q, const UdpAddress& from, const std::string& key = "") {
    unsigned char buf[kUdpRequestSize + kUdpTagSize];
    encode(q, reinterpret_cast<unsigned char(&)[kUdpRequestSize]>(buf));
    const std::size_t n = seal(buf, kUdpRequestSize, key);
    now += kMs;
    const std::vector<unsigned char> out = target.handle(buf, n, from, now);
    if (out.empty()) return std::nullopt;
    const std::size_t payload = unseal(out.data(), out.size(), key);
    EXPECT_GT(payload, 0u) << "a reply without a valid tag";
    return decode_reply(out.data(), payload);
  }
  std::uint32_t hello(const UdpAddress& from, std::uint32_t* status = nullptr) {
    const auto r = send({UdpType::kHello, 0, 10e3, 0, 0}, from);
    EXPECT_TRUE(r);
    if (status != nullptr) *status = r ? r->status : 0;
    return r ? r->session : 0;
  }
};

TEST(UdpTarget, ServesOneHostAtATimeAndRefusesASecondWithBusy) {
  Fixture f;
  const std::uint32_t a = f.hello(kHostA);
  ASSERT_NE(a, 0u);
  for (std::uint64_t k = 1; k <= 3; ++k) {
    const auto r = f.send({UdpType::kIo, k, 0.1, 0, a}, kHostA);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sample, k);
    EXPECT_EQ(r->session, a);
  }
  // Another host (another port of the same machine): busy, and its commands do nothing.
  std::uint32_t status = 0;
  EXPECT_EQ(f.hello(kHostB, &status), 0u);
  EXPECT_EQ(status & kUdpStatusBusy, kUdpStatusBusy);
  EXPECT_FALSE(f.send({UdpType::kIo, 4, 7.5, 0, a}, kHostB));   // the right id from the wrong host
  EXPECT_FALSE(f.send({UdpType::kIo, 4, 7.5, 0, 0}, kHostB));
  EXPECT_FALSE(f.send({UdpType::kBye, 5, 0.0, 0, a}, kHostB));
  EXPECT_FALSE(f.send({UdpType::kIo, 4, 0.1, 0, a + 1}, kHostA));  // the right host, another id
  EXPECT_EQ(f.applied.size(), 3u);
  EXPECT_EQ(f.resets, 1);  // the refused hello did not reset the bench
  // The session goes on where it was.
  const auto r = f.send({UdpType::kIo, 4, 0.1, 0, a}, kHostA);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->sample, 4u);
  EXPECT_EQ(f.target.report().refused, 1u);
  EXPECT_EQ(f.target.report().rejected, 4u);
  // A replayed (old) sequence is dropped.
  EXPECT_FALSE(f.send({UdpType::kIo, 2, 0.1, 0, a}, kHostA));
  // After the bye, B may open its session.
  ASSERT_TRUE(f.send({UdpType::kBye, 5, 0.0, 0, a}, kHostA));
  EXPECT_NE(f.hello(kHostB), 0u);
}

TEST(UdpTarget, EnforcesItsOwnVoltageAndSlewLimits) {
  Fixture f;  // APA300ML behind 20 V/V: u in [-1, 7.5] V, 0.5 V per sample at 10 kHz
  const std::uint32_t a = f.hello(kHostA);
  auto r = f.send({UdpType::kIo, 1, 1e300, 0, a}, kHostA);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status & kUdpStatusClamped, kUdpStatusClamped);
  EXPECT_DOUBLE_EQ(f.applied.back(), 0.5);  // 10 V at the stacks, not 150 V in one sample
  for (std::uint64_t k = 2; k <= 40; ++k) r = f.send({UdpType::kIo, k, 1e300, 0, a}, kHostA);
  EXPECT_DOUBLE_EQ(f.applied.back(), 7.5);  // 150 V, never above
  r = f.send({UdpType::kIo, 41, std::nan(""), 0, a}, kHostA);
  EXPECT_DOUBLE_EQ(f.applied.back(), 7.5);
  r = f.send({UdpType::kIo, 42, -50.0, 0, a}, kHostA);
  EXPECT_DOUBLE_EQ(f.applied.back(), 7.0);
  for (std::size_t k = 1; k < f.applied.size(); ++k) {
    EXPECT_LE(std::abs(f.applied[k] - f.applied[k - 1]), 0.5 + 1e-12) << k;
    EXPECT_LE(f.applied[k], 7.5);
    EXPECT_GE(f.applied[k], -1.0);
  }
  EXPECT_EQ(f.target.report().limited, 42u);
}

TEST(UdpTarget, ALatchedSafeStateIsClearedOnlyByASessionsReset) {
  Fixture f;
  std::uint32_t a = f.hello(kHostA);
  for (std::uint64_t k = 1; k <= 20; ++k) f.send({UdpType::kIo, k, 7.5, 0, a}, kHostA);
  EXPECT_DOUBLE_EQ(f.applied.back(), 7.5);
  EXPECT_FALSE(f.send({UdpType::kSafe, 0, 0.0, 1, a}, kHostA));  // the host's watchdog
  auto r = f.send({UdpType::kIo, 21, 7.5, 0, a}, kHostA);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status & kUdpStatusTargetSafe, kUdpStatusTargetSafe);
  EXPECT_DOUBLE_EQ(f.applied.back(), 7.0);  // to the safe value at the slew limit, not in one jump
  ASSERT_TRUE(f.send({UdpType::kBye, 22, 0.0, 0, a}, kHostA));
  // A hello (from anyone) does not clear it: issue 35's "hello from another port".
  std::uint32_t status = 0;
  const std::uint32_t b = f.hello(kHostB, &status);
  EXPECT_EQ(status & kUdpStatusTargetSafe, kUdpStatusTargetSafe);
  r = f.send({UdpType::kIo, 1, 7.5, 0, b}, kHostB);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status & kUdpStatusTargetSafe, kUdpStatusTargetSafe);
  EXPECT_DOUBLE_EQ(f.applied.back(), 0.0);  // the bench restarted at the safe value and stays there
  // Only this session's reset clears it (another host's is dropped).
  EXPECT_FALSE(f.send({UdpType::kReset, 0, 0.0, 0, b}, kHostA));
  r = f.send({UdpType::kReset, 0, 0.0, 0, b}, kHostB);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->type, UdpType::kResetReply);
  EXPECT_EQ(r->status & kUdpStatusTargetSafe, 0u);
  r = f.send({UdpType::kIo, 1, 7.5, 0, b}, kHostB);
  EXPECT_DOUBLE_EQ(f.applied.back(), 0.5);
  EXPECT_EQ(f.target.report().safe_reason, "the host's watchdog asked for it");
}

TEST(UdpTarget, ASilentSessionEndsAndLatchesTheSafeStateAfterItsFirstCommand) {
  UdpTargetOptions o;
  o.session_timeout = 0.5;
  Fixture f(o);
  const std::uint32_t a = f.hello(kHostA);
  f.send({UdpType::kIo, 1, 0.1, 0, a}, kHostA);
  f.target.tick(f.now + 400 * kMs);
  EXPECT_TRUE(f.target.session_open());
  f.target.tick(f.now + 600 * kMs);  // the host died mid-run
  EXPECT_FALSE(f.target.session_open());
  EXPECT_TRUE(f.target.report().target_safe);
  EXPECT_EQ(f.target.report().expired, 1u);
  // A session that never moved anything just ends.
  Fixture g(o);
  g.hello(kHostA);
  g.target.tick(g.now + 600 * kMs);
  EXPECT_FALSE(g.target.session_open());
  EXPECT_FALSE(g.target.report().target_safe);
}

TEST(UdpTarget, WithAKeyOnlySealedDatagramsCount) {
  const std::string key = "a-shared-key-of-32-bytes-for-lab";
  UdpTargetOptions o;
  o.key = key;
  Fixture f(o);
  EXPECT_FALSE(f.send({UdpType::kHello, 0, 10e3, 0, 0}, kHostA));         // no tag
  EXPECT_FALSE(f.send({UdpType::kHello, 0, 10e3, 0, 0}, kHostA, "wrong-key-wrong-key"));
  const auto r = f.send({UdpType::kHello, 0, 10e3, 0, 0}, kHostA, key);  // the reply's tag is checked in send()
  ASSERT_TRUE(r);
  EXPECT_NE(r->session, 0u);
  EXPECT_EQ(f.target.report().rejected, 2u);
  // A tag of the key over other bytes: rejected. HMAC-SHA256 of RFC 4231 test case 2 checks seal().
  unsigned char msg[28 + kUdpTagSize];
  std::memcpy(msg, "what do ya want for nothing?", 28);
  ASSERT_EQ(seal(msg, 28, "Jefe"), 28 + kUdpTagSize);
  const unsigned char expected[] = {0x5b, 0xdc, 0xc1, 0x46, 0xbf, 0x60, 0x75, 0x4e, 0x6a, 0x04, 0x24, 0x26, 0x08, 0x95, 0x75, 0xc7,
                                    0x5a, 0x00, 0x3f, 0x08, 0x9d, 0x27, 0x39, 0x83, 0x9d, 0xec, 0x58, 0xb9, 0x64, 0xec, 0x38, 0x43};
  EXPECT_EQ(std::memcmp(msg + 28, expected, 32), 0);
  EXPECT_EQ(unseal(msg, sizeof msg, "Jefe"), 28u);
  msg[3] ^= 1;
  EXPECT_EQ(unseal(msg, sizeof msg, "Jefe"), 0u);
}

TEST(UdpKey, IsReadFromAFileAndMustBeLongEnough) {
  test::TempDir dir;
  const auto file = dir.path() / "bench.key";
  std::ofstream(file) << "0123456789abcdef0123\n";
  EXPECT_EQ(read_udp_key(file, "b.toml", "udp.key_file"), "0123456789abcdef0123");
  std::ofstream(file) << "short\n";
  test::input_error([&] { (void)read_udp_key(file, "b.toml", "udp.key_file"); }, "udp.key_file");
  test::input_error([&] { (void)read_udp_key(dir.path() / "none", "b.toml", "udp.key_file"); }, "udp.key_file");
}

}  // namespace
}  // namespace piezobench::rt
