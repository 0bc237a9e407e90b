#include "piezobench/rt/virtual_backend.hpp"

namespace piezobench::rt {

VirtualBenchBackend::VirtualBenchBackend(const bench::UnitTruth& unit, const bench::BenchOptions& options,
                                         std::uint64_t seed)
    : bench_(unit, options, seed), seed_(seed) {}

double VirtualBenchBackend::sample_rate() const { return bench_.sample_rate(); }

void VirtualBenchBackend::start() {
  bench_.reset(seed_);
  last_ = SensorSample{};
  last_.va = 0.0;
  last_.sequence = 0;
}

SensorSample VirtualBenchBackend::read() noexcept { return last_; }

void VirtualBenchBackend::write(double u) noexcept {
  const bench::BenchSample s = bench_.step(u);
  last_.de = s.de;
  last_.vs = s.vs;
  last_.va = s.va;
  ++last_.sequence;
}

}  // namespace piezobench::rt
