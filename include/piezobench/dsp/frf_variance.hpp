#pragma once
// The random error of a Welch FRF estimate (J. S. Bendat, A. G. Piersol, "Random data: analysis and
// measurement procedures", 4th ed., 2010, ch. 9, random errors of gain and phase factor estimates;
// "Engineering applications of correlation and spectral analysis", 2nd ed., 1993, ch. 9): with gamma^2
// the coherence and n_d the number of independent averages,
//
//   normalized random error of |H|:   eps = std(|H_est|) / |H| = sqrt((1 - gamma^2) / (2 n_d gamma^2))
//   standard deviation of the phase:  std(phase) = eps  (radians)
//
// i.e. the error H_est - H is a circular complex Gaussian whose real and imaginary parts each have
// the standard deviation |H| eps (along H it moves the magnitude, across H the phase). That per-part
// standard deviation, in H's units, is what dsp::Frf::std_H holds. The first-order formulas hold for
// eps below ~0.2 (B&P); the estimated coherence is used for gamma^2 (biased up for n_d < ~10).
//
// Overlapping windowed segments are not independent: n_d is the effective number of averages of
// Welch's method (P. D. Welch, IEEE Trans. Audio Electroacoust. 15(2), 1967, eq. 13-14):
//
//   n_d = K / (1 + 2 sum_{j=1}^{K-1} (1 - j/K) rho(j)^2),  rho(j) = sum_n w(n) w(n + j D) / sum_n w(n)^2
//
// for K segments of the window w shifted by D = nfft - noverlap samples (hann at 50 %: rho(1) = 1/6,
// n_d = K / 1.056 for large K; rectangular without overlap: n_d = K).
#include <Eigen/Dense>
#include <optional>
#include <vector>

#include "piezobench/dsp/frf.hpp"
#include "piezobench/dsp/window.hpp"

namespace piezobench::dsp {

// Welch's effective number of independent averages (above). InputError (source "welch") for
// nfft < 2, noverlap outside [0, nfft) or segments < 1.
[[nodiscard]] double effective_averages(WindowType window, Eigen::Index nfft, Eigen::Index noverlap, Eigen::Index segments);

// eps(gamma^2, n_d) above. The coherence is clamped to [1e-12, 1] (a zero coherence gives a large
// but finite error); n_d must be > 0 (else InputError).
// effective_averages: a count (n_d).
[[nodiscard]] double frf_relative_std(double coherence, double effective_averages);

// The smallest relative standard deviation a fit assumes for a line: below it (a coherence of
// nearly 1) the spectra's round-off and quantization, not the random error, limit the estimate, and
// a coherence of exactly 1 would give an infinite chi^2.
inline constexpr double kMinFitRelativeStd = 1e-4;
// The relative error of the models the fits use (eq. 2.3, the 2-DoF model) against a real bench:
// the IFF plant fit's rms misfit on the virtual bench is ~5 %. The fits weight a line by
// 1 / sqrt(eps^2 + kFitModelRelativeError^2): a line whose random error exceeds the model's (the
// anti-resonance, low coherence) counts less, while the well-measured lines keep equal weights (a
// pure 1/eps weighting lets the model's misfit where eps is smallest decide the fit).
inline constexpr double kFitModelRelativeError = 0.05;

// The correlation of the random errors of a Welch estimate at two adjacent lines (df apart): the
// windowed segments' spectra leak into the next bin, so the errors of H at lines k and k + 1 are not
// independent (hann without overlap: 4/9; hann at 50 %: 0.457 for 9 segments). For K segments of the
// window w (nfft samples) shifted by D = nfft - noverlap, the cross-spectrum's error at lines k, k + 1
// has the correlation
//
//   rho_1 = sum_j (K - |j|) |A_j(1)|^2 / sum_j (K - |j|) |A_j(0)|^2,   A_j(d) = sum_n w(n) w(n + j D) e^(2 pi i d n / nfft)
//
// (white input and noise; the same derivation as Welch's n_d, eq. 13-14). It is real and positive,
// for the real parts and the imaginary parts alike. H1's division by the input's own estimate lowers it
// slightly (hann 50 %, 9 segments: 0.434 +- 0.013 by Monte Carlo against 0.457). Lines further apart:
// hann's second neighbour is below 0.04, left out. InputError as effective_averages.
[[nodiscard]] double adjacent_line_correlation(WindowType window, Eigen::Index nfft, Eigen::Index noverlap, Eigen::Index segments);
// From an FRF's provenance (window, nfft, overlap, averages); 0 (independent) when one is unknown.
[[nodiscard]] double adjacent_line_correlation(const FrfProvenance& provenance);

// The Welch layout an FRF's provenance records (window, and noverlap = floor(overlap nfft) samples);
// nullopt when the window, nfft, overlap or averages are missing, or the window is one piezobench does
// not know (no variance rather than a wrong one).
struct WelchLayout {
  WindowType window{};
  Eigen::Index noverlap = 0;
};
[[nodiscard]] std::optional<WelchLayout> welch_layout(const FrfProvenance& provenance);

// The noise of an FRF whose variance nothing records (no coherence, or no Welch provenance), estimated
// from the residuals of a model fitted to it: each part of H_k - G_k has the variance
//
//   s_k^2 = additive_std^2 + relative_std^2 |G_k|^2
//
// (the sensor's noise, which does not shrink in a dip, plus an error proportional to the response).
// The two are the maximum-likelihood values for |H_k - G_k|^2 / 2 exponentially distributed with mean
// s_k^2 (a gamma GLM with identity link, by iteratively reweighted least squares; a component that
// would be negative is 0). The model's misfit counts as noise: the fits that use it then weight the
// lines by what they can tell, and their standard errors see the dip's noise instead of the average.
struct FrfNoiseEstimate {
  double additive_std = 0.0;  // per part, H's units
  double relative_std = 0.0;  // per part, a fraction of |G|
  // s_k / |G_k|: the relative standard deviation per part at each line (inf where G_k = 0).
  [[nodiscard]] Eigen::VectorXd relative_std_at(const Eigen::VectorXcd& model) const;
};
// InputError when the sizes differ or there are fewer than 3 lines; NumericalError for a non-finite
// residual.
[[nodiscard]] FrfNoiseEstimate estimate_frf_noise(const Eigen::VectorXcd& H, const Eigen::VectorXcd& model);
// The same maximum-likelihood fit from per-part variance samples v_k (|H_k - G_k|^2 / 2, or a Welch
// estimate's std_k^2: the same likelihood equations for any gamma shape) and the model's power
// |G_k|^2: `variance` and `model_power` in the same units as |H|^2. InputError / NumericalError as above.
[[nodiscard]] FrfNoiseEstimate fit_frf_noise(const Eigen::VectorXd& variance, const Eigen::VectorXd& model_power);

// The random error of a Welch estimate per line (per part, H's units): what makes the fitted
// parameters scatter from one record to the next, for their standard errors.
//
// B&P's std_k from the measured coherence also counts the window's leakage at a sharp resonance or
// dip (dsp::KernelGrid::leakage_coherence): power the estimate spreads over neighbouring lines, the
// same for every record of the same excitation, not a noise. Near the APA's resonance it is 10^3-10^5
// times the noise's share of 1 - gamma^2, and the 2-DoF tuning's intervals of ka, ga, gs were 1.6
// times their scatter (docs/uncertainty.md, section 6). Here the noise is the additive and
// proportional model of fit_frf_noise, fitted to std_k^2 on the lines where the leakage is below a
// tenth of the measured coherence loss (1/leakage - 1 <= 0.1 (1 - gamma^2)/gamma^2, gamma^2 from
// std_k / |H_k| and n_d) and evaluated at every line: smooth, it also leaves out the scatter of each
// line's own estimate (8 averages: +-35 %), which the weights computed from the same coherence would
// turn into standard errors 5-10 % too small.
// When fewer than 8 lines are clean, or the model misses the clean lines' variance (mean ratio outside
// [0.5, 2] in one of 8 consecutive groups: a coloured noise this model does not describe), the
// measured std_k is kept where the leakage is small and capped by the model elsewhere
// (smooth_model false). std_H, H, model and leakage: one value per line; n_d > 0.
struct RandomFrfStd {
  Eigen::VectorXd std;         // per part, H's units
  FrfNoiseEstimate noise;      // the model fitted on the clean lines
  Eigen::Index clean_lines = 0;
  bool smooth_model = false;   // std is the model at every line
};
[[nodiscard]] RandomFrfStd random_frf_std(const Eigen::VectorXcd& H, const Eigen::VectorXd& std_H, const Eigen::VectorXcd& model,
                                          const Eigen::VectorXd& leakage, double effective_averages);

// The coverage factor k of the 95 % (or `level`) band H +- k std_H with n_d effective averages:
//
//   k = sqrt(n_d / (n_d - 1)) t_{(1 + level) / 2}(2 n_d - 2)
//
// (N. R. Goodman, "Statistical analysis based on a certain multivariate complex Gaussian
// distribution", Ann. Math. Stat. 34, 1963; B&P ch. 9: with the coherence and the spectra
// themselves estimated from n_d averages, each part of H_est - H over its estimated standard
// deviation is Student's t with 2 n_d - 2 degrees of freedom, the estimate's variance having
// 2 n_d - 2 where eps counts 2 n_d). 2.27 at n_d = 8.6 (a 20 s record in 4 s segments), where 1.96
// covers 92.5 %; it tends to 1.96 as n_d grows. InputError for n_d <= 1 (no band: one average
// gives a coherence of 1) or a level outside (0, 1). effective_averages: a count (n_d); level: a fraction.
[[nodiscard]] double frf_band_factor(double effective_averages, double level = 0.95);

// std_H (per part, H's units) at each line: |H(k)| frf_relative_std(coherence(k), n_d). Sizes must
// agree (InputError).
[[nodiscard]] Eigen::VectorXd frf_standard_deviation(const Eigen::VectorXcd& H, const Eigen::VectorXd& coherence,
                                                     double effective_averages);

// std_H of an FRF read from a file that keeps the coherence and the Welch provenance (window, nfft,
// overlap, averages) but not the standard deviation (UFF 58 has no function type for it): n_d from
// the provenance (stored in provenance.effective_averages when it was 0), then frf_standard_deviation
// per output. Empty (and the FRF unchanged) when the coherence or a provenance field is missing or
// unknown.
[[nodiscard]] std::vector<Eigen::VectorXd> std_from_coherence(Frf& frf);

}  // namespace piezobench::dsp
