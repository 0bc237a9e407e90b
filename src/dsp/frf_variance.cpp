#include "piezobench/dsp/frf_variance.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/statistics.hpp"

namespace piezobench::dsp {

using Eigen::Index;

double effective_averages(WindowType window, Index nfft, Index noverlap, Index segments) {
  if (nfft < 2) throw InputError("welch", "nfft", "at least 2 samples", std::to_string(nfft));
  if (noverlap < 0 || noverlap >= nfft) {
    throw InputError("welch", "noverlap", "in [0, nfft = " + std::to_string(nfft) + ")", std::to_string(noverlap));
  }
  if (segments < 1) throw InputError("welch", "averages", "at least 1 segment", std::to_string(segments));
  const Eigen::VectorXd w = make_window(window, nfft);
  const double energy = w.squaredNorm();
  const Index shift = nfft - noverlap;
  const auto k = static_cast<double>(segments);
  double sum = 0.0;
  // Segments further apart than nfft do not share samples: rho(j) = 0 there.
  for (Index j = 1; j < segments && j * shift < nfft; ++j) {
    const Index lag = j * shift;
    const double rho = w.head(nfft - lag).dot(w.tail(nfft - lag)) / energy;
    sum += (1.0 - static_cast<double>(j) / k) * rho * rho;
  }
  return k / (1.0 + 2.0 * sum);
}

double adjacent_line_correlation(WindowType window, Index nfft, Index noverlap, Index segments) {
  (void)effective_averages(window, nfft, noverlap, segments);  // the same validation
  const Eigen::VectorXd w = make_window(window, nfft);
  const Index shift = nfft - noverlap;
  const double step = 2.0 * std::numbers::pi / static_cast<double>(nfft);
  double num = 0.0, den = 0.0;
  for (Index j = 1 - segments; j < segments; ++j) {
    const Index lag = std::abs(j) * shift;
    if (lag >= nfft) continue;  // no shared samples
    // A_j(d) = sum_n w(n) w(n + j D) e^(i d step n); |A_j| = |A_-j| up to a phase, so |j| will do.
    std::complex<double> a1 = 0.0;
    double a0 = 0.0;
    for (Index n = 0; n + lag < nfft; ++n) {
      const double ww = w(n) * w(n + lag);
      a0 += ww;
      a1 += ww * std::polar(1.0, step * static_cast<double>(n));
    }
    const double count = static_cast<double>(segments - std::abs(j));
    num += count * std::norm(a1);
    den += count * a0 * a0;
  }
  return den > 0.0 ? num / den : 0.0;
}

std::optional<WelchLayout> welch_layout(const FrfProvenance& p) {
  if (p.window.empty() || p.nfft < 2 || p.averages < 1) return std::nullopt;
  WelchLayout l;
  try {
    l.window = window_type_from_string(p.window);
  } catch (const InputError&) {
    return std::nullopt;
  }
  l.noverlap = static_cast<Index>(std::floor(p.overlap * static_cast<double>(p.nfft)));
  if (l.noverlap < 0 || l.noverlap >= p.nfft) return std::nullopt;
  return l;
}

double adjacent_line_correlation(const FrfProvenance& p) {
  const auto l = welch_layout(p);
  return l ? adjacent_line_correlation(l->window, p.nfft, l->noverlap, p.averages) : 0.0;
}

double frf_relative_std(double coherence, double effective_averages) {
  if (!(effective_averages > 0.0)) {
    throw InputError("frf variance", "effective averages", "a number > 0", format_number_exact(effective_averages));
  }
  const double g2 = std::clamp(coherence, 1e-12, 1.0);
  return std::sqrt((1.0 - g2) / (2.0 * effective_averages * g2));
}

double frf_band_factor(double effective_averages, double level) {
  if (!(effective_averages > 1.0 && std::isfinite(effective_averages))) {
    throw InputError("frf variance", "effective averages", "a number > 1 (a band needs at least two averages)",
                     format_number(effective_averages));
  }
  if (!(level > 0.0 && level < 1.0)) throw InputError("frf variance", "level", "a probability in (0, 1)", format_number(level));
  const double n = effective_averages;
  return std::sqrt(n / (n - 1.0)) * core::student_t_quantile(0.5 * (1.0 + level), 2.0 * n - 2.0);
}

Eigen::VectorXd frf_standard_deviation(const Eigen::VectorXcd& H, const Eigen::VectorXd& coherence, double effective_averages) {
  if (H.size() != coherence.size()) {
    throw InputError("frf variance", "coherence", std::to_string(H.size()) + " values (one per line)", std::to_string(coherence.size()));
  }
  Eigen::VectorXd s(H.size());
  for (Index k = 0; k < H.size(); ++k) s(k) = std::abs(H(k)) * frf_relative_std(coherence(k), effective_averages);
  return s;
}

Eigen::VectorXd FrfNoiseEstimate::relative_std_at(const Eigen::VectorXcd& model) const {
  Eigen::VectorXd eps(model.size());
  const double a = additive_std * additive_std, b = relative_std * relative_std;
  for (Index k = 0; k < model.size(); ++k) {
    const double g2 = std::norm(model(k));
    eps(k) = g2 > 0.0 ? std::sqrt(a / g2 + b) : std::numeric_limits<double>::infinity();
  }
  return eps;
}

namespace {

// The negative log-likelihood (up to a constant) of the per-part variances m_k = a + b x_k for the
// samples v_k (|H_k - G_k|^2 / 2, exponential with mean m_k); inf where a variance is not positive.
double noise_cost(const Eigen::VectorXd& v, const Eigen::VectorXd& x, double a, double b) {
  double cost = 0.0;
  for (Index k = 0; k < v.size(); ++k) {
    const double m = a + b * x(k);
    if (m == 0.0 && v(k) == 0.0) continue;  // a line the model meets exactly, with no variance
    if (!(m > 0.0)) return std::numeric_limits<double>::infinity();
    cost += v(k) / m + std::log(m);
  }
  return cost;
}

// Both components positive, by iteratively reweighted least squares from the additive-only fit;
// nullopt when an iterate leaves the positive quadrant (the optimum is then on its boundary).
std::optional<std::pair<double, double>> both_components(const Eigen::VectorXd& v, const Eigen::VectorXd& x, double a0) {
  double a = a0, b = 0.0;
  for (int it = 0; it < 100; ++it) {
    // Weighted least squares of v on [1, x] with weights 1 / m^2.
    double s0 = 0, s1 = 0, s2 = 0, t0 = 0, t1 = 0;
    for (Index k = 0; k < v.size(); ++k) {
      const double m = a + b * x(k), w = 1.0 / (m * m);
      s0 += w, s1 += w * x(k), s2 += w * x(k) * x(k), t0 += w * v(k), t1 += w * x(k) * v(k);
    }
    const double det = s0 * s2 - s1 * s1;
    if (!(det > 0.0)) return std::nullopt;
    const double a1 = (s2 * t0 - s1 * t1) / det, b1 = (s0 * t1 - s1 * t0) / det;
    if (!(a1 > 0.0 && b1 > 0.0)) return std::nullopt;
    const bool done = std::abs(a1 - a) <= 1e-10 * a1 && std::abs(b1 - b) <= 1e-10 * b1;
    a = a1, b = b1;
    if (done) break;
  }
  return std::make_pair(a, b);
}

}  // namespace

FrfNoiseEstimate estimate_frf_noise(const Eigen::VectorXcd& H, const Eigen::VectorXcd& model) {
  if (H.size() != model.size()) {
    throw InputError("frf noise", "model", std::to_string(H.size()) + " values (one per line)", std::to_string(model.size()));
  }
  if (H.size() < 3) throw InputError("frf noise", "H", "at least 3 lines", std::to_string(H.size()));
  Eigen::VectorXd v(H.size()), x(H.size());
  for (Index k = 0; k < H.size(); ++k) {
    v(k) = 0.5 * std::norm(H(k) - model(k));
    x(k) = std::norm(model(k));
  }
  return fit_frf_noise(v, x);
}

FrfNoiseEstimate fit_frf_noise(const Eigen::VectorXd& v, const Eigen::VectorXd& x) {
  if (v.size() != x.size()) {
    throw InputError("frf noise", "model", std::to_string(v.size()) + " values (one per line)", std::to_string(x.size()));
  }
  if (v.size() < 3) throw InputError("frf noise", "variance", "at least 3 lines", std::to_string(v.size()));
  if (!v.allFinite() || !x.allFinite()) throw NumericalError("frf noise", "a non-finite residual or model value", false);
  FrfNoiseEstimate e;
  const double additive = v.mean();
  if (!(additive > 0.0)) return e;  // an exact fit: no noise to see
  // The candidates: additive only (its ML value is the mean), proportional only (the mean of v / x),
  // both; the most likely wins.
  double best_a = additive, best_b = 0.0, best = noise_cost(v, x, additive, 0.0);
  if ((x.array() > 0.0).all()) {
    const double b = (v.array() / x.array()).mean();
    if (const double c = noise_cost(v, x, 0.0, b); c < best) best = c, best_a = 0.0, best_b = b;
  }
  if (const auto ab = both_components(v, x, additive)) {
    if (const double c = noise_cost(v, x, ab->first, ab->second); c < best) best = c, best_a = ab->first, best_b = ab->second;
  }
  e.additive_std = std::sqrt(best_a);
  e.relative_std = std::sqrt(best_b);
  return e;
}

RandomFrfStd random_frf_std(const Eigen::VectorXcd& H, const Eigen::VectorXd& std_H, const Eigen::VectorXcd& model,
                            const Eigen::VectorXd& leakage, double effective_averages) {
  const Index n = H.size();
  for (const auto& [size, name] : {std::pair{std_H.size(), "std_H"}, std::pair{model.size(), "model"}, std::pair{leakage.size(), "leakage"}}) {
    if (size != n) throw InputError("frf noise", name, std::to_string(n) + " values (one per line)", std::to_string(size));
  }
  if (!(effective_averages > 0.0)) {
    throw InputError("frf noise", "effective averages", "a number > 0", format_number_exact(effective_averages));
  }
  RandomFrfStd out;
  out.std = std_H;
  constexpr double kLeakageShare = 0.1;  // of the measured coherence loss
  constexpr Index kMinClean = 8, kGroups = 8;
  std::vector<Index> clean;
  std::vector<bool> is_clean(static_cast<std::size_t>(n), false);
  for (Index k = 0; k < n; ++k) {
    const double abs_h = std::abs(H(k));
    if (!(abs_h > 0.0 && std_H(k) > 0.0 && leakage(k) > 0.0)) continue;
    const double eps = std_H(k) / abs_h;
    const double q = 2.0 * effective_averages * eps * eps;  // (1 - gamma^2) / gamma^2
    if (1.0 / leakage(k) - 1.0 <= kLeakageShare * q) {
      clean.push_back(k);
      is_clean[static_cast<std::size_t>(k)] = true;
    }
  }
  out.clean_lines = static_cast<Index>(clean.size());
  if (out.clean_lines < kMinClean) return out;
  Eigen::VectorXd v(out.clean_lines), x(out.clean_lines);
  for (Index i = 0; i < out.clean_lines; ++i) {
    const Index k = clean[static_cast<std::size_t>(i)];
    v(i) = std_H(k) * std_H(k);
    x(i) = std::norm(model(k));
  }
  out.noise = fit_frf_noise(v, x);
  const double a = out.noise.additive_std * out.noise.additive_std, b = out.noise.relative_std * out.noise.relative_std;
  // The model describes the clean lines when their variance over it averages to 1 (within a factor 2)
  // in every group of consecutive clean lines.
  bool adequate = a + b > 0.0;
  for (Index g = 0; g < kGroups && adequate; ++g) {
    const Index lo = g * out.clean_lines / kGroups, hi = (g + 1) * out.clean_lines / kGroups;
    double ratio = 0.0;
    for (Index i = lo; i < hi; ++i) ratio += v(i) / (a + b * x(i));
    ratio /= static_cast<double>(hi - lo);
    adequate = ratio >= 0.5 && ratio <= 2.0;
  }
  out.smooth_model = adequate;
  for (Index k = 0; k < n; ++k) {
    const double m = std::sqrt(a + b * std::norm(model(k)));
    if (adequate) {
      out.std(k) = m;
    } else if (!is_clean[static_cast<std::size_t>(k)] && m > 0.0) {
      out.std(k) = std::min(std_H(k), m);
    }
  }
  return out;
}

std::vector<Eigen::VectorXd> std_from_coherence(Frf& frf) {
  const FrfProvenance& p = frf.provenance;
  const auto l = welch_layout(p);
  if (frf.coherence.size() != frf.H.size() || frf.H.empty() || !l) return {};
  const double n_d = effective_averages(l->window, p.nfft, l->noverlap, p.averages);
  if (frf.provenance.effective_averages <= 0.0) frf.provenance.effective_averages = n_d;
  std::vector<Eigen::VectorXd> std_H;
  for (std::size_t i = 0; i < frf.H.size(); ++i) std_H.push_back(frf_standard_deviation(frf.H[i], frf.coherence[i], n_d));
  return std_H;
}

}  // namespace piezobench::dsp
