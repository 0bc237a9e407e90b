#include "piezobench/rt/udp_target.hpp"

#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::rt {

UdpTarget::UdpTarget(UdpTargetIo io, UdpTargetOptions options)
    : io_(std::move(io)),
      options_(std::move(options)),
      guard_(options_.limits, io_.sample_rate),
      ids_(options_.seed != 0 ? options_.seed : (static_cast<std::uint64_t>(std::random_device{}()) << 32) ^ std::random_device{}()) {
  if (!io_.reset || !io_.step) throw InputError("udp target", "io", "a reset and a step", "none");
  checked_duration_s(options_.session_timeout, 1e-3, 3600.0, NumberOrigin::file("udp target", "session_timeout"));
}

std::vector<unsigned char> UdpTarget::reply(const UdpReply& r) const {
  std::vector<unsigned char> out(kUdpReplySize + kUdpTagSize);
  encode(r, *reinterpret_cast<unsigned char(*)[kUdpReplySize]>(out.data()));
  out.resize(seal(out.data(), kUdpReplySize, options_.key));
  return out;
}

std::uint32_t UdpTarget::status() const noexcept { return report_.target_safe ? kUdpStatusTargetSafe : 0u; }

void UdpTarget::latch(const std::string& reason) noexcept {
  guard_.trip(Fault::kInterrupted, sample_);
  report_.target_safe = true;
  report_.safe_reason = reason;
}

void UdpTarget::restart() {
  // The bench back to its start, its output at the safe value: the limits' state follows it (so
  // the next command moves from there at the slew limit); a latched safe state stays latched.
  io_.reset();
  sample_ = io_requests_ = last_sequence_ = 0;
  guard_ = SafetyGuard(options_.limits, io_.sample_rate);
  if (report_.target_safe) guard_.trip(Fault::kInterrupted, 0);
}

void UdpTarget::end_session() noexcept {
  open_ = false;
  session_ = 0;
}

void UdpTarget::tick(std::int64_t now_ns) noexcept {
  if (!open_ || now_ns - last_seen_ns_ <= static_cast<std::int64_t>(options_.session_timeout * 1e9)) return;
  // The host went silent: after its first io it died mid-run, so the output goes safe and stays.
  if (io_requests_ > 0) latch("the session's host went silent mid-run");
  ++report_.expired;
  end_session();
}

std::vector<unsigned char> UdpTarget::hello(const UdpRequest& q, const UdpAddress& from, std::int64_t now_ns) {
  UdpReply r;
  r.type = UdpType::kHelloReply;
  r.sequence = q.sequence;
  r.de = io_.sample_rate;
  if (open_ && !(from == peer_)) {
    ++report_.refused;  // one host at a time: the open session is left alone
    r.status = kUdpStatusBusy | status();
    return reply(r);
  }
  // A new session (or the same host again: its hello reply may have been lost). The bench goes
  // back to its start; a latched safe state stays latched (only a reset clears it).
  if (!open_ || io_requests_ > 0) {
    open_ = true;
    peer_ = from;
    do {
      session_ = static_cast<std::uint32_t>(ids_());
    } while (session_ == 0);
    restart();
  }
  last_seen_ns_ = now_ns;
  r.session = session_;
  r.status = status();
  return reply(r);
}

std::vector<unsigned char> UdpTarget::io(const UdpRequest& q) {
  // Sequences increase within a session: an old or repeated one is a replay, dropped.
  if (q.sequence <= last_sequence_) {
    ++report_.rejected;
    return {};
  }
  last_sequence_ = q.sequence;
  ++report_.requests;
  ++io_requests_;
  // The target's own limits, whatever the host asked: clamp, slew limit, safe state.
  const SafetyGuard::Output out = guard_.limit(q.u);
  if (out.clamped || out.slew_limited) ++report_.limited;
  const bench::BenchSample s = io_.step(out.u);
  UdpReply r;
  r.type = UdpType::kIoReply;
  r.sequence = q.sequence;
  r.sample = ++sample_;
  r.de = s.de;
  r.vs = s.vs;
  r.va = s.va;
  r.session = session_;
  r.status = status() | (out.clamped || out.slew_limited ? kUdpStatusClamped : 0u);
  if (options_.drop_every > 0 && io_requests_ % options_.drop_every == 0) {
    ++report_.dropped;
    return {};
  }
  return reply(r);
}

std::vector<unsigned char> UdpTarget::handle(const unsigned char* data, std::size_t size, const UdpAddress& from,
                                             std::int64_t now_ns) noexcept {
  try {
    tick(now_ns);
    const std::size_t payload = unseal(data, size, options_.key);
    const auto q = payload > 0 ? decode_request(data, payload) : std::nullopt;
    if (!q) {
      ++report_.rejected;
      return {};
    }
    if (q->type == UdpType::kHello) return hello(*q, from, now_ns);
    // Everything else belongs to the open session: its host and its id.
    if (!open_ || !(from == peer_) || q->session != session_) {
      ++report_.rejected;
      return {};
    }
    last_seen_ns_ = now_ns;
    UdpReply r;
    r.sequence = q->sequence;
    r.session = session_;
    switch (q->type) {
      case UdpType::kIo:
        return io(*q);
      case UdpType::kSafe:
        latch("the host's watchdog asked for it");
        return {};
      case UdpType::kReset:
        // The session's explicit reset (its host asked the operator first): the bench back to its
        // start with the output at the safe value, and new limits state.
        report_.target_safe = false;
        restart();
        r.type = UdpType::kResetReply;
        r.status = status();
        return reply(r);
      case UdpType::kBye:
        ++report_.sessions;
        end_session();
        r.type = UdpType::kByeReply;
        r.status = status();
        return reply(r);
      default:
        ++report_.rejected;
        return {};
    }
  } catch (...) {
    // Allocation of a reply failed: no reply (the host counts it lost).
    return {};
  }
}

}  // namespace piezobench::rt
