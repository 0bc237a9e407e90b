// The virtual bench's speed (issue 5): one VirtualBench::step() of the 2-DoF bench with
// hysteresis, creep and noise (target <= 20 ns per 100 us sample: 5,000 times real time), of the
// APA95ML super-element bench (target 200 times real time), and a whole frf-noise record of
// 100 s (1 M samples) in memory. The peer is scipy.signal.dlsim / lfilter on the same linear
// 2-DoF bench (scripts/analysis/peer_dlsim.py), run in the same session; docs/performance.md has the
// figures and the commands.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <span>
#include <vector>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/bench/virtual_bench.hpp"

namespace {

using piezobench::bench::BenchOptions;
using piezobench::bench::VirtualBench;

// A DAC command with some content: noise-like, within the stack range.
std::vector<double> command(std::size_t n) {
  std::vector<double> u(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto t = static_cast<double>(k);
    u[k] = 0.5 + 0.3 * std::sin(0.013 * t) + 0.2 * std::sin(0.77 * t + 0.3 * std::sin(0.002 * t));
  }
  return u;
}

void report(benchmark::State& state, std::size_t steps_per_iteration, double sample_rate) {
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * steps_per_iteration));
  // Simulated seconds per wall second: how many times faster than real time.
  state.counters["x_realtime"] = benchmark::Counter(static_cast<double>(state.iterations() * steps_per_iteration) / sample_rate,
                                                    benchmark::Counter::kIsRate);
}

// Unit 1's bench with these options, one VirtualBench::step() per sample of an n-sample command.
void step_samples(benchmark::State& state, const BenchOptions& options, std::size_t n) {
  VirtualBench bench(piezobench::bench::batch_unit(1, 1), options, 1);
  const std::vector<double> u = command(n);
  for (auto _ : state) {
    double sum = 0.0;
    for (const double v : u) {
      const auto m = bench.step(v);
      sum += m.de + m.vs;
    }
    benchmark::DoNotOptimize(sum);
  }
  report(state, u.size(), options.sample_rate);
}

// range(0): 1 = everything on (the bench's default); 0 = hysteresis, creep and noise off.
void BM_TwoDofBenchStep(benchmark::State& state) {
  BenchOptions options;  // hysteresis, creep, noise, delay, NMP zero: all on
  if (state.range(0) == 0) options.hysteresis = options.creep = options.noise = false;
  step_samples(state, options, 1 << 16);
}
BENCHMARK(BM_TwoDofBenchStep)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// The same through VirtualBench::run (the experiments' path): blocks of 4096 samples.
void BM_TwoDofBenchRun(benchmark::State& state) {
  BenchOptions options;
  if (state.range(0) == 0) options.hysteresis = options.creep = options.noise = false;
  VirtualBench bench(piezobench::bench::batch_unit(1, 1), options, 1);
  const std::vector<double> u = command(1 << 16);
  std::vector<piezobench::bench::BenchSample> out(4096);
  for (auto _ : state) {
    for (std::size_t k = 0; k < u.size(); k += out.size()) {
      bench.run(std::span<const double>(u.data() + k, out.size()), out);
      benchmark::DoNotOptimize(out.data());
    }
  }
  report(state, u.size(), options.sample_rate);
}
BENCHMARK(BM_TwoDofBenchRun)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

std::filesystem::path apa95ml_toml() {
  const std::filesystem::path data = std::filesystem::path(PIEZOBENCH_SHARED_DATA_DIR) / "apa95ml-ansys";
  const std::filesystem::path toml = std::filesystem::temp_directory_path() / "piezobench-bench-sim-apa95ml.toml";
  std::ofstream(toml) << "k_file = \"" << (data / "piezo_amplified_K.txt").string() << "\"\n"
                      << "m_file = \"" << (data / "piezo_amplified_M.txt").string() << "\"\n"
                      << "nodes_file = \"" << (data / "piezo_amplified.txt").string() << "\"\n"
                      << "fix = [76429]\nactuator = \"76430:76433:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:y\"\n"
                      << "ga = 20.0\ngs = 0.2e6\n";
  return toml;
}

void BM_SuperElementBenchStep(benchmark::State& state) {
  BenchOptions options;
  options.superelement = apa95ml_toml();
  step_samples(state, options, 1 << 14);
}
BENCHMARK(BM_SuperElementBenchStep)->Unit(benchmark::kMillisecond);

void BM_SimulateFrfNoise100s(benchmark::State& state) {
  piezobench::bench::ExperimentOptions o;
  o.duration = 100.0;
  const auto unit = piezobench::bench::batch_unit(1, 1);
  for (auto _ : state) {
    const auto ts = piezobench::bench::simulate(piezobench::bench::Experiment::kFrfNoise, unit, o, 1);
    benchmark::DoNotOptimize(ts.data.data());
  }
  report(state, 1000000, o.bench.sample_rate);
}
BENCHMARK(BM_SimulateFrfNoise100s)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
