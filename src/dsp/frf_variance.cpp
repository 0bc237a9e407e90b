#include "piezobench/dsp/frf_variance.hpp"

#include <algorithm>
#include <cmath>
#include <string>

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

std::vector<Eigen::VectorXd> std_from_coherence(Frf& frf) {
  const FrfProvenance& p = frf.provenance;
  if (frf.coherence.size() != frf.H.size() || frf.H.empty() || p.nfft < 2 || p.averages < 1 || p.window.empty()) return {};
  WindowType window{};
  try {
    window = window_type_from_string(p.window);
  } catch (const InputError&) {
    return {};  // a window piezobench does not know: no variance rather than a wrong one
  }
  const auto noverlap = static_cast<Index>(std::floor(p.overlap * static_cast<double>(p.nfft)));
  if (noverlap < 0 || noverlap >= p.nfft) return {};
  const double n_d = effective_averages(window, p.nfft, noverlap, p.averages);
  if (frf.provenance.effective_averages <= 0.0) frf.provenance.effective_averages = n_d;
  std::vector<Eigen::VectorXd> std_H;
  for (std::size_t i = 0; i < frf.H.size(); ++i) std_H.push_back(frf_standard_deviation(frf.H[i], frf.coherence[i], n_d));
  return std_H;
}

}  // namespace piezobench::dsp
