// Benchmarks of the lti module, each paired with the same job in Octave (bench/octave/lti_bench.m);
// see bench/README.md for how to reproduce the figures of docs/performance.md.
//
// (a) Frequency response of a 100-state lightly damped SISO system (bench/data/ss100.txt, 50 modes
//     with damping 0.1 % .. 2 %, dense A) at 10,000 log-spaced frequencies 2 pi [1 Hz, 10 kHz].
// (b) Root locus of the report's IFF loop L = -K0 G (eqs. 2.3 and 2.4 at g = 1) with the automatic
//     gain grid, and the maximum damping of the branch that starts at the 95 Hz resonance.
#include <benchmark/benchmark.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <stdexcept>
#include <string>

#include "piezobench/control/iff.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/lti/rlocus.hpp"
#include "piezobench/lti/state_space.hpp"
#include "piezobench/core/units.hpp"

namespace {

using piezobench::kTwoPi;
using piezobench::lti::Complex;
using piezobench::lti::Index;
using piezobench::lti::Matrix;
using piezobench::lti::StateSpace;
using piezobench::lti::Vector;

// Format of bench/data/ss100.txt (written by bench/octave/make_ss100.m): "states inputs outputs",
// then the rows of A, B, C, D.
StateSpace read_system(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path + " (run bench/octave/make_ss100.m)");
  Index n = 0;
  Index m = 0;
  Index p = 0;
  in >> n >> m >> p;
  auto read = [&in](Index rows, Index cols) {
    Matrix x(rows, cols);
    for (Index i = 0; i < rows; ++i) {
      for (Index j = 0; j < cols; ++j) in >> x(i, j);
    }
    return x;
  };
  Matrix a = read(n, n);
  Matrix b = read(n, m);
  Matrix c = read(p, n);
  Matrix d = read(p, m);
  if (!in) throw std::runtime_error("malformed " + path);
  return {a, b, c, d};
}

const StateSpace& system100() {
  static const StateSpace sys = read_system(std::string(PIEZOBENCH_BENCH_DATA_DIR) + "/ss100.txt");
  return sys;
}

Vector frequencies() {
  return piezobench::lti::logspace(std::log10(kTwoPi * 1.0), std::log10(kTwoPi * 1e4), 10000);
}

// L = -K0 G, the open loop of the report's IFF loop (1 + g L = 0): the plant of eq. 2.3 and the
// controller of eq. 2.4 at the report's values (control/iff.hpp), as in the fixture script.
StateSpace iff_loop() {
  namespace control = piezobench::control;
  return control::iff_open_loop(piezobench::lti::to_state_space(control::iff_plant()),
                                piezobench::lti::to_state_space(control::iff_controller()));
}

// The plant's resonance pole, where the optimized branch starts.
Complex resonance_pole() {
  const piezobench::control::IffPlantParams p;
  return {-p.xp * p.wp, p.wp * std::sqrt(1 - p.xp * p.xp)};
}

// (a) one call: Hessenberg reduction + 10,000 frequencies, one thread.
void BM_FreqResp100States10000Frequencies(benchmark::State& state) {
  const StateSpace& sys = system100();
  const Vector omega = frequencies();
  for (auto _ : state) {
    auto r = piezobench::lti::freqresp(sys, omega);
    benchmark::DoNotOptimize(r.H.data());
  }
  state.counters["frequencies"] = static_cast<double>(omega.size());
  // Same check values as the Octave script prints.
  const auto r = piezobench::lti::freqresp(sys, omega);
  state.counters["absH_first"] = std::abs(r.H.front()(0, 0));
  state.counters["absH_5000"] = std::abs(r.H[4999](0, 0));
  state.counters["absH_last"] = std::abs(r.H.back()(0, 0));
}
BENCHMARK(BM_FreqResp100States10000Frequencies)->Unit(benchmark::kMillisecond)->UseRealTime();

// (a') the same with the evaluator's thread split over all cores (0 = hardware concurrency).
void BM_FreqResp100States10000FrequenciesAllCores(benchmark::State& state) {
  const StateSpace& sys = system100();
  const Vector omega = frequencies();
  for (auto _ : state) {
    const piezobench::lti::FrequencyResponseEvaluator evaluator(sys);
    auto r = evaluator.response(omega, /*threads=*/0);
    benchmark::DoNotOptimize(r.H.data());
  }
}
BENCHMARK(BM_FreqResp100States10000FrequenciesAllCores)->Unit(benchmark::kMillisecond)->UseRealTime();

// (b) automatic root locus of the IFF loop (default options).
void BM_RootLocusAutoIff(benchmark::State& state) {
  const StateSpace loop = iff_loop();
  std::size_t points = 0;
  for (auto _ : state) {
    auto locus = piezobench::lti::rlocus_auto(loop);
    points = locus.gains.size();
    benchmark::DoNotOptimize(locus.poles.data());
  }
  state.counters["gains"] = static_cast<double>(points);
}
BENCHMARK(BM_RootLocusAutoIff)->Unit(benchmark::kMillisecond)->UseRealTime();

// (b') maximum damping on the 95 Hz branch (branch following + golden section).
void BM_MaxDampingOnBranchIff(benchmark::State& state) {
  const StateSpace loop = iff_loop();
  piezobench::lti::BranchOptimum best;
  for (auto _ : state) {
    best = piezobench::lti::max_damping_on_branch(loop, resonance_pole());
    benchmark::DoNotOptimize(best);
  }
  state.counters["damping"] = best.damping;
  state.counters["gain"] = best.gain;
}
BENCHMARK(BM_MaxDampingOnBranchIff)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
