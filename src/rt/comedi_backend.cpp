#include "piezobench/rt/comedi_backend.hpp"

#include <comedilib.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/rt/timing.hpp"

namespace piezobench::rt {

namespace {

struct Channel {
  const SignalChannel* spec = nullptr;
  std::string name;  // "u", "d_e", "Vs", "Va"
  unsigned subdevice = 0, channel = 0, range = 0, aref = AREF_GROUND;
  lsampl_t maxdata = 0;
  double range_min = 0.0, range_max = 0.0;
  comedi_polynomial_t poly{};
  std::string calibration;  // "soft", "hard", "linear", "counter"
  lsampl_t raw = 0;         // the instruction's data
};

Channel channel_of(const SignalChannel& spec, std::string name) {
  Channel c;
  c.spec = &spec;
  c.name = std::move(name);
  return c;
}

unsigned aref_of(const std::string& a) { return a == "common" ? AREF_COMMON : a == "diff" ? AREF_DIFF : AREF_GROUND; }

std::string last_error() { return comedi_strerror(comedi_errno()); }

}  // namespace

struct ComediBackend::State {
  BenchDescription bench;
  comedi_t* dev = nullptr;
  comedi_calibration_t* calibration = nullptr;
  Channel u, de, vs, va;
  bool has_va = false;
  std::array<comedi_insn, 3> reads{};
  comedi_insnlist list{};
  comedi_insn write{};
  lsampl_t safe_raw = 0;
  bool armed = false;  // the channels are checked: stop() may write the safe output
  // Encoder unwrapping (counter).
  lsampl_t last_count = 0;
  double counts = 0.0;
  SensorSample last;
  IoStats stats;
  TimingHistogram io_time;

  std::string source(const Channel& c) const { return bench.source + ": signals." + c.name; }

  void check_channel(Channel& c, int wanted_type) {
    const SignalChannel& s = *c.spec;
    c.subdevice = static_cast<unsigned>(s.subdevice);
    c.channel = static_cast<unsigned>(s.channel);
    c.aref = aref_of(s.aref);
    const int n_sub = comedi_get_n_subdevices(dev);
    if (s.subdevice >= n_sub) {
      throw InputError(bench.source, "signals." + c.name + ".subdevice",
                       fmt::format("a subdevice of {} (0..{})", bench.comedi_device, n_sub - 1), std::to_string(s.subdevice));
    }
    const int type = comedi_get_subdevice_type(dev, c.subdevice);
    if (type != wanted_type) {
      const char* names[] = {"unused", "analog input", "analog output", "digital input", "digital output",
                             "digital I/O", "counter", "timer", "memory", "calibration", "processor", "serial"};
      const auto name = [&](int t) { return t >= 0 && t < 12 ? std::string(names[t]) : "type " + std::to_string(t); };
      throw InputError(bench.source, "signals." + c.name + ".subdevice",
                       fmt::format("an {} subdevice", name(wanted_type)),
                       fmt::format("subdevice {} is {}", s.subdevice, name(type)));
    }
    const int n_chan = comedi_get_n_channels(dev, c.subdevice);
    if (s.channel >= n_chan) {
      throw InputError(bench.source, "signals." + c.name + ".channel",
                       fmt::format("a channel of subdevice {} (0..{})", s.subdevice, n_chan - 1),
                       std::to_string(s.channel) + " (missing channel)");
    }
    c.maxdata = comedi_get_maxdata(dev, c.subdevice, c.channel);
    if (wanted_type == COMEDI_SUBD_COUNTER) {
      c.calibration = "counter";
      return;
    }
    // The smallest range that covers the file's.
    const int n_ranges = comedi_get_n_ranges(dev, c.subdevice, c.channel);
    int best = -1;
    double best_span = std::numeric_limits<double>::infinity();
    std::string available;
    for (int r = 0; r < n_ranges; ++r) {
      const comedi_range* cr = comedi_get_range(dev, c.subdevice, c.channel, static_cast<unsigned>(r));
      if (cr == nullptr) continue;
      available += fmt::format("{}[{:g}, {:g}]", available.empty() ? "" : ", ", cr->min, cr->max);
      if (cr->min <= s.range_min + 1e-9 && cr->max >= s.range_max - 1e-9 && cr->max - cr->min < best_span) {
        best = r;
        best_span = cr->max - cr->min;
      }
    }
    if (best < 0) {
      throw InputError(bench.source, "signals." + c.name + ".range",
                       fmt::format("a range the card has on subdevice {} ({})", s.subdevice, available),
                       fmt::format("[{}, {}]", format_number_exact(s.range_min), format_number_exact(s.range_max)));
    }
    c.range = static_cast<unsigned>(best);
    const comedi_range* cr = comedi_get_range(dev, c.subdevice, c.channel, c.range);
    c.range_min = cr->min;
    c.range_max = cr->max;
    // Calibration.
    const auto direction = wanted_type == COMEDI_SUBD_AO ? COMEDI_FROM_PHYSICAL : COMEDI_TO_PHYSICAL;
    std::string mode = bench.calibration;
    if (mode == "auto") mode = (comedi_get_subdevice_flags(dev, c.subdevice) & SDF_SOFT_CALIBRATED) ? "soft" : "hard";
    if (mode == "hard" && calibration == nullptr && bench.calibration == "auto") mode = "linear";
    if (mode == "soft" && calibration == nullptr) {
      throw InputError(bench.source, "comedi.calibration",
                       "the board's soft calibration file (run comedi_soft_calibrate; or calibration = \"none\")",
                       "no file");
    }
    if (mode == "soft") {
      if (comedi_get_softcal_converter(c.subdevice, c.channel, c.range, direction, calibration, &c.poly) < 0) {
        throw InputError(bench.source, "comedi.calibration",
                         fmt::format("a soft calibration of subdevice {} channel {} range {} in the calibration file",
                                     c.subdevice, c.channel, c.range),
                         "none (" + last_error() + ")");
      }
      c.calibration = "soft";
    } else {
      if (mode == "hard" && comedi_apply_parsed_calibration(dev, c.subdevice, c.channel, c.range, c.aref, calibration) < 0) {
        throw InputError(bench.source, "comedi.calibration",
                         fmt::format("the board's calibration of subdevice {} channel {} range {}", c.subdevice, c.channel,
                                     c.range),
                         "none applicable (" + last_error() + ")");
      }
      if (comedi_get_hardcal_converter(dev, c.subdevice, c.channel, c.range, direction, &c.poly) < 0) {
        throw InputError(source(c), "calibration", "a linear converter", last_error());
      }
      c.calibration = mode == "hard" ? "hard" : "linear";
    }
  }

  // The DAC word for u (V of the command): through the scale and the converter, inside the range.
  lsampl_t dac_word(double u_value) const {
    const double volts = std::clamp(u_value * u.spec->scale, u.range_min, u.range_max);
    const lsampl_t w = comedi_from_physical(volts, &u.poly);
    return std::min(w, u.maxdata);
  }

  double analog(const Channel& c) const { return comedi_to_physical(c.raw, &c.poly) * c.spec->scale; }
};

ComediBackend::ComediBackend(const BenchDescription& bench) : state_(std::make_unique<State>()) {
  bench.validate();
  if (bench.backend != "comedi") {
    throw InputError(bench.source, "bench.backend", "\"comedi\" for the Comedi backend", "'" + bench.backend + "'");
  }
  state_->bench = bench;
  State& s = *state_;
  s.u = channel_of(s.bench.u, "u");
  s.de = channel_of(s.bench.de, "d_e");
  s.vs = channel_of(s.bench.vs, "Vs");
  s.has_va = s.bench.va.has_value();
  if (s.has_va) s.va = channel_of(*s.bench.va, "Va");
  for (const Channel* c : {&s.u, &s.de, &s.vs, s.has_va ? &s.va : nullptr}) {
    if (c != nullptr && c->spec->device != s.bench.comedi_device) {
      throw InputError(bench.source, "signals." + c->name + ".device",
                       "the bench's card " + s.bench.comedi_device + " (one card per bench)", "'" + c->spec->device + "'");
    }
  }
}

ComediBackend::~ComediBackend() { stop(); }

double ComediBackend::sample_rate() const { return state_->bench.sample_rate; }

void ComediBackend::start() {
  State& s = *state_;
  stop();
  s.dev = comedi_open(s.bench.comedi_device.c_str());
  if (s.dev == nullptr) {
    throw InputError(s.bench.source, "comedi.device", "a Comedi device that can be opened", s.bench.comedi_device + ": " + last_error());
  }
  try {
    if (s.bench.calibration != "none") {
      char* path = comedi_get_default_calibration_path(s.dev);
      const std::string file = path ? path : "";
      std::free(path);
      if (!file.empty()) s.calibration = comedi_parse_calibration_file(file.c_str());
      if (s.calibration == nullptr && s.bench.calibration != "auto") {
        throw InputError(s.bench.source, "comedi.calibration",
                         "the board's calibration file " + (file.empty() ? std::string("(no default path)") : file) +
                             " (made by comedi_soft_calibrate or comedi_calibrate; or calibration = \"none\")",
                         "no readable file");
      }
    }
    s.check_channel(s.u, COMEDI_SUBD_AO);
    s.check_channel(s.de, s.bench.de.kind == "counter" ? COMEDI_SUBD_COUNTER : COMEDI_SUBD_AI);
    s.check_channel(s.vs, COMEDI_SUBD_AI);
    if (s.has_va) s.check_channel(s.va, COMEDI_SUBD_AI);
  } catch (...) {
    stop();
    throw;
  }
  // One instruction list for the inputs, one instruction for the output.
  unsigned n = 0;
  for (Channel* c : {&s.de, &s.vs, s.has_va ? &s.va : nullptr}) {
    if (c == nullptr) continue;
    comedi_insn& i = s.reads[n++];
    i = comedi_insn{};
    i.insn = INSN_READ;
    i.n = 1;
    i.data = &c->raw;
    i.subdev = c->subdevice;
    i.chanspec = CR_PACK(c->channel, c->range, c->aref);
  }
  s.list.n_insns = n;
  s.list.insns = s.reads.data();
  s.write = comedi_insn{};
  s.write.insn = INSN_WRITE;
  s.write.n = 1;
  s.write.data = &s.u.raw;
  s.write.subdev = s.u.subdevice;
  s.write.chanspec = CR_PACK(s.u.channel, s.u.range, AREF_GROUND);
  s.safe_raw = s.dac_word(s.bench.limits.u_safe());
  s.stats = IoStats{};
  s.io_time = TimingHistogram{};
  s.last = SensorSample{};
  // The encoder's origin: d_e is measured from where the actuator is at the start.
  if (comedi_do_insnlist(s.dev, &s.list) != static_cast<int>(n)) {
    const std::string err = last_error();
    stop();
    throw InputError(s.bench.source, "comedi", "a first reading of the inputs", err);
  }
  s.last_count = s.de.raw;
  s.counts = 0.0;
  s.u.raw = s.safe_raw;
  s.armed = true;
  comedi_do_insn(s.dev, &s.write);
}

SensorSample ComediBackend::read() noexcept {
  State& s = *state_;
  if (s.dev == nullptr) return s.last;
  const std::int64_t t0 = monotonic_ns();
  const int done = comedi_do_insnlist(s.dev, &s.list);
  s.io_time.add(static_cast<double>(monotonic_ns() - t0));
  ++s.stats.exchanges;
  if (done != static_cast<int>(s.list.n_insns)) {
    ++s.stats.errors;
    s.last.de = s.last.vs = std::numeric_limits<double>::quiet_NaN();  // the safe state
    return s.last;
  }
  ++s.stats.replies;
  if (s.de.calibration == "counter") {
    // Unwrap the counter (modulo maxdata + 1), signed steps.
    const double modulus = static_cast<double>(s.de.maxdata) + 1.0;
    double step = static_cast<double>(s.de.raw) - static_cast<double>(s.last_count);
    if (step > modulus / 2) step -= modulus;
    if (step < -modulus / 2) step += modulus;
    s.counts += step;
    s.last_count = s.de.raw;
    s.last.de = s.counts * s.de.spec->scale;
  } else {
    s.last.de = s.analog(s.de);
  }
  s.last.vs = s.analog(s.vs);
  s.last.va = s.has_va ? s.analog(s.va) : std::numeric_limits<double>::quiet_NaN();
  ++s.last.sequence;
  return s.last;
}

void ComediBackend::write(double u) noexcept {
  State& s = *state_;
  if (s.dev == nullptr) return;
  s.u.raw = std::isfinite(u) ? s.dac_word(u) : s.safe_raw;
  if (comedi_do_insn(s.dev, &s.write) < 0) ++s.stats.errors;
}

void ComediBackend::on_watchdog() noexcept {
  State& s = *state_;
  if (s.dev == nullptr || !s.armed) return;
  comedi_data_write(s.dev, s.u.subdevice, s.u.channel, s.u.range, AREF_GROUND, s.safe_raw);
}

void ComediBackend::stop() noexcept {
  State& s = *state_;
  if (s.dev != nullptr) {
    if (s.armed) comedi_data_write(s.dev, s.u.subdevice, s.u.channel, s.u.range, AREF_GROUND, s.safe_raw);
    s.armed = false;
    comedi_close(s.dev);
    s.dev = nullptr;
  }
  if (s.calibration != nullptr) {
    comedi_cleanup_calibration(s.calibration);
    s.calibration = nullptr;
  }
}

IoStats ComediBackend::io_stats() const {
  IoStats s = state_->stats;
  s.round_trip_us = state_->io_time.summary_us();
  return s;
}

ComediBackend::ChannelSetup ComediBackend::setup(const std::string& signal) const {
  const State& s = *state_;
  const Channel* c = signal == "u" ? &s.u : signal == "d_e" ? &s.de : signal == "Vs" ? &s.vs : signal == "Va" && s.has_va ? &s.va : nullptr;
  if (c == nullptr) throw InputError("comedi backend", "signal", "u, d_e, Vs or Va (when wired)", "'" + signal + "'");
  return {c->range, c->range_min, c->range_max, c->calibration};
}

}  // namespace piezobench::rt
