#include "fake_comedi.hpp"

#include <comedilib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

struct comedi_t_struct {
  int open = 0;
};

namespace piezobench::test::fake_comedi {

namespace {

Card g_card;
comedi_t g_device;
int g_errno = 0;

constexpr lsampl_t kMax16 = 65535, kMax24 = 0xFFFFFF;
const comedi_range kAiRanges[] = {{-10.0, 10.0, UNIT_volt}, {-5.0, 5.0, UNIT_volt}, {-1.0, 1.0, UNIT_volt}};
const comedi_range kAoRanges[] = {{-10.0, 10.0, UNIT_volt}, {0.0, 5.0, UNIT_volt}};

int fail(int err) {
  g_errno = err;
  errno = err;
  return -1;
}

bool valid(comedi_t* it) { return it == &g_device && g_device.open > 0; }

// True volts at an analog input channel.
double ai_volts(unsigned channel) {
  switch (channel) {
    case 2: return g_card.now.vs;
    case 3: return g_card.now.va * g_card.monitor_gain;
    default: return 0.0;
  }
}

lsampl_t ai_read(unsigned chanspec) {
  const comedi_range& r = kAiRanges[std::min<unsigned>(CR_RANGE(chanspec), 2)];
  const double gain = g_card.hard_applied ? 1.0 : g_card.adc_gain;
  const double offset = g_card.hard_applied ? 0.0 : g_card.adc_offset;
  const double measured = gain * ai_volts(CR_CHAN(chanspec)) + offset;
  const double word = std::round((measured - r.min) / (r.max - r.min) * kMax16);
  return static_cast<lsampl_t>(std::clamp(word, 0.0, static_cast<double>(kMax16)));
}

lsampl_t counter_read() {
  const auto counts = static_cast<std::int64_t>(std::floor(g_card.now.de / g_card.encoder_resolution));
  return static_cast<lsampl_t>((static_cast<std::int64_t>(g_card.counter_origin) + counts) & kMax24);
}

double dac_true(unsigned chanspec, lsampl_t word) {
  const comedi_range& r = kAoRanges[std::min<unsigned>(CR_RANGE(chanspec), 1)];
  const double nominal = r.min + static_cast<double>(std::min(word, kMax16)) / kMax16 * (r.max - r.min);
  return g_card.hard_applied ? nominal : g_card.dac_gain * nominal + g_card.dac_offset;
}

void ao_write(unsigned chanspec, lsampl_t word, bool step) {
  if (CR_CHAN(chanspec) != 0) return;  // not wired
  const double volts = dac_true(chanspec, word);
  g_card.max_dac_step = std::max(g_card.max_dac_step, std::abs(volts - g_card.dac_volts));
  g_card.dac_min = std::min(g_card.dac_min, volts);
  g_card.dac_max = std::max(g_card.dac_max, volts);
  g_card.dac_volts = volts;
  if (!step) {
    ++g_card.direct_writes;
    return;
  }
  ++g_card.writes;
  g_card.now = g_card.bench->step(g_card.dac_volts);
  const double va = g_card.now.va;
  g_card.va_min = std::min(g_card.va_min, va);
  g_card.va_max = std::max(g_card.va_max, va);
  g_card.max_va_step = std::max(g_card.max_va_step, std::abs(va - g_card.last_va));
  g_card.last_va = va;
}

}  // namespace

Card& card() { return g_card; }

Card& reset(const bench::UnitTruth& unit, const bench::BenchOptions& options, std::uint64_t seed) {
  g_card = Card{};
  g_card.bench = std::make_unique<bench::VirtualBench>(unit, options, seed);
  g_card.encoder_resolution = options.encoder_resolution;
  g_device.open = 0;
  return g_card;
}

}  // namespace piezobench::test::fake_comedi

using piezobench::test::fake_comedi::g_card;
using piezobench::test::fake_comedi::g_device;
using piezobench::test::fake_comedi::g_errno;
namespace fc = piezobench::test::fake_comedi;

extern "C" {

comedi_t* comedi_open(const char* fn) {
  if (fn == nullptr || std::strcmp(fn, "/dev/comedi-fake0") != 0 || !g_card.bench) {
    fc::fail(ENOENT);
    return nullptr;
  }
  ++g_device.open;
  return &g_device;
}

int comedi_close(comedi_t* it) {
  if (!fc::valid(it)) return fc::fail(EBADF);
  --g_device.open;
  return 0;
}

int comedi_errno(void) { return g_errno; }
const char* comedi_strerror(int errnum) { return std::strerror(errnum); }

int comedi_get_n_subdevices(comedi_t* it) { return fc::valid(it) ? 4 : fc::fail(EBADF); }

int comedi_get_subdevice_type(comedi_t* it, unsigned int subdevice) {
  if (!fc::valid(it)) return fc::fail(EBADF);
  const int types[] = {COMEDI_SUBD_AI, COMEDI_SUBD_AO, COMEDI_SUBD_COUNTER, COMEDI_SUBD_DIO};
  return subdevice < 4 ? types[subdevice] : fc::fail(EINVAL);
}

int comedi_get_subdevice_flags(comedi_t* it, unsigned int subdevice) {
  if (!fc::valid(it)) return fc::fail(EBADF);
  return subdevice <= 1 && g_card.soft_calibrated ? SDF_SOFT_CALIBRATED : 0;
}

int comedi_get_n_channels(comedi_t* it, unsigned int subdevice) {
  if (!fc::valid(it)) return fc::fail(EBADF);
  const int n[] = {16, 2, 2, 8};
  return subdevice < 4 ? n[subdevice] : fc::fail(EINVAL);
}

lsampl_t comedi_get_maxdata(comedi_t* it, unsigned int subdevice, unsigned int) {
  if (!fc::valid(it)) return 0;
  return subdevice == 2 ? fc::kMax24 : subdevice == 3 ? 1 : fc::kMax16;
}

int comedi_get_n_ranges(comedi_t* it, unsigned int subdevice, unsigned int) {
  if (!fc::valid(it)) return fc::fail(EBADF);
  return subdevice == 0 ? 3 : subdevice == 1 ? 2 : 1;
}

comedi_range* comedi_get_range(comedi_t* it, unsigned int subdevice, unsigned int, unsigned int range) {
  if (!fc::valid(it)) return nullptr;
  if (subdevice == 0 && range < 3) return const_cast<comedi_range*>(&fc::kAiRanges[range]);
  if (subdevice == 1 && range < 2) return const_cast<comedi_range*>(&fc::kAoRanges[range]);
  return nullptr;
}

char* comedi_get_default_calibration_path(comedi_t* it) {
  if (!fc::valid(it)) return nullptr;
  return strdup("/var/lib/comedi/calibrations/fake_card_comedi0");
}

comedi_calibration_t* comedi_parse_calibration_file(const char*) {
  if (!g_card.calibration_file) {
    fc::fail(ENOENT);
    return nullptr;
  }
  auto* c = static_cast<comedi_calibration_t*>(std::calloc(1, sizeof(comedi_calibration_t)));
  return c;
}

void comedi_cleanup_calibration(comedi_calibration_t* calibration) { std::free(calibration); }

int comedi_apply_parsed_calibration(comedi_t* it, unsigned int, unsigned int, unsigned int, unsigned int,
                                    const comedi_calibration_t* calibration) {
  if (!fc::valid(it)) return fc::fail(EBADF);
  if (calibration == nullptr) return fc::fail(EINVAL);
  g_card.hard_applied = true;
  return 0;
}

int comedi_get_softcal_converter(unsigned subdevice, unsigned, unsigned range, enum comedi_conversion_direction direction,
                                 const comedi_calibration_t* calibration, comedi_polynomial_t* p) {
  if (calibration == nullptr || p == nullptr || subdevice > 1) return fc::fail(EINVAL);
  *p = comedi_polynomial_t{};
  p->order = 1;
  p->expansion_origin = 0.0;
  if (subdevice == 0 && direction == COMEDI_TO_PHYSICAL) {
    const comedi_range& r = fc::kAiRanges[std::min(range, 2u)];
    const double span = r.max - r.min;
    // nominal = min + word span / max; true = (nominal - offset) / gain
    p->coefficients[0] = (r.min - g_card.adc_offset) / g_card.adc_gain;
    p->coefficients[1] = span / fc::kMax16 / g_card.adc_gain;
    return 0;
  }
  if (subdevice == 1 && direction == COMEDI_FROM_PHYSICAL) {
    const comedi_range& r = fc::kAoRanges[std::min(range, 1u)];
    const double span = r.max - r.min;
    // true = gain nominal + offset -> nominal = (true - offset) / gain -> word
    p->coefficients[0] = (-g_card.dac_offset / g_card.dac_gain - r.min) * fc::kMax16 / span;
    p->coefficients[1] = fc::kMax16 / (span * g_card.dac_gain);
    return 0;
  }
  return fc::fail(EINVAL);
}

int comedi_get_hardcal_converter(comedi_t* it, unsigned subdevice, unsigned, unsigned range,
                                 enum comedi_conversion_direction direction, comedi_polynomial_t* p) {
  if (!fc::valid(it) || p == nullptr || subdevice > 1) return fc::fail(EINVAL);
  *p = comedi_polynomial_t{};
  p->order = 1;
  const comedi_range& r = subdevice == 0 ? fc::kAiRanges[std::min(range, 2u)] : fc::kAoRanges[std::min(range, 1u)];
  const double span = r.max - r.min;
  if (direction == COMEDI_TO_PHYSICAL) {
    p->coefficients[0] = r.min;
    p->coefficients[1] = span / fc::kMax16;
  } else {
    p->coefficients[0] = -r.min * fc::kMax16 / span;
    p->coefficients[1] = fc::kMax16 / span;
  }
  return 0;
}

double comedi_to_physical(lsampl_t data, const comedi_polynomial_t* p) {
  double x = static_cast<double>(data) - p->expansion_origin, term = 1.0, value = 0.0;
  for (unsigned i = 0; i <= p->order; ++i) {
    value += p->coefficients[i] * term;
    term *= x;
  }
  return value;
}

lsampl_t comedi_from_physical(double data, const comedi_polynomial_t* p) {
  double x = data - p->expansion_origin, term = 1.0, value = 0.0;
  for (unsigned i = 0; i <= p->order; ++i) {
    value += p->coefficients[i] * term;
    term *= x;
  }
  return value < 0.0 ? 0 : static_cast<lsampl_t>(std::nearbyint(value));
}

int comedi_do_insnlist(comedi_t* it, comedi_insnlist* il) {
  if (!fc::valid(it)) return fc::fail(EBADF);
  if (g_card.fail_reads_after >= 0 && static_cast<long>(g_card.reads) >= g_card.fail_reads_after) return fc::fail(EIO);
  ++g_card.reads;
  g_card.sampled.push_back(g_card.now);
  for (unsigned i = 0; i < il->n_insns; ++i) {
    comedi_insn& insn = il->insns[i];
    if (insn.insn == INSN_READ) {
      if (insn.subdev == 0) {
        insn.data[0] = fc::ai_read(insn.chanspec);
      } else if (insn.subdev == 2) {
        insn.data[0] = CR_CHAN(insn.chanspec) == 0 ? fc::counter_read() : 0;
      } else {
        return static_cast<int>(i);
      }
    } else if (insn.insn == INSN_WRITE && insn.subdev == 1) {
      fc::ao_write(insn.chanspec, insn.data[0], true);
    } else {
      return static_cast<int>(i);
    }
  }
  return static_cast<int>(il->n_insns);
}

int comedi_do_insn(comedi_t* it, comedi_insn* insn) {
  comedi_insnlist list{1, insn};
  if (insn->insn == INSN_WRITE) {  // writes do not count as reads
    if (!fc::valid(it)) return fc::fail(EBADF);
    if (insn->subdev != 1) return fc::fail(EINVAL);
    fc::ao_write(insn->chanspec, insn->data[0], true);
    return 1;
  }
  return comedi_do_insnlist(it, &list);
}

int comedi_data_write(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int range, unsigned int aref,
                      lsampl_t data) {
  if (!fc::valid(it)) return fc::fail(EBADF);
  if (subd != 1) return fc::fail(EINVAL);
  fc::ao_write(CR_PACK(chan, range, aref), data, false);
  return 1;
}

}  // extern "C"
