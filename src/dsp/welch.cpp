#include "piezobench/dsp/welch.hpp"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <complex>
#include <limits>
#include <thread>

#include "fft.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/dsp/frf_variance.hpp"

namespace piezobench::dsp {

using Eigen::Index;
using Complex = std::complex<double>;

namespace {

// Segments are summed in this many contiguous chunks, each by one thread, and the chunk sums are
// added in chunk order: the result is the same whatever the number of threads.
constexpr Index kChunks = 16;
// Below this many samples transformed in total, threads cost more than they save.
constexpr double kMinWorkForThreads = 1 << 18;

void check_channel(const Channel& ch, Index expected_length, const std::string& source) {
  const auto n = static_cast<Index>(ch.samples.size());
  if (n != expected_length) {
    throw InputError(source, ch.name, std::to_string(expected_length) + " samples (as the input)",
                     std::to_string(n));
  }
  for (Index i = 0; i < n; ++i) {
    const double x = ch.samples[static_cast<std::size_t>(i)];
    if (!std::isfinite(x)) {
      throw InputError(source, ch.name, "finite samples",
                       std::string(std::isnan(x) ? "NaN" : x > 0 ? "Inf" : "-Inf") + " at sample " + std::to_string(i) +
                           " (0-based)");
    }
  }
}

// The checks of every channel in order (lengths and finite samples): throws the first problem.
void check_channels(const Channel& input, const std::vector<Channel>& outputs, const std::string& source) {
  const auto n = static_cast<Index>(input.samples.size());
  check_channel(input, n, source);
  for (const auto& out : outputs) check_channel(out, n, source);
}

bool all_finite(const double* x, Index n) {
  bool ok = true;
  for (Index i = 0; i < n; ++i) ok &= (x[i] - x[i]) == 0.0;  // NaN for NaN and +-Inf
  return ok;
}

// Asks for samples [from, to) of every channel to be brought into the cache: the part of the next
// segment that this one does not share. Loading the segments was bound by memory latency (the
// record is read straight from RAM, 48 MB per channel); fetched while the FFTs of this segment
// run, the samples are in the cache when the next segment is windowed.
void prefetch_next_segment([[maybe_unused]] const Channel& input, [[maybe_unused]] const std::vector<Channel>& outputs,
                           [[maybe_unused]] Index from, [[maybe_unused]] Index to) {
#if defined(__GNUC__)
  constexpr Index kLine = 64 / sizeof(double);
  const auto fetch = [&](const Channel& ch) {
    for (Index i = from; i < to; i += kLine) __builtin_prefetch(ch.samples.data() + i, 0, 3);
  };
  fetch(input);
  for (const auto& out : outputs) fetch(out);
#endif
}

// Detrends and windows one segment of nfft samples into `out`.
class SegmentLoader {
 public:
  SegmentLoader(const Eigen::VectorXd& window, Detrend detrend) : w_(window), detrend_(detrend) {
    const double n = static_cast<double>(w_.size());
    tc_ = 0.5 * (n - 1.0);
    stt_ = n * (n * n - 1.0) / 12.0;
  }

  void load(const double* x, double* out) const {
    const Index n = w_.size();
    const double* w = w_.data();
    switch (detrend_) {
      case Detrend::kNone:
        for (Index i = 0; i < n; ++i) out[i] = w[i] * x[i];
        return;
      case Detrend::kMean: {
        double sum = 0.0;
        for (Index i = 0; i < n; ++i) sum += x[i];
        const double mean = sum / static_cast<double>(n);
        for (Index i = 0; i < n; ++i) out[i] = w[i] * (x[i] - mean);
        return;
      }
      case Detrend::kLinear: {
        // Same line as detrend_in_place: mean + slope (t - tc).
        double sum = 0.0;
        double sxt = 0.0;
        for (Index i = 0; i < n; ++i) {
          sum += x[i];
          sxt += (static_cast<double>(i) - tc_) * x[i];
        }
        const double mean = sum / static_cast<double>(n);
        const double slope = stt_ > 0.0 ? sxt / stt_ : 0.0;
        for (Index i = 0; i < n; ++i) out[i] = w[i] * (x[i] - mean - slope * (static_cast<double>(i) - tc_));
        return;
      }
    }
  }

 private:
  const Eigen::VectorXd& w_;
  Detrend detrend_;
  double tc_ = 0.0;
  double stt_ = 0.0;
};

}  // namespace

std::string to_string(FrfEstimator estimator) { return estimator == FrfEstimator::kH1 ? "H1" : "H2"; }

FrfEstimator frf_estimator_from_string(const std::string& name) {
  if (name == "H1") return FrfEstimator::kH1;
  if (name == "H2") return FrfEstimator::kH2;
  throw InputError("", "estimator", "one of H1, H2", "\"" + name + "\"");
}

void WelchOptions::validate(const std::string& source) const {
  if (nfft < 2) throw InputError(source, "nfft", "an integer >= 2", std::to_string(nfft));
  if (nfft > std::numeric_limits<int>::max()) {
    throw InputError(source, "nfft", "at most " + std::to_string(std::numeric_limits<int>::max()),
                     std::to_string(nfft));
  }
  if (!(overlap >= 0.0 && overlap < 1.0)) {
    throw InputError(source, "overlap", "a fraction in [0, 1)", format_number_exact(overlap));
  }
  if (threads < 0) throw InputError(source, "threads", ">= 0 (0 = all cores)", std::to_string(threads));
}

Index WelchOptions::noverlap() const {
  return static_cast<Index>(std::floor(overlap * static_cast<double>(nfft)));
}

Index segment_length_for_record(Index samples, double sample_rate_Hz, double resolution_Hz, const std::string& source) {
  if (!(std::isfinite(sample_rate_Hz) && sample_rate_Hz > 0.0)) {
    throw InputError(source, "sample rate", "a finite rate > 0 Hz", format_number_exact(sample_rate_Hz));
  }
  if (!(std::isfinite(resolution_Hz) && resolution_Hz > 0.0)) {
    throw InputError(source, "resolution", "a finite frequency resolution > 0 Hz", format_number_exact(resolution_Hz));
  }
  const auto target = static_cast<Index>(std::lround(sample_rate_Hz / resolution_Hz));
  return std::max<Index>(256, std::min<Index>(target, samples / 4));
}

WelchOptions welch_options_for_record(Index samples, double sample_rate_Hz, double resolution_Hz, const std::string& source) {
  WelchOptions o;
  o.window = WindowType::kHannPeriodic;
  o.nfft = segment_length_for_record(samples, sample_rate_Hz, resolution_Hz, source);
  o.overlap = 0.5;
  o.detrend = Detrend::kMean;
  o.estimator = FrfEstimator::kH1;
  return o;
}

Channel channel(std::string name, const Eigen::VectorXd& samples) {
  return Channel{std::move(name), std::span<const double>(samples.data(), static_cast<std::size_t>(samples.size()))};
}

namespace {

// How a record is cut: nseg segments of nfft samples, `step` apart, summed in `chunks` chunks
// (the unit of work of a thread).
struct SegmentPlan {
  Index n = 0, nfft = 0, noverlap = 0, step = 0, nseg = 0, nout = 0, chunks = 0;
};

// The preconditions of cross_spectra and the segments. Finite samples are not checked in a pass of
// their own (records reach 10^7 samples per channel): a NaN or Inf in a segment makes every bin of
// that segment's spectrum non-finite, so the sums are checked at the end, and the samples after the
// last segment up front. Only when either shows a problem (or a length differs) are the channels
// scanned in order for the message.
SegmentPlan plan_segments(const Channel& input, const std::vector<Channel>& outputs, double sample_rate_Hz, const WelchOptions& options,
                          const std::string& source) {
  options.validate(source);
  if (!(std::isfinite(sample_rate_Hz) && sample_rate_Hz > 0.0)) {
    throw InputError(source, "sample rate", "a finite rate > 0 Hz", format_number_exact(sample_rate_Hz));
  }
  SegmentPlan p;
  p.n = static_cast<Index>(input.samples.size());
  p.nfft = options.nfft;
  const Index n = p.n, nfft = p.nfft;
  const bool lengths_ok = std::all_of(outputs.begin(), outputs.end(),
                                      [&](const Channel& out) { return static_cast<Index>(out.samples.size()) == n; });
  if (!lengths_ok || n < nfft) check_channels(input, outputs, source);
  if (n < nfft) {
    throw InputError(source, input.name, "a record of at least nfft = " + std::to_string(nfft) + " samples",
                     std::to_string(n) + " samples");
  }
  p.noverlap = options.noverlap();
  p.step = nfft - p.noverlap;
  p.nseg = (n - nfft) / p.step + 1;
  const Index covered = (p.nseg - 1) * p.step + nfft;  // segments overlap or touch: no gap before this
  bool tail_ok = all_finite(input.samples.data() + covered, n - covered);
  for (const auto& out : outputs) tail_ok = tail_ok && all_finite(out.samples.data() + covered, n - covered);
  if (!tail_ok) check_channels(input, outputs, source);
  p.nout = static_cast<Index>(outputs.size());
  p.chunks = std::min(kChunks, p.nseg);
  return p;
}

// Per-chunk sums, allocated once: [chunk][bin] and [chunk][output][bin].
struct ChunkSums {
  std::vector<double> uu, yy;
  std::vector<Complex> uy;
};

// A thread's FFT buffers.
struct SegmentBuffers {
  detail::FftwBuffer<double> segment;
  detail::FftwBuffer<Complex> u;
  detail::FftwBuffer<Complex> y;
};

// |U|^2 added to suu. Written out on (re, im) pairs: std::complex's operator* checks for NaN/Inf
// (C99 Annex G) and would not vectorize; the spectra here are finite by construction.
inline void add_auto_spectrum(const double* U, Index nbins, double* suu) {
  for (Index k = 0; k < nbins; ++k) suu[k] += U[2 * k] * U[2 * k] + U[2 * k + 1] * U[2 * k + 1];
}

// |Y|^2 added to syy and conj(U) Y to suy (re, im pairs).
inline void add_cross_spectrum(const double* U, const double* Y, Index nbins, double* syy, double* suy) {
  for (Index k = 0; k < nbins; ++k) {
    const double ur = U[2 * k], ui = U[2 * k + 1], yr = Y[2 * k], yi = Y[2 * k + 1];
    syy[k] += yr * yr + yi * yi;
    suy[2 * k] += ur * yr + ui * yi;      // Re(conj(U) Y)
    suy[2 * k + 1] += ur * yi - ui * yr;  // Im(conj(U) Y)
  }
}

// The segments of chunk c, transformed and summed into its sums.
inline void sum_chunk(Index c, const SegmentPlan& plan, const Channel& input, const std::vector<Channel>& outputs,
                      const SegmentLoader& loader, const detail::RealForwardFft& fft, SegmentBuffers& ws, ChunkSums& sums) {
  const Index nbins = fft.bins();
  const Index first = c * plan.nseg / plan.chunks;
  const Index last = (c + 1) * plan.nseg / plan.chunks;
  double* suu = sums.uu.data() + c * nbins;
  for (Index s = first; s < last; ++s) {
    const Index start = s * plan.step;
    prefetch_next_segment(input, outputs, start + plan.nfft, std::min(start + plan.step + plan.nfft, plan.n));
    loader.load(input.samples.data() + start, ws.segment.data());
    fft.execute(ws.segment.data(), ws.u.data());
    const double* U = reinterpret_cast<const double*>(ws.u.data());
    add_auto_spectrum(U, nbins, suu);
    for (Index o = 0; o < plan.nout; ++o) {
      loader.load(outputs[static_cast<std::size_t>(o)].samples.data() + start, ws.segment.data());
      fft.execute(ws.segment.data(), ws.y.data());
      add_cross_spectrum(U, reinterpret_cast<const double*>(ws.y.data()), nbins, sums.yy.data() + (c * plan.nout + o) * nbins,
                         reinterpret_cast<double*>(sums.uy.data() + (c * plan.nout + o) * nbins));
    }
  }
}

int spectra_threads(const WelchOptions& options, const SegmentPlan& plan) {
  int threads = options.threads == 0 ? static_cast<int>(std::max(1U, std::thread::hardware_concurrency()))
                                     : options.threads;
  const double work = static_cast<double>(plan.nseg) * static_cast<double>(plan.nfft) * static_cast<double>(1 + plan.nout);
  if (work < kMinWorkForThreads) threads = 1;
  return static_cast<int>(std::min<Index>(threads, plan.chunks));
}

// Every chunk summed, the chunks shared out among the threads as they come free.
ChunkSums sum_chunks(const SegmentPlan& plan, const Channel& input, const std::vector<Channel>& outputs, const WelchOptions& options,
                     const SegmentLoader& loader, const detail::RealForwardFft& fft) {
  const Index nbins = fft.bins();
  ChunkSums sums{std::vector<double>(static_cast<std::size_t>(plan.chunks * nbins), 0.0),
                 std::vector<double>(static_cast<std::size_t>(plan.chunks * plan.nout * nbins), 0.0),
                 std::vector<Complex>(static_cast<std::size_t>(plan.chunks * plan.nout * nbins), Complex(0.0, 0.0))};
  const int threads = spectra_threads(options, plan);
  std::vector<SegmentBuffers> workspaces;
  workspaces.reserve(static_cast<std::size_t>(threads));
  for (int t = 0; t < threads; ++t) {
    workspaces.push_back(SegmentBuffers{detail::FftwBuffer<double>(plan.nfft), detail::FftwBuffer<Complex>(nbins),
                                        detail::FftwBuffer<Complex>(nbins)});
  }
  std::atomic<Index> next_chunk{0};
  auto worker = [&](SegmentBuffers& ws) {
    for (Index c = next_chunk.fetch_add(1); c < plan.chunks; c = next_chunk.fetch_add(1)) {
      sum_chunk(c, plan, input, outputs, loader, fft, ws, sums);
    }
  };
  if (threads == 1) {
    worker(workspaces[0]);
  } else {
    std::vector<std::jthread> pool;
    pool.reserve(static_cast<std::size_t>(threads - 1));
    for (int t = 1; t < threads; ++t) pool.emplace_back([&, t] { worker(workspaces[static_cast<std::size_t>(t)]); });
    worker(workspaces[0]);
  }  // jthreads join here
  return sums;
}

// The chunks' sums added up and scaled to densities: 1 / (fs sum w^2), averaged over the segments,
// one-sided: every bin that has a negative-frequency twin (all but DC and, for even nfft, Nyquist)
// counts twice.
void scale_spectra(const ChunkSums& sums, const SegmentPlan& plan, const Eigen::VectorXd& window, Index nbins, double sample_rate_Hz,
                   CrossSpectra& result) {
  const double scale = 1.0 / (sample_rate_Hz * window.squaredNorm() * static_cast<double>(plan.nseg));
  Eigen::VectorXd factor = Eigen::VectorXd::Constant(nbins, 2.0 * scale);
  factor(0) = scale;
  if (plan.nfft % 2 == 0) factor(nbins - 1) = scale;

  result.Suu = Eigen::VectorXd::Zero(nbins);
  for (Index c = 0; c < plan.chunks; ++c) {
    result.Suu += Eigen::Map<const Eigen::VectorXd>(sums.uu.data() + c * nbins, nbins);
  }
  result.Suu.array() *= factor.array();
  for (Index o = 0; o < plan.nout; ++o) {
    Eigen::VectorXd syy = Eigen::VectorXd::Zero(nbins);
    Eigen::VectorXcd suy = Eigen::VectorXcd::Zero(nbins);
    for (Index c = 0; c < plan.chunks; ++c) {
      syy += Eigen::Map<const Eigen::VectorXd>(sums.yy.data() + (c * plan.nout + o) * nbins, nbins);
      suy += Eigen::Map<const Eigen::VectorXcd>(sums.uy.data() + (c * plan.nout + o) * nbins, nbins);
    }
    syy.array() *= factor.array();
    suy.array() *= factor.array().cast<Complex>();
    result.Syy.push_back(std::move(syy));
    result.Suy.push_back(std::move(suy));
  }
}

}  // namespace

CrossSpectra cross_spectra(const Channel& input, const std::vector<Channel>& outputs, double sample_rate_Hz,
                           const WelchOptions& options, const std::string& source) {
  const SegmentPlan plan = plan_segments(input, outputs, sample_rate_Hz, options, source);
  const Eigen::VectorXd window = make_window(options.window, plan.nfft);
  const SegmentLoader loader(window, options.detrend);
  const detail::RealForwardFft fft(plan.nfft);
  const Index nbins = fft.bins();
  const ChunkSums sums = sum_chunks(plan, input, outputs, options, loader, fft);
  // Non-finite sums from finite samples (overflow of values near 1e154) are returned as they are.
  const bool sums_ok = all_finite(sums.uu.data(), static_cast<Index>(sums.uu.size())) &&
                       all_finite(sums.yy.data(), static_cast<Index>(sums.yy.size())) &&
                       all_finite(reinterpret_cast<const double*>(sums.uy.data()), 2 * static_cast<Index>(sums.uy.size()));
  if (!sums_ok) check_channels(input, outputs, source);

  CrossSpectra result;
  result.input = input.name;
  for (const auto& out : outputs) result.outputs.push_back(out.name);
  result.window = options.window;
  result.detrend = options.detrend;
  result.nfft = plan.nfft;
  result.noverlap = plan.noverlap;
  result.averages = plan.nseg;
  result.sample_rate = sample_rate_Hz;
  result.freq_Hz.resize(nbins);
  for (Index k = 0; k < nbins; ++k) {
    result.freq_Hz(k) = static_cast<double>(k) * sample_rate_Hz / static_cast<double>(plan.nfft);
  }
  scale_spectra(sums, plan, window, nbins, sample_rate_Hz, result);
  return result;
}

Eigen::VectorXd coherence(const CrossSpectra& spectra, Index output) {
  assert(output >= 0 && output < static_cast<Index>(spectra.Suy.size()));
  const auto& suy = spectra.Suy[static_cast<std::size_t>(output)];
  const auto& syy = spectra.Syy[static_cast<std::size_t>(output)];
  Eigen::VectorXd gamma2(suy.size());
  for (Index k = 0; k < suy.size(); ++k) {
    const double den = spectra.Suu(k) * syy(k);
    gamma2(k) = den > 0.0 ? std::norm(suy(k)) / den : std::numeric_limits<double>::quiet_NaN();
  }
  return gamma2;
}

Frf frf_from_spectra(const CrossSpectra& spectra, FrfEstimator estimator, const std::string& source) {
  if (!(spectra.Suu.array() > 0.0).any()) {
    throw InputError(source, spectra.input, "an input with non-zero power", "zero power at every frequency");
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Frf frf;
  frf.freq_Hz = spectra.freq_Hz;
  frf.input = spectra.input;
  frf.outputs = spectra.outputs;
  for (std::size_t o = 0; o < spectra.Suy.size(); ++o) {
    const auto& suy = spectra.Suy[o];
    const auto& syy = spectra.Syy[o];
    // A silent output (all samples equal, or zero after detrending) has no FRF: its coherence
    // would be 0/0 at every frequency.
    if (!(syy.array() > 0.0).any()) {
      throw InputError(source, spectra.outputs[o], "an output with non-zero power (a varying signal)",
                       "zero power at every frequency (a constant channel: check the channel name and its wiring)");
    }
    Eigen::VectorXcd h(suy.size());
    if (estimator == FrfEstimator::kH1) {
      for (Index k = 0; k < h.size(); ++k) h(k) = spectra.Suu(k) != 0.0 ? suy(k) / spectra.Suu(k) : Complex(nan, nan);
    } else {
      // H2 = Syy / Syu, Syu = conj(Suy): for y = H u both equal H.
      for (Index k = 0; k < h.size(); ++k) h(k) = suy(k) != 0.0 ? syy(k) / std::conj(suy(k)) : Complex(nan, nan);
    }
    frf.coherence.push_back(coherence(spectra, static_cast<Index>(o)));
    frf.H.push_back(std::move(h));
  }
  frf.provenance.effective_averages = effective_averages(spectra.window, spectra.nfft, spectra.noverlap, spectra.averages);
  // A NaN line (zero denominator) keeps a NaN std: validate() rejects the FRF there as for H.
  for (std::size_t o = 0; o < frf.H.size(); ++o) {
    frf.std_H.push_back(frf_standard_deviation(frf.H[o], frf.coherence[o].unaryExpr([](double c) { return std::isfinite(c) ? c : 0.0; }),
                                               frf.provenance.effective_averages));
  }
  frf.provenance.source = source;
  frf.provenance.estimator = to_string(estimator);
  frf.provenance.window = to_string(spectra.window);
  frf.provenance.nfft = spectra.nfft;
  frf.provenance.overlap =
      spectra.nfft > 0 ? static_cast<double>(spectra.noverlap) / static_cast<double>(spectra.nfft) : 0.0;
  frf.provenance.detrend = to_string(spectra.detrend);
  frf.provenance.averages = spectra.averages;
  frf.provenance.sample_rate = spectra.sample_rate;
  return frf;
}

FrfEstimate estimate_frf(const Channel& input, const std::vector<Channel>& outputs, double sample_rate_Hz,
                         const WelchOptions& options, const std::string& source) {
  if (outputs.empty()) throw InputError(source, "outputs", "at least one output channel", "none");
  FrfEstimate estimate;
  estimate.spectra = cross_spectra(input, outputs, sample_rate_Hz, options, source);
  estimate.frf = frf_from_spectra(estimate.spectra, options.estimator, source);
  // The fraction the user asked for (noverlap / nfft may differ from it by the floor).
  estimate.frf.provenance.overlap = options.overlap;
  return estimate;
}

Eigen::VectorXd welch_psd(const Eigen::VectorXd& x, double sample_rate_Hz, const WelchOptions& options) {
  return cross_spectra(channel("x", x), {}, sample_rate_Hz, options).Suu;
}

Eigen::VectorXcd welch_csd(const Eigen::VectorXd& x, const Eigen::VectorXd& y, double sample_rate_Hz,
                           const WelchOptions& options) {
  return cross_spectra(channel("x", x), {channel("y", y)}, sample_rate_Hz, options).Suy[0];
}

}  // namespace piezobench::dsp
