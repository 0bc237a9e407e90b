#include "piezobench/ident/modal.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {
namespace {

void check_data(const char* source, const Vector& omega, const CMatrix& h) {
  if (omega.size() < 3) throw InputError(source, "omega", "at least 3 frequencies", std::to_string(omega.size()));
  if (h.rows() != omega.size() || h.cols() < 1) {
    throw InputError(source, "h", std::to_string(omega.size()) + " rows (one per frequency), at least 1 column",
                     std::to_string(h.rows()) + "x" + std::to_string(h.cols()));
  }
  for (Index k = 0; k < omega.size(); ++k) {
    if (!std::isfinite(omega(k)) || omega(k) < 0.0 || (k > 0 && omega(k) <= omega(k - 1))) {
      throw InputError(source, "omega[" + std::to_string(k) + "]",
                       "finite, non-negative, strictly increasing frequencies", format_number(omega(k)));
    }
  }
  if (!h.allFinite()) throw InputError(source, "h", "finite values", "non-finite");
  if (h.cwiseAbs().maxCoeff() == 0.0) throw InputError(source, "h", "a nonzero response", "all zeros");
}

// [first, last] indices of the band; throws when it holds fewer than `needed` points.
std::pair<Index, Index> band(const char* source, const Vector& omega, double lo, double hi, Index needed) {
  Index first = 0, last = omega.size() - 1;
  while (first < omega.size() && omega(first) < lo) ++first;
  if (hi > 0.0) {
    while (last >= 0 && omega(last) > hi) --last;
  }
  if (last - first + 1 < needed) {
    throw InputError(source, "band", "at least " + std::to_string(needed) + " frequencies between " + format_number(lo) +
                                         " and " + (hi > 0.0 ? format_number(hi) : std::string("the end")) + " rad/s",
                     std::to_string(std::max<Index>(last - first + 1, 0)));
  }
  return {first, last};
}

Mode mode_from_pole(Complex pole) {
  Mode m;
  m.pole = pole;
  m.natural_frequency = std::abs(pole);
  m.damping = -pole.real() / m.natural_frequency;
  return m;
}

}  // namespace

double Mode::frequency_Hz() const { return natural_frequency / kTwoPi; }

void PeakPickingOptions::validate() const {
  const char* src = "peak picking options";
  if (!std::isfinite(min_omega) || min_omega < 0.0) throw InputError(src, "min_omega", ">= 0 rad/s", format_number(min_omega));
  if (!std::isfinite(max_omega) || max_omega < 0.0 || (max_omega > 0.0 && max_omega <= min_omega)) {
    throw InputError(src, "max_omega", "0 (all) or above min_omega", format_number(max_omega));
  }
  if (!std::isfinite(min_prominence) || min_prominence < 1.0) {
    throw InputError(src, "min_prominence", ">= 1", format_number(min_prominence));
  }
  if (max_modes < 0) throw InputError(src, "max_modes", ">= 0", std::to_string(max_modes));
}

void LscfOptions::validate() const {
  const char* src = "lscf options";
  if (!std::isfinite(min_omega) || min_omega < 0.0) throw InputError(src, "min_omega", ">= 0 rad/s", format_number(min_omega));
  if (!std::isfinite(max_omega) || max_omega < 0.0 || (max_omega > 0.0 && max_omega <= min_omega)) {
    throw InputError(src, "max_omega", "0 (all) or above min_omega", format_number(max_omega));
  }
  if (min_order < 1) throw InputError(src, "min_order", ">= 1", std::to_string(min_order));
  if (max_order < min_order) {
    throw InputError(src, "max_order", ">= min_order (" + std::to_string(min_order) + ")", std::to_string(max_order));
  }
  if (!(frequency_tolerance > 0.0 && frequency_tolerance < 1.0)) {
    throw InputError(src, "frequency_tolerance", "value in (0, 1)", format_number(frequency_tolerance));
  }
  if (!(damping_tolerance > 0.0 && damping_tolerance < 1.0)) {
    throw InputError(src, "damping_tolerance", "value in (0, 1)", format_number(damping_tolerance));
  }
  if (min_stable_orders < 1 || min_stable_orders > max_order - min_order + 1) {
    throw InputError(src, "min_stable_orders",
                     "between 1 and the number of orders swept (" + std::to_string(max_order - min_order + 1) + ")",
                     std::to_string(min_stable_orders));
  }
  if (!(max_damping > 0.0 && max_damping < 1.0)) throw InputError(src, "max_damping", "value in (0, 1)", format_number(max_damping));
}

std::vector<Mode> peak_picking(const Vector& omega, const CMatrix& h, const PeakPickingOptions& options) {
  const char* src = "peak picking";
  options.validate();
  check_data(src, omega, h);
  const auto [first, last] = band(src, omega, options.min_omega, options.max_omega, 3);
  const Vector mag = h.rowwise().norm();

  struct Found {
    Mode mode;
    double prominence;
  };
  std::vector<Found> found;
  for (Index k = first + 1; k < last; ++k) {
    if (!(mag(k) > mag(k - 1) && mag(k) >= mag(k + 1))) continue;
    // Prominence: the lowest point on each side before a higher peak (or the band edge).
    double left_min = mag(k), right_min = mag(k);
    for (Index j = k - 1; j >= first && mag(j) <= mag(k); --j) left_min = std::min(left_min, mag(j));
    for (Index j = k + 1; j <= last && mag(j) <= mag(k); ++j) right_min = std::min(right_min, mag(j));
    const double prominence = mag(k) / std::max({left_min, right_min, 1e-300});
    if (prominence < options.min_prominence) continue;

    // Parabola through (w, ln|H|) at k-1, k, k+1 (non-uniform grid): vertex = peak.
    const double x0 = omega(k - 1), x1 = omega(k), x2 = omega(k + 1);
    const double y0 = std::log(mag(k - 1)), y1 = std::log(mag(k)), y2 = std::log(mag(k + 1));
    const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1);
    const double curv = (d12 - d01) / (x2 - x0);  // = a of a (x - x1)^2 + ...
    double w_peak = x1, y_peak = y1;
    if (curv < 0.0) {
      // y = y1 + b (x - x1) + curv (x - x1)^2 with b from the divided differences.
      const double b = d01 + curv * (x1 - x0);
      const double dx = std::clamp(-b / (2.0 * curv), x0 - x1, x2 - x1);
      w_peak = x1 + dx;
      y_peak = y1 + b * dx + curv * dx * dx;
    }
    const double half = std::exp(y_peak) / std::sqrt(2.0);
    // Half-power crossings, linear interpolation of |H| between samples.
    double w1 = -1.0, w2 = -1.0;
    for (Index j = k; j > 0; --j) {
      if (mag(j - 1) > mag(k)) break;  // ran into a higher peak first
      if (mag(j - 1) <= half) {
        w1 = omega(j - 1) + (half - mag(j - 1)) / (mag(j) - mag(j - 1)) * (omega(j) - omega(j - 1));
        break;
      }
    }
    for (Index j = k; j + 1 < omega.size(); ++j) {
      if (mag(j + 1) > mag(k)) break;
      if (mag(j + 1) <= half) {
        w2 = omega(j) + (mag(j) - half) / (mag(j) - mag(j + 1)) * (omega(j + 1) - omega(j));
        break;
      }
    }
    if (w1 < 0.0 || w2 < 0.0) continue;
    const double zeta = (w2 - w1) / (2.0 * w_peak);
    Mode m;
    m.natural_frequency = w_peak;
    m.damping = zeta;
    m.pole = Complex(-zeta * w_peak, w_peak * std::sqrt(std::max(1.0 - zeta * zeta, 0.0)));
    found.push_back({m, prominence});
  }
  if (options.max_modes > 0 && static_cast<Index>(found.size()) > options.max_modes) {
    std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) { return a.prominence > b.prominence; });
    found.resize(static_cast<size_t>(options.max_modes));
  }
  std::vector<Mode> modes;
  for (const Found& f : found) modes.push_back(f.mode);
  std::sort(modes.begin(), modes.end(),
            [](const Mode& a, const Mode& b) { return a.natural_frequency < b.natural_frequency; });
  return modes;
}

namespace {

// The reduced normal equations of LSCF. X(k, r) = Omega_k^r; they only need Re(X^H X),
// Re(X^H diag(h) X) and Re(X^H diag(|h|^2) X), computed once at the highest order: the lower
// orders use their leading blocks.
struct LscfNormalEquations {
  Matrix rr;
  std::vector<Matrix> ss, tt;  // per output
};

LscfNormalEquations lscf_normal_equations(const Vector& omega, const CMatrix& h, Index first, Index nf, Index nmax, double ts) {
  CMatrix x(nf, nmax + 1);
  for (Index k = 0; k < nf; ++k) {
    const Complex z = std::exp(Complex(0.0, omega(first + k) * ts));
    Complex zr(1.0, 0.0);
    for (Index r = 0; r <= nmax; ++r) {
      x(k, r) = zr;
      zr *= z;
    }
  }
  const CMatrix xh = x.adjoint();
  LscfNormalEquations e;
  e.rr = (xh * x).real();
  for (Index o = 0; o < h.cols(); ++o) {
    const CVector ho = h.col(o).segment(first, nf);
    e.ss.push_back(-(xh * (ho.asDiagonal() * x)).real());
    e.tt.push_back((xh * (ho.cwiseAbs2().cast<Complex>().asDiagonal() * x)).real());
  }
  return e;
}

// The roots (z-domain) of the order-n denominator, alpha_n = 1; nullopt when it cannot be solved.
std::optional<Eigen::VectorXcd> lscf_denominator_roots(const LscfNormalEquations& e, Index n, const char* src) {
  const Index m1 = n + 1;
  Eigen::LLT<Matrix> rllt(e.rr.topLeftCorner(m1, m1));
  if (rllt.info() != Eigen::Success) {
    throw NumericalError(src, "the basis Gram matrix is not positive definite at order " + std::to_string(n) +
                                  " (too many orders for the band)",
                         /*retry_may_help=*/true);
  }
  Matrix mm = Matrix::Zero(m1, m1);
  for (size_t o = 0; o < e.ss.size(); ++o) {
    const Matrix s = e.ss[o].topLeftCorner(m1, m1);
    mm += e.tt[o].topLeftCorner(m1, m1) - s.transpose() * rllt.solve(s);
  }
  // Denominator with alpha_n = 1: M(0:n, 0:n) alpha = -M(0:n, n).
  const Vector alpha = mm.topLeftCorner(n, n).colPivHouseholderQr().solve(-mm.col(n).head(n));
  if (!alpha.allFinite()) return std::nullopt;
  Matrix companion = Matrix::Zero(n, n);
  for (Index i = 1; i < n; ++i) companion(i, i - 1) = 1.0;
  companion.col(n - 1) = -alpha;
  Eigen::EigenSolver<Matrix> eig(companion, /*computeEigenvectors=*/false);
  if (eig.info() != Eigen::Success) return std::nullopt;
  return Eigen::VectorXcd(eig.eigenvalues());
}

// A physical pole with the number of consecutive orders it has been stable over.
struct LscfCandidate {
  StabilizationPole pole;
  Index chain;
};

// The stabilization diagram, order by order: each physical pole in the band is linked to the
// nearest pole of the order below within the tolerances.
class StabilizationTracker {
 public:
  StabilizationTracker(const LscfOptions& options, double ts, double w_lo, double w_hi)
      : options_(options), ts_(ts), w_lo_(w_lo), w_hi_(w_hi) {}

  void add_order(Index n, const Eigen::VectorXcd& roots, LscfResult& result) {
    std::vector<StabilizationPole> current;
    std::vector<Index> chain;
    for (Index i = 0; i < n; ++i) {
      const Complex z = roots(i);
      if (std::abs(z) == 0.0) continue;
      const Complex lambda = std::log(z) / ts_;
      if (lambda.imag() <= 0.0 || lambda.real() >= 0.0) continue;
      StabilizationPole p;
      p.order = n;
      p.pole = lambda;
      p.natural_frequency = std::abs(lambda);
      p.damping = -lambda.real() / p.natural_frequency;
      if (p.damping >= options_.max_damping || lambda.imag() < w_lo_ || lambda.imag() > w_hi_) continue;
      const Index link = link_of(p);
      p.stable = link > 0;
      current.push_back(p);
      chain.push_back(link + 1);
      result.diagram.push_back(p);
      if (link + 1 >= options_.min_stable_orders) candidates_.push_back({p, link + 1});
    }
    previous_ = std::move(current);
    previous_chain_ = std::move(chain);
  }

  [[nodiscard]] std::vector<LscfCandidate>& candidates() { return candidates_; }

 private:
  // The chain length of the nearest pole of the order below within the tolerances (0: none).
  [[nodiscard]] Index link_of(const StabilizationPole& p) const {
    Index link = 0;
    double best = 2.0;
    for (size_t j = 0; j < previous_.size(); ++j) {
      const double df = std::abs(p.natural_frequency - previous_[j].natural_frequency) / previous_[j].natural_frequency;
      const double dz = std::abs(p.damping - previous_[j].damping) / previous_[j].damping;
      if (df < options_.frequency_tolerance && dz < options_.damping_tolerance && df < best) {
        best = df;
        link = previous_chain_[j];
      }
    }
    return link;
  }

  const LscfOptions& options_;
  double ts_, w_lo_, w_hi_;
  std::vector<StabilizationPole> previous_;
  std::vector<Index> previous_chain_;
  std::vector<LscfCandidate> candidates_;
};

// Groups the candidates by frequency; in each group keeps the longest chain (then the highest order).
std::vector<Mode> stable_modes(std::vector<LscfCandidate>& candidates, double frequency_tolerance) {
  std::sort(candidates.begin(), candidates.end(), [](const LscfCandidate& a, const LscfCandidate& b) {
    return a.pole.natural_frequency < b.pole.natural_frequency;
  });
  std::vector<Mode> modes;
  for (size_t i = 0; i < candidates.size();) {
    size_t j = i + 1;
    LscfCandidate best = candidates[i];
    while (j < candidates.size() &&
           candidates[j].pole.natural_frequency - candidates[j - 1].pole.natural_frequency <
               frequency_tolerance * candidates[j - 1].pole.natural_frequency) {
      const LscfCandidate& c = candidates[j];
      if (c.chain > best.chain || (c.chain == best.chain && c.pole.order > best.pole.order)) best = c;
      ++j;
    }
    Mode m = mode_from_pole(best.pole.pole);
    m.stable_orders = best.chain;
    modes.push_back(m);
    i = j;
  }
  return modes;
}

}  // namespace

LscfResult lscf(const Vector& omega, const CMatrix& h, const LscfOptions& options) {
  const char* src = "lscf";
  options.validate();
  check_data(src, omega, h);
  const auto [first, last] = band(src, omega, options.min_omega, options.max_omega, options.max_order + 1);
  const double w_lo = omega(first), w_hi = omega(last);
  // Ts maps the top of the band to the Nyquist frequency, as in PolyMAX.
  const double ts = std::numbers::pi / w_hi;
  const LscfNormalEquations normal = lscf_normal_equations(omega, h, first, last - first + 1, options.max_order, ts);

  LscfResult result;
  StabilizationTracker tracker(options, ts, w_lo, w_hi);
  for (Index n = options.min_order; n <= options.max_order; ++n) {
    if (const auto roots = lscf_denominator_roots(normal, n, src)) tracker.add_order(n, *roots, result);
  }
  result.modes = stable_modes(tracker.candidates(), options.frequency_tolerance);
  // Quality: a mode must be stable over min_stable_orders orders and lie inside the band.
  if (result.modes.empty()) {
    result.quality.add_problem("no mode stayed stable over " + std::to_string(options.min_stable_orders) + " orders");
  }
  for (const Mode& m : result.modes) {
    if (m.natural_frequency < w_lo || m.natural_frequency > w_hi) {
      result.quality.add_problem("mode at " + format_number(m.frequency_Hz()) + " Hz outside the band");
    }
  }
  result.quality.advise("a band around the modes with a high coherence, or more averages");
  return result;
}

}  // namespace piezobench::ident
