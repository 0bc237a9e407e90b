#pragma once
// The virtual bench (bench::VirtualBench) as the loop's backend: hardware-in-the-loop simulation.
// The bench is stepped in lockstep with the loop: write(u) advances it by one sample period with the
// DAC command u and stores its measurements, which the next read() returns (the ADC sample at the
// start of the next cycle). The bench's step() allocates nothing, so the cycle stays real-time.
#include <cstdint>

#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/rt/backend.hpp"

namespace piezobench::rt {

class VirtualBenchBackend final : public Backend {
 public:
  // The bench of `unit` with `options` (its sample_rate is the loop's), noise from `seed`.
  // InputError from the bench's validation.
  VirtualBenchBackend(const bench::UnitTruth& unit, const bench::BenchOptions& options, std::uint64_t seed);

  [[nodiscard]] std::string name() const override { return "virtual"; }
  [[nodiscard]] double sample_rate() const override;
  void start() override;
  SensorSample read() noexcept override;
  // u: V at the DAC.
  void write(double u) noexcept override;
  void stop() noexcept override {}

  [[nodiscard]] const bench::VirtualBench& bench() const { return bench_; }

 private:
  bench::VirtualBench bench_;
  std::uint64_t seed_;
  SensorSample last_;
};

}  // namespace piezobench::rt
