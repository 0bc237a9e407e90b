// The UDP protocol and backend against `serve_udp` on loopback (in a thread of this process; the
// two-process runs are in tests/app/measure_cli_test.cpp): the wire layout, the loop over UDP equal
// to the in-process virtual bench, lost replies as stale inputs, the watchdog's safe request.
#include "piezobench/rt/udp.hpp"

#include <gtest/gtest.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>

#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/rt/loop.hpp"
#include "piezobench/rt/udp_target.hpp"
#include "piezobench/rt/virtual_backend.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
namespace {

TEST(UdpProtocol, EncodesLittleEndianFixedLayouts) {
  unsigned char req[kUdpRequestSize];
  encode(UdpRequest{UdpType::kIo, 0x0102030405060708ULL, 1.5, 1u}, req);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(req), 4), "PBZ1");
  EXPECT_EQ(req[4], 2);  // version
  EXPECT_EQ(req[6], 3);  // io
  EXPECT_EQ(req[8], 0x08);
  EXPECT_EQ(req[15], 0x01);
  EXPECT_EQ(req[23], 0x3F);  // 1.5 = 0x3FF8000000000000, most significant byte last
  EXPECT_EQ(req[22], 0xF8);
  const auto r = decode_request(req, sizeof req);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->sequence, 0x0102030405060708ULL);
  EXPECT_EQ(r->u, 1.5);
  EXPECT_EQ(r->flags, 1u);

  unsigned char rep[kUdpReplySize];
  encode(UdpReply{UdpType::kIoReply, 7, 9, -1e-6, 0.25, std::nan(""), kUdpStatusClamped}, rep);
  const auto p = decode_reply(rep, sizeof rep);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->sequence, 7u);
  EXPECT_EQ(p->sample, 9u);
  EXPECT_EQ(p->de, -1e-6);
  EXPECT_EQ(p->vs, 0.25);
  EXPECT_TRUE(std::isnan(p->va));
  EXPECT_EQ(p->status, kUdpStatusClamped);
  // Wrong size, magic or version: not a datagram of the protocol.
  EXPECT_FALSE(decode_reply(rep, sizeof rep - 1));
  rep[0] ^= 1;
  EXPECT_FALSE(decode_reply(rep, sizeof rep));
  EXPECT_FALSE(decode_request(req, sizeof req + 1));
}

TEST(UdpProtocol, ParsesAddresses) {
  const UdpAddress a = parse_udp_address("127.0.0.1:5600", "test", "address");
  EXPECT_EQ(a.port, 5600);
  EXPECT_EQ(a.to_string(), "127.0.0.1:5600");
  EXPECT_EQ(parse_udp_address("localhost:0", "test", "address").to_string(), "127.0.0.1:0");
  for (const char* bad : {"127.0.0.1", "host:5600", "127.0.0.1:70000", "127.0.0.1:"}) {
    EXPECT_THROW(parse_udp_address(bad, "test", "address"), InputError) << bad;
  }
}

// serve_udp on 127.0.0.1:<free port> in a thread, stopped at destruction.
class Server {
 public:
  explicit Server(std::uint64_t drop_every = 0, double rate = 10e3) {
    UdpServerOptions o;
    o.address = "127.0.0.1:0";
    o.target.drop_every = drop_every;
    o.stop = &stop_;
    o.idle_timeout = 30.0;
    o.on_listening = [this](const std::string& a) {
      std::lock_guard<std::mutex> lock(mutex_);
      address_ = a;
      cv_.notify_all();
    };
    bench::BenchOptions bo;
    bo.sample_rate = rate;
    thread_ = std::thread([this, o, bo] { report_ = serve_udp(bench::batch_unit(1, 3), bo, 3, o); });
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [this] { return !address_.empty(); });
  }
  ~Server() { join(); }
  const UdpServerReport& join() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    return report_;
  }
  [[nodiscard]] std::string address() const { return address_; }

 private:
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::condition_variable cv_;
  std::string address_;
  std::thread thread_;
  UdpServerReport report_;
};

LoopOptions iff_options(double duration) {
  LoopOptions lo;
  lo.duration = duration;
  lo.realtime = false;
  lo.gain = 280000.0;
  lo.keep_log = true;
  lo.excitation = Eigen::VectorXd::Zero(1000);
  for (Eigen::Index k = 0; k < 1000; ++k) lo.excitation(k) = 0.1 * std::sin(2.0 * 3.14159265358979 * 95.0 * k / 1e4);
  return lo;
}

TEST(UdpBackend, TheLoopOverUdpIsTheLoopOnTheVirtualBench) {
  Server server;
  UdpBackend udp(server.address(), 10e3, 0.5);
  io::TimeSeries remote, local;
  const LoopReport r = run_loop(udp, iff_options(0.5), &remote);
  VirtualBenchBackend virt(bench::batch_unit(1, 3), bench::BenchOptions{}, 3);
  run_loop(virt, iff_options(0.5), &local);
  ASSERT_EQ(remote.samples(), local.samples());
  // The served bench is stepped by the datagrams as the in-process one by the loop: the same run.
  for (const char* ch : {"u", "de", "Vs", "Va"}) {
    EXPECT_EQ((remote.channel(ch) - local.channel(ch)).cwiseAbs().maxCoeff(), 0.0) << ch;
  }
  EXPECT_EQ(r.safe_state_reason, "none");
  EXPECT_EQ(r.io.lost, 0u);
  EXPECT_EQ(r.io.late, 0u);
  EXPECT_EQ(r.io.timeouts, 0u);
  EXPECT_EQ(r.io.replies, r.io.exchanges);
  EXPECT_EQ(r.io.round_trip_us.count, r.cycles);
  const UdpServerReport& s = server.join();
  EXPECT_EQ(s.sessions, 1u);
  EXPECT_EQ(s.requests, r.io.exchanges);
}

TEST(UdpBackend, LostRepliesAreStaleInputs) {
  {
    // Every 500th reply lost: each one a stale input, counted lost, tolerated (stale_cycles = 3).
    Server server(500);
    UdpBackend udp(server.address(), 10e3, 50e-3);  // long enough that only the dropped replies miss it
    const LoopReport r = run_loop(udp, iff_options(0.3));
    EXPECT_EQ(r.safe_state_reason, "none");
    EXPECT_EQ(r.io.lost, r.io.exchanges / 500);
    EXPECT_EQ(r.io.timeouts, r.io.lost);
    EXPECT_EQ(r.stale_sensor_samples, r.io.lost);
  }
  {
    // No reply at all: the fourth stale read trips the safe state.
    Server server(1);
    UdpBackend udp(server.address(), 10e3, 1e-3);
    LoopOptions lo = iff_options(0.02);
    const LoopReport r = run_loop(udp, lo);
    EXPECT_EQ(r.safe_state_reason, "stale sensor");
    EXPECT_EQ(r.safe_state_cycle, 4);  // cycle 0 has nothing to compare with; 1..3 tolerated
  }
}

TEST(UdpBackend, TheWatchdogAsksTheTargetForItsSafeState) {
  Server server;
  UdpBackend udp(server.address(), 10e3, 0.5);
  udp.start();
  udp.write(0.0);
  EXPECT_TRUE(std::isfinite(udp.read().vs));
  udp.on_watchdog();  // from the watchdog thread: straight to the target
  udp.write(1.0);
  const SensorSample s = udp.read();
  EXPECT_TRUE(std::isnan(s.de));  // the target says it is safe: the loop's safe state follows
  udp.stop();
  EXPECT_TRUE(server.join().target_safe);
}

TEST(UdpBackend, RefusesATargetAtAnotherRateOrNone) {
  {
    Server server(0, 5e3);
    UdpBackend udp(server.address(), 10e3, 0.01);
    try {
      udp.start();
      FAIL() << "no error";
    } catch (const InputError& e) {
      EXPECT_TRUE(test::contains(e.what(), "sample rate")) << e.what();
      EXPECT_TRUE(test::contains(e.what(), "5000 Hz")) << e.what();
    }
  }
  UdpBackend nobody("127.0.0.1:9", 10e3, 0.01);  // discard port: nothing answers
  EXPECT_THROW(nobody.start(), InputError);
}

TEST(UdpBackend, ATargetInItsLatchedSafeStateNeedsTheOperatorsReset) {
  Server server;
  {
    UdpBackend udp(server.address(), 10e3, 0.5);
    udp.start();
    udp.write(1.0);
    (void)udp.read();
    udp.on_watchdog();  // latched on the target
    udp.stop();
  }
  UdpBackend refused(server.address(), 10e3, 0.5);
  const std::string e = test::input_error([&] { refused.start(); }, "safe state");
  EXPECT_TRUE(test::contains(e, "--reset-target")) << e;  // and the refused session was closed (bye)
  UdpBackendOptions o;
  std::string asked;
  o.confirm_reset = [&asked](const std::string& target) {
    asked = target;
    return true;  // the operator pressed Enter
  };
  UdpBackend confirmed(server.address(), 10e3, 0.5, o);
  confirmed.start();
  EXPECT_TRUE(test::contains(asked, server.address())) << asked;
  confirmed.write(0.5);
  EXPECT_TRUE(std::isfinite(confirmed.read().de));  // moving again
  confirmed.stop();
}

// A target whose sample counter advances by two per request (another host stepping it, or a
// broken target): the host's check trips the safe state at the first reply.
TEST(UdpBackend, ASampleCounterThatJumpsIsAFault) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa), 0);
  socklen_t len = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &len);
  std::atomic<bool> done{false};
  std::thread liar([&] {
    while (!done.load()) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      unsigned char in[64];
      sockaddr_in from{};
      socklen_t from_len = sizeof from;
      const ssize_t n = ::recvfrom(fd, in, sizeof in, 0, reinterpret_cast<sockaddr*>(&from), &from_len);
      const auto q = decode_request(in, static_cast<std::size_t>(n));
      if (!q) continue;
      UdpReply r;
      r.sequence = q->sequence;
      r.session = 77;
      r.type = q->type == UdpType::kHello ? UdpType::kHelloReply : q->type == UdpType::kBye ? UdpType::kByeReply : UdpType::kIoReply;
      if (q->type == UdpType::kHello) r.de = 10e3;
      r.sample = 2 * q->sequence;
      unsigned char out[kUdpReplySize];
      encode(r, out);
      ::sendto(fd, out, sizeof out, 0, reinterpret_cast<sockaddr*>(&from), from_len);
    }
  });
  UdpBackend udp("127.0.0.1:" + std::to_string(ntohs(sa.sin_port)), 10e3, 0.5);
  udp.start();
  udp.write(0.1);
  const SensorSample s = udp.read();
  EXPECT_TRUE(std::isnan(s.de));
  EXPECT_EQ(udp.io_stats().errors, 1u);
  udp.stop();
  done = true;
  liar.join();
  ::close(fd);
}

}  // namespace
}  // namespace piezobench::rt
