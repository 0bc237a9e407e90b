#pragma once
// A test-only comedilib: the comedilib calls the Comedi backend uses (comedi_open ... comedi_do_insnlist,
// the calibration functions, comedi_to_physical / comedi_from_physical), implemented on top of the
// virtual bench, so that the backend's own code (channel checks, ranges, calibration, counter
// unwrapping, timing, safety) runs in CI without a card. Linked instead of libcomedi into
// comedi_backend_tests only.
//
// The card "/dev/comedi-fake0" (anything else fails to open):
//   subdevice 0  analog input, 16 channels, 16 bit, ranges [-10, 10], [-5, 5], [-1, 1] V
//   subdevice 1  analog output, 2 channels, 16 bit, ranges [-10, 10], [0, 5] V
//   subdevice 2  counter, 2 channels, 24 bit
//   subdevice 3  digital I/O, 8 channels
// Wiring: AO 1/0 -> the bench's DAC input u; AI 0/2 <- Vs; AI 0/3 <- Va / 50 (amplifier monitor);
// counter 2/0 <- the encoder (d_e / resolution counts, starting near the 24-bit wrap). Other
// channels read 0 V. The converters have gain and offset errors that the calibration corrects.
#include <cstdint>
#include <memory>
#include <vector>

#include "piezobench/bench/virtual_bench.hpp"

namespace piezobench::test::fake_comedi {

struct Card {
  std::unique_ptr<bench::VirtualBench> bench;
  double encoder_resolution = 2.5e-9;   // m per count
  std::uint32_t counter_origin = 0xFFFF00;  // counts at d_e = 0: the counter wraps soon after
  double monitor_gain = 1.0 / 50.0;     // V at AI 0/3 per V at the stacks
  // Converter errors (true = gain * nominal + offset), corrected by a soft calibration (the
  // polynomials of the "calibration file") or a hard one (comedi_apply_parsed_calibration).
  double adc_gain = 1.02, adc_offset = 0.01;   // V
  double dac_gain = 0.99, dac_offset = -0.004; // V
  bool soft_calibrated = true;          // SDF_SOFT_CALIBRATED on the AI and AO subdevices
  bool calibration_file = true;         // comedi_parse_calibration_file succeeds
  bool hard_applied = false;            // set by comedi_apply_parsed_calibration
  long fail_reads_after = -1;           // comedi_do_insnlist fails (EIO) after this many reads
  // What happened.
  std::uint64_t reads = 0, writes = 0, direct_writes = 0;
  double dac_volts = 0.0;               // the DAC's true output now
  double va_min = 0.0, va_max = 0.0, max_va_step = 0.0, last_va = 0.0;      // V at the stacks (bench)
  double dac_min = 0.0, dac_max = 0.0, max_dac_step = 0.0;                 // V, the DAC's true output
  bench::BenchSample now;               // the bench's instruments now
  std::vector<bench::BenchSample> sampled;  // `now` at each successful instruction list (reads)
};

// The card, reset with a fresh bench of `unit` (the bench's errors and noise from `seed`).
Card& reset(const bench::UnitTruth& unit, const bench::BenchOptions& options, std::uint64_t seed);
Card& card();

}  // namespace piezobench::test::fake_comedi
