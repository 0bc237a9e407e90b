#pragma once
// Welch's averaged modified periodograms (P. D. Welch, "The use of fast Fourier transform for the
// estimation of power spectra", IEEE Trans. Audio Electroacoust. 15(2), 1967): auto and cross
// spectral densities of one input u and several outputs y_i, and from them the H1 and H2
// frequency-response estimators and the coherence (Bendat & Piersol, "Engineering applications of
// correlation and spectral analysis", 2nd ed., 1993, ch. 3 and 9).
//
// Conventions (docs/dsp-conventions.md), identical to scipy.signal.csd/welch/coherence and to
// Octave's cpsd/pwelch/tfestimate/mscohere for the same window, overlap and detrending:
//  - segments of nfft samples start every nfft - noverlap samples, noverlap = floor(overlap*nfft);
//    the last incomplete segment is dropped; each segment is detrended, then windowed, then
//    transformed (no zero padding: the segment length is the FFT length, any integer >= 2);
//  - Suy(f) = C * mean_segments( conj(U(f)) * Y(f) )   (scipy csd(u, y); Octave cpsd(u, y))
//  - density scaling C = 1 / (fs * sum(w^2)), one-sided: bins 1 .. ceil(nfft/2)-1 are doubled,
//    DC is not, and for even nfft neither is the Nyquist bin nfft/2;
//  - frequencies k * fs / nfft, k = 0 .. floor(nfft/2), in Hz;
//  - H1 = Suy / Suu, H2 = Syy / Syu with Syu = conj(Suy), coherence = |Suy|^2 / (Suu * Syy).
//
// Cost: each channel's segment is transformed once (FFTW r2c, one plan per nfft shared by the
// process), so the whole estimate costs (1 + outputs) * segments real FFTs plus O(nfft) work per
// segment and channel; nothing is allocated per segment. Segments are split into a fixed number of
// contiguous chunks that are summed in order, so the result does not depend on the thread count.
#include <Eigen/Dense>
#include <span>
#include <string>
#include <vector>

#include "piezobench/dsp/detrend.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/dsp/window.hpp"

namespace piezobench::dsp {

enum class FrfEstimator {
  kH1,  // "H1" = Suy / Suu: unbiased by noise on the output
  kH2,  // "H2" = Syy / Syu: unbiased by noise on the input
};
std::string to_string(FrfEstimator estimator);
FrfEstimator frf_estimator_from_string(const std::string& name);  // InputError field "estimator"

struct WelchOptions {
  WindowType window = WindowType::kHannPeriodic;  // scipy's default window
  Eigen::Index nfft = 1024;   // segment length = FFT length, samples; any integer >= 2
  double overlap = 0.5;       // fraction of nfft shared by consecutive segments, in [0, 1)
  Detrend detrend = Detrend::kNone;  // NB scipy's default is "constant" (= kMean)
  FrfEstimator estimator = FrfEstimator::kH1;  // used by estimate_frf
  int threads = 0;            // worker threads; 0 = all cores

  // InputError naming the bad field ("nfft", "overlap", "threads"), prefixed with `source`.
  void validate(const std::string& source = "") const;
  // Samples shared by consecutive segments: floor(overlap * nfft), as Octave's pwelch (scipy takes
  // the count itself: pass noverlap = this value to scipy).
  [[nodiscard]] Eigen::Index noverlap() const;
};

// The settings `run` and `frf` share for a record of `samples` at `sample_rate_Hz` (one procedure,
// one set of defaults): segments of 1 / resolution_Hz seconds (4 s: 0.25 Hz bins) limited to a
// quarter of the record (at least 7 averages with 50 % overlap) and to at least 256 samples; the
// mean removed per segment (a linear-trend removal would distort the lowest bins); hann-periodic,
// 50 % overlap, H1. InputError (prefixed with `source`) for a non-positive rate or resolution.
[[nodiscard]] Eigen::Index segment_length_for_record(Eigen::Index samples, double sample_rate_Hz,
                                                     double resolution_Hz = 0.25, const std::string& source = "");
[[nodiscard]] WelchOptions welch_options_for_record(Eigen::Index samples, double sample_rate_Hz,
                                                    double resolution_Hz = 0.25, const std::string& source = "");

// A named, borrowed record of samples (the caller keeps the storage alive during the call).
struct Channel {
  std::string name;
  std::span<const double> samples;
};
// Convenience: a Channel viewing an Eigen vector (which must outlive it; temporaries, e.g. an
// expression like x.head(n), are refused at compile time).
Channel channel(std::string name, const Eigen::VectorXd& samples);
Channel channel(std::string name, Eigen::VectorXd&& samples) = delete;

// One-sided spectral densities of one input and several outputs.
struct CrossSpectra {
  Eigen::VectorXd freq_Hz;              // k * fs / nfft, k = 0 .. floor(nfft/2)
  std::string input;                    // input channel name
  std::vector<std::string> outputs;     // output channel names
  Eigen::VectorXd Suu;                  // input PSD, [u]^2/Hz
  std::vector<Eigen::VectorXd> Syy;     // Syy[i]: PSD of output i, [y_i]^2/Hz
  std::vector<Eigen::VectorXcd> Suy;    // Suy[i]: CSD conj(U) Y_i, [u][y_i]/Hz (scipy csd(u, y_i))
  WindowType window = WindowType::kHannPeriodic;
  Detrend detrend = Detrend::kNone;
  Eigen::Index nfft = 0;
  Eigen::Index noverlap = 0;
  Eigen::Index averages = 0;            // number of segments
  double sample_rate = 0.0;             // Hz
};

// All spectra in one pass over the data. Preconditions checked (InputError, prefixed with
// `source`, field = the channel name): sample_rate_Hz finite and > 0 (field "sample rate"), every
// output as long as the input, every sample finite (the message gives the first bad index), the
// record at least nfft samples long. Zero outputs are allowed (then only Suu is computed).
CrossSpectra cross_spectra(const Channel& input, const std::vector<Channel>& outputs,
                           double sample_rate_Hz, const WelchOptions& options,
                           const std::string& source = "");

// H1 or H2 and the coherence of every output. InputError (field = input name) when the input has
// zero power at every frequency; for H2 also when an output has. A bin where a denominator is
// exactly zero gives NaN there (and Frf::validate will reject the result).
Frf frf_from_spectra(const CrossSpectra& spectra, FrfEstimator estimator, const std::string& source = "");

// |Suy|^2 / (Suu Syy) of output `output` (NaN where the denominator is zero).
Eigen::VectorXd coherence(const CrossSpectra& spectra, Eigen::Index output);

struct FrfEstimate {
  Frf frf;               // options.estimator; provenance filled in (source, window, nfft, ...)
  CrossSpectra spectra;  // the raw densities it was computed from
};

// FrfEstimate's figures as its declaration shows them (read from its frf and spectra).
inline const Eigen::VectorXd* estimate_freq_Hz(const FrfEstimate& e) { return &e.spectra.freq_Hz; }
inline const std::vector<Eigen::VectorXcd>* estimate_H(const FrfEstimate& e) { return &e.frf.H; }
inline const std::vector<Eigen::VectorXd>* estimate_coherence(const FrfEstimate& e) { return &e.frf.coherence; }
inline const std::vector<Eigen::VectorXd>* estimate_std_H(const FrfEstimate& e) { return &e.frf.std_H; }
inline const Eigen::VectorXd* estimate_Suu(const FrfEstimate& e) { return &e.spectra.Suu; }
inline const std::vector<Eigen::VectorXd>* estimate_Syy(const FrfEstimate& e) { return &e.spectra.Syy; }
inline const std::vector<Eigen::VectorXcd>* estimate_Suy(const FrfEstimate& e) { return &e.spectra.Suy; }
inline Eigen::Index estimate_averages(const FrfEstimate& e) { return e.spectra.averages; }

// The spectra's window, detrend and segment settings are in frf.provenance.
constexpr auto describe(core::Type<FrfEstimate>) {
  using S = FrfEstimate;
  using namespace core::shown;
  return core::fields<S>("FrfEstimate", "H1 (or H2), coherence and the Welch densities of every output, from one pass over the data",
      core::derived("freq_Hz", &estimate_freq_Hz, kHertz, "k fs / nfft, k = 0 .. nfft / 2"),
      core::derived("H", &estimate_H, kNone, "H[i](k): output i / input (frf.H)"),
      core::derived("coherence", &estimate_coherence, kRatio, "same layout as H (frf.coherence)"),
      core::derived("std_H", &estimate_std_H, kNone, "standard deviation of H's random error, H's units (frf.std_H)"),
      core::derived("Suu", &estimate_Suu, kNone, "input PSD, [u]^2/Hz"),
      core::derived("Syy", &estimate_Syy, kNone, "Syy[i]: PSD of output i, [y_i]^2/Hz"),
      core::derived("Suy", &estimate_Suy, kNone, "Suy[i]: CSD conj(U) Y_i, [u][y_i]/Hz (scipy csd(u, y_i))"),
      core::derived("averages", &estimate_averages, kNone, "segments averaged"),
      core::field("frf", &S::frf, kNone, "the FRF with its provenance (window, nfft, overlap, ...)"));
}
FrfEstimate estimate_frf(const Channel& input, const std::vector<Channel>& outputs, double sample_rate_Hz,
                         const WelchOptions& options, const std::string& source = "");

// Single-channel conveniences (same conventions): scipy welch(x) and csd(x, y).
// x in any unit u: the PSD in u^2/Hz.
Eigen::VectorXd welch_psd(const Eigen::VectorXd& x, double sample_rate_Hz, const WelchOptions& options);
// x, y in units u, v: the CSD in u v/Hz.
Eigen::VectorXcd welch_csd(const Eigen::VectorXd& x, const Eigen::VectorXd& y, double sample_rate_Hz,
                           const WelchOptions& options);

}  // namespace piezobench::dsp
