// libFuzzer target of the UDP protocol's target side (rt::UdpTarget, what `bench serve` runs on
// each datagram; docs/fuzzing.md). The input is a run of datagrams from up to four hosts:
//
//   byte 0: bit 0 set = the target has a shared key (and the hosts' datagrams are sealed with it
//           when bit 1 of a record's host byte is set)
//   then records: [host byte: bits 0-1 host, bit 2 seal, bits 3-7 time step][length byte][length
//           bytes of datagram]; a request whose session field is 0xFFFFFFFF gets the id the host's
//           last hello reply gave (so the seeds of scripts/fuzz/make_udp_seeds.py reach sessions)
//
// Besides the sanitizers, the target's safety contract is checked after every datagram: the
// command it applied stays within [u_min, u_max] and moves by at most the slew limit per sample,
// a reply is 0, 56 or 56 + 32 bytes, at most one session is open. A violation aborts (a finding).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "piezobench/rt/udp_target.hpp"

namespace {

void require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "udp_target fuzz: contract broken: %s\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace piezobench::rt;
  if (size < 1) return 0;
  const bool keyed = (data[0] & 1u) != 0;
  const std::string key = "0123456789abcdef-fuzz-key";
  UdpTargetOptions options;
  options.seed = 1;
  options.session_timeout = 1.0;
  if (keyed) options.key = key;
  const ActuatorLimits& l = options.limits;
  const double rate = 10e3, step_max = l.max_step(rate) * (1.0 + 1e-12) + 1e-15;
  double applied = l.u_safe(), previous = l.u_safe();
  bool stepped = false;
  UdpTarget target({rate, [&] { previous = applied = l.u_safe(); }, [&](double u) {
                      previous = applied;
                      applied = u;
                      stepped = true;
                      return piezobench::bench::BenchSample{1e-6 * u, 0.1 * u, 20.0 * u};
                    }},
                   options);
  std::int64_t now = 0;
  std::uint32_t sessions[4] = {};
  std::size_t i = 1;
  while (i + 2 <= size) {
    const std::uint8_t host = data[i];
    const std::size_t n = data[i + 1];
    i += 2;
    if (i + n > size) break;
    std::vector<unsigned char> datagram(data + i, data + i + n);
    i += n;
    if (n == kUdpRequestSize && datagram[28] == 0xFF && datagram[29] == 0xFF && datagram[30] == 0xFF && datagram[31] == 0xFF) {
      for (int b = 0; b < 4; ++b) datagram[28 + b] = static_cast<unsigned char>(sessions[host & 3u] >> (8 * b));
    }
    if (keyed && (host & 4u) != 0) {
      datagram.resize(n + kUdpTagSize);
      datagram.resize(seal(datagram.data(), n, key));
    }
    const UdpAddress from{0x0100007F, static_cast<std::uint16_t>(40000 + (host & 3u))};
    // 0.1 ms .. 3.1 ms between datagrams, or 2 s (step 31: longer than the session time-out)
    now += (host >> 3) == 31 ? 2'000'000'000 : 100'000 * (1 + (host >> 3));
    stepped = false;
    const std::vector<unsigned char> reply = target.handle(datagram.data(), datagram.size(), from, now);
    require(reply.empty() || reply.size() == kUdpReplySize + (keyed ? kUdpTagSize : 0), "reply size");
    if (!reply.empty()) {
      const std::size_t payload = unseal(reply.data(), reply.size(), options.key);
      require(payload == kUdpReplySize, "a reply without its valid tag");
      const auto r = decode_reply(reply.data(), payload);
      require(r.has_value(), "a reply that does not decode");
      if (r->type == UdpType::kHelloReply) sessions[host & 3u] = r->session;
    }
    if (stepped) {
      require(applied >= l.u_min() && applied <= l.u_max(), "command outside [u_min, u_max]");
      require(std::abs(applied - previous) <= step_max, "command faster than the slew limit");
    }
  }
  return 0;
}
