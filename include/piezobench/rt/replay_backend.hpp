#pragma once
// Replay of a recorded file as the loop's backend: each cycle reads the next row of the channels
// `de` (m) and `Vs` (V) of a time series (io::read_timeseries: .mat or .csv) and ignores the
// command (open loop: the record does not react to it). The loop runs at the record's sample rate
// and stops at its end. Used to run the controller against measured sensor data (what it would
// have commanded) and to test the loop without hardware.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/backend.hpp"

namespace piezobench::rt {

class ReplayBackend final : public Backend {
 public:
  // InputError (source = the record's file) when `de` or `Vs` is missing (the message lists the
  // channels) or the record is invalid (io::TimeSeries::validate).
  explicit ReplayBackend(const io::TimeSeries& record);
  // Reads the file (io::read_timeseries; its errors) and then as above.
  explicit ReplayBackend(const std::filesystem::path& file);

  [[nodiscard]] std::string name() const override { return "replay"; }
  [[nodiscard]] double sample_rate() const override { return sample_rate_; }
  void start() override;
  SensorSample read() noexcept override;
  // u: V at the DAC.
  void write(double u) noexcept override;
  [[nodiscard]] bool finished() const noexcept override;
  void stop() noexcept override {}

  [[nodiscard]] std::size_t samples() const { return de_.size(); }
  [[nodiscard]] const std::string& source() const { return source_; }
  // The last command written (V), for tests.
  [[nodiscard]] double last_command() const { return last_u_; }

 private:
  std::vector<double> de_, vs_;  // m, V
  double sample_rate_ = 0.0;     // Hz
  std::string source_;
  std::size_t next_ = 0;
  double last_u_ = 0.0;  // V at the DAC
};

}  // namespace piezobench::rt
