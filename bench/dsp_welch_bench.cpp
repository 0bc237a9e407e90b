// Welch H1 + coherence at the size: 6 million samples, 2 outputs, nfft 10,000, 50 %
// overlap (1199 segments x 3 channels = 3597 real FFTs), against the FFTs alone (FFTW_ESTIMATE
// plans, as piezobench uses; and FFTW_MEASURE plans, with the planning time as a counter).
// CPU times are the whole process's (all threads).
//   build-speed/bench/dsp_welch_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <random>

#include <fftw3.h>
#include "piezobench/dsp/welch.hpp"

namespace {

using namespace piezobench::dsp;

constexpr Eigen::Index kSamples = 6'000'000;
constexpr Eigen::Index kNfft = 10'000;

struct Data {
  Eigen::VectorXd u, y1, y2;
  Data() : u(kSamples), y1(kSamples), y2(kSamples) {
    std::mt19937_64 rng(1);
    std::normal_distribution<double> normal;
    double state = 0.0;
    for (Eigen::Index i = 0; i < kSamples; ++i) {
      u(i) = normal(rng);
      state = 0.95 * state + u(i);
      y1(i) = state + 0.1 * normal(rng);
      y2(i) = -0.5 * u(i) + 0.1 * normal(rng);
    }
  }
};

const Data& data() {
  static const Data d;
  return d;
}

void BM_WelchH1Coherence(benchmark::State& state) {
  const Data& d = data();
  WelchOptions o;
  o.nfft = kNfft;
  o.overlap = 0.5;
  o.threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    FrfEstimate e = estimate_frf(channel("u", d.u), {channel("y1", d.y1), channel("y2", d.y2)}, 10e3, o);
    benchmark::DoNotOptimize(e.frf.H[0].data());
  }
  state.counters["segments"] = 1199;
}
BENCHMARK(BM_WelchH1Coherence)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

// The floor: the same 3597 transforms of length nfft and nothing else, one thread. Argument
// "measure": 0 = FFTW_ESTIMATE plans (piezobench's choice), 1 = FFTW_MEASURE.
void BM_FftsAlone(benchmark::State& state) {
  const Data& d = data();
  // FFTW used directly (the peer), aligned buffers.
  double* in = fftw_alloc_real(kNfft);
  fftw_complex* out = fftw_alloc_complex(kNfft / 2 + 1);
  const unsigned flags = state.range(0) != 0 ? FFTW_MEASURE : FFTW_ESTIMATE;
  fftw_forget_wisdom();
  const auto t0 = std::chrono::steady_clock::now();
  const fftw_plan plan = fftw_plan_dft_r2c_1d(static_cast<int>(kNfft), in, out, flags);
  state.counters["plan_ms"] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const Eigen::Index segments = (kSamples - kNfft) / (kNfft / 2) + 1;
  for (auto _ : state) {
    for (Eigen::Index s = 0; s < segments; ++s) {
      for (const Eigen::VectorXd* x : {&d.u, &d.y1, &d.y2}) {
        std::copy_n(x->data() + s * (kNfft / 2), kNfft, in);
        fftw_execute(plan);
        benchmark::DoNotOptimize(out);
      }
    }
  }
  fftw_destroy_plan(plan);
  fftw_free(out);
  fftw_free(in);
}
BENCHMARK(BM_FftsAlone)->ArgName("measure")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
