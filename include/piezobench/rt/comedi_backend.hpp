#pragma once
// The Comedi backend: a data-acquisition card driven through comedilib (Debian's libcomedi-dev),
// with per-cycle synchronous I/O: each cycle's read() runs one instruction list that samples every
// input (the encoder's counter or an analog input, Vs, the optional Va monitor), write() one
// instruction that sets the DAC. The host's clock paces the loop (ClockSource::kHostMonotonic).
//
// Before anything moves, start() checks the card against the bench file: each signal's subdevice
// exists and has the right type (AO for u, AI for the analog inputs, counter for a counter
// encoder), its channel exists, and a range of the subdevice covers the file's range (the smallest
// such range is used). Calibration ("comedi.calibration"): "soft" converts with the polynomials of
// the board's calibration file (comedi_soft_calibrate; comedi_get_softcal_converter), "hard"
// applies the file's caldac settings to the board (comedi_calibrate; comedi_apply_parsed_calibration)
// and converts linearly (comedi_get_hardcal_converter), "auto" picks by the subdevice's
// SDF_SOFT_CALIBRATED flag, "none" converts linearly without a file. A missing calibration file
// (soft, hard) is an error naming the program that makes it.
//
// Errors in the cycle never throw: a failed instruction list returns NaN sensors (the loop's safe
// state), a failed write is counted. on_watchdog() writes the safe DAC value directly. stop()
// writes it and closes the card.
#include <memory>
#include <string>

#include "piezobench/rt/backend.hpp"
#include "piezobench/rt/bench_file.hpp"

namespace piezobench::rt {

class ComediBackend final : public Backend {
 public:
  // Validates the description (backend "comedi"); the card is opened by start().
  explicit ComediBackend(const BenchDescription& bench);
  ~ComediBackend() override;

  [[nodiscard]] std::string name() const override { return "comedi"; }
  [[nodiscard]] double sample_rate() const override;
  // Opens the card(s), checks the channels and ranges, sets up the calibration, reads the encoder's
  // origin and writes the safe output. InputError naming the bench file and signal otherwise.
  void start() override;
  SensorSample read() noexcept override;
  // u: V at the DAC.
  void write(double u) noexcept override;
  void stop() noexcept override;
  void on_watchdog() noexcept override;
  [[nodiscard]] IoStats io_stats() const override;

  // What start() chose, for reports and tests: the range index and the converter polynomial of a
  // signal ("u", "d_e", "Vs", "Va"), "soft"/"hard"/"linear" calibration per signal.
  struct ChannelSetup {
    unsigned range = 0;
    double range_min = 0.0, range_max = 0.0;  // V of the chosen range
    std::string calibration;
  };
  [[nodiscard]] ChannelSetup setup(const std::string& signal) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace piezobench::rt
