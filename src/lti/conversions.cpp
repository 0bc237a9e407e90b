#include "piezobench/lti/conversions.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

#include "balance.hpp"
#include "check.hpp"
#include "spectral.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/lti/interconnect.hpp"

namespace piezobench::lti {
namespace {

Vector convolve(const Vector& a, const Vector& b) {
  Vector c = Vector::Zero(a.size() + b.size() - 1);
  for (Index i = 0; i < a.size(); ++i) c.segment(i, b.size()) += a(i) * b;
  return c;
}

void require_index(Index value, Index count, const std::string& field) {
  if (value < 0 || value >= count) {
    throw InputError("", field, "an index in [0, " + std::to_string(count) + ")", std::to_string(value));
  }
}

// A point to evaluate H at for the gain of a zpk form: among points on circles around the origin
// (radius: the median modulus of the nonzero poles and zeros, times 1/4 .. 4), the one farthest from
// every pole and zero relative to its own modulus. There each factor (s0 - x) is known to about
// |error of x| / |s0 - x| relative, and sI - A is far from singular.
Complex gain_point(const CVector& p, const CVector& z) {
  std::vector<double> mags;
  for (Index i = 0; i < p.size(); ++i) {
    if (std::abs(p(i)) > 0.0) mags.push_back(std::abs(p(i)));
  }
  for (Index i = 0; i < z.size(); ++i) {
    if (std::abs(z(i)) > 0.0) mags.push_back(std::abs(z(i)));
  }
  double r = 1.0;
  if (!mags.empty()) {
    std::nth_element(mags.begin(), mags.begin() + static_cast<std::ptrdiff_t>(mags.size() / 2), mags.end());
    r = mags[mags.size() / 2];
  }
  Complex best(r, 0.0);
  double best_score = -1.0;
  for (const double radius : {1.0, 0.5, 2.0, 0.25, 4.0}) {
    for (int k = 0; k < 16; ++k) {
      const Complex s0 = std::polar(radius * r, kPi * (k + 0.5) / 16.0);
      double score = std::numeric_limits<double>::infinity();
      for (Index i = 0; i < p.size(); ++i) score = std::min(score, std::abs(s0 - p(i)));
      for (Index i = 0; i < z.size(); ++i) score = std::min(score, std::abs(s0 - z(i)));
      score /= std::abs(s0);
      if (score > best_score) {
        best_score = score;
        best = s0;
      }
    }
  }
  return best;
}

// One real section of the cascade: one real pole, a complex pole pair, or two real poles, with at
// most as many zeros; numerator monic in its zeros (leading coefficient 1). Plain data (fixed
// arrays) since a section holds at most two of each.
struct Section {
  std::array<double, 2> real_poles{};
  int n_real_poles = 0;
  bool has_pair = false;
  Complex pair;  // Im > 0
  std::array<double, 2> real_zeros{};
  int n_real_zeros = 0;
  bool has_zero_pair = false;
  Complex zero_pair;  // Im > 0

  [[nodiscard]] int pole_count() const { return n_real_poles + (has_pair ? 2 : 0); }
  [[nodiscard]] int zero_count() const { return n_real_zeros + (has_zero_pair ? 2 : 0); }
  [[nodiscard]] double distance(Complex x) const {
    double d = std::numeric_limits<double>::infinity();
    if (has_pair) d = std::abs(x - pair);
    for (int i = 0; i < n_real_poles; ++i) d = std::min(d, std::abs(x - real_poles[static_cast<std::size_t>(i)]));
    return d;
  }
};

StateSpace realize(const Section& sec, double ts) {
  // Numerator d s^2 + n1 s + n0 (second order) or d s + n0 (first order).
  if (sec.pole_count() == 1) {
    const double p = sec.real_poles[0];
    if (sec.zero_count() == 1) {
      // (s - z)/(s - p) = 1 + (p - z)/(s - p)
      return StateSpace(Matrix::Constant(1, 1, p), Matrix::Ones(1, 1), Matrix::Constant(1, 1, p - sec.real_zeros[0]),
                        Matrix::Ones(1, 1), ts);
    }
    return StateSpace(Matrix::Constant(1, 1, p), Matrix::Ones(1, 1), Matrix::Ones(1, 1), Matrix::Zero(1, 1), ts);
  }
  double d = 0.0;
  double n1 = 0.0;
  double n0 = 1.0;
  if (sec.has_zero_pair) {
    d = 1.0;
    n1 = -2.0 * sec.zero_pair.real();
    n0 = std::norm(sec.zero_pair);
  } else if (sec.n_real_zeros == 2) {
    d = 1.0;
    n1 = -(sec.real_zeros[0] + sec.real_zeros[1]);
    n0 = sec.real_zeros[0] * sec.real_zeros[1];
  } else if (sec.n_real_zeros == 1) {
    n1 = 1.0;
    n0 = -sec.real_zeros[0];
  }
  if (sec.has_pair) {
    // Real Jordan block A = [sig w; -w sig]: its eigenvalues are exactly sig +- jw, however lightly
    // damped (a companion form would hold them only through the ill-conditioned coefficients).
    // H = d + (r1 s + r0) / ((s - sig)^2 + w^2), with B = [0; 1], C = [(r0 + r1 sig)/w, r1].
    const double sig = sec.pair.real();
    const double w = sec.pair.imag();
    double r1 = n1 + 2.0 * sig * d;
    double r0 = n0 - d * std::norm(sec.pair);
    if (sec.has_zero_pair) {
      // The same numbers without cancellation when the zeros sit next to the poles (anti-resonance
      // close to a resonance): differences first.
      const Complex zp = sec.zero_pair;
      r1 = 2.0 * (sig - zp.real());
      r0 = (zp.real() - sig) * (zp.real() + sig) + (zp.imag() - w) * (zp.imag() + w);
    }
    Matrix a(2, 2);
    a << sig, w, -w, sig;
    Matrix b(2, 1);
    b << 0.0, 1.0;
    Matrix c(1, 2);
    c << (r0 + r1 * sig) / w, r1;
    return StateSpace(a, b, c, Matrix::Constant(1, 1, d), ts);
  }
  // Two real poles in series: x1 = u/(s - p1), x2 = x1/(s - p2);
  // y = d u + c1 x1 + c2 x2 gives the numerator d (s-p1)(s-p2) + c1 (s - p2) + c2.
  const double p1 = sec.real_poles[0];
  const double p2 = sec.real_poles[1];
  const double c1 = n1 + d * (p1 + p2);
  const double c2 = n0 - d * p1 * p2 + c1 * p2;
  Matrix a(2, 2);
  a << p1, 0.0, 1.0, p2;
  Matrix b(2, 1);
  b << 1.0, 0.0;
  Matrix c(1, 2);
  c << c1, c2;
  return StateSpace(a, b, c, Matrix::Constant(1, 1, d), ts);
}

}  // namespace

CVector roots(const Vector& coefficients) {
  detail::require_finite(coefficients, "roots", "coefficients");
  Index lead = 0;
  while (lead < coefficients.size() && coefficients(lead) == 0.0) ++lead;
  if (coefficients.size() - lead <= 1) return CVector();
  Index last = coefficients.size() - 1;
  Index zero_roots = 0;
  while (coefficients(last) == 0.0) {
    --last;
    ++zero_roots;  // exact roots at the origin, kept out of the eigenvalue problem
  }
  const Index degree = last - lead;
  CVector r = CVector::Zero(degree + zero_roots);
  if (degree > 0) {
    Matrix companion = Matrix::Zero(degree, degree);
    for (Index j = 0; j < degree; ++j) companion(0, j) = -coefficients(lead + 1 + j) / coefficients(lead);
    for (Index i = 1; i < degree; ++i) companion(i, i - 1) = 1.0;
    r.head(degree) = detail::balanced_eigenvalues(companion);
  }
  detail::sort_roots(r);
  return r;
}

Vector poly(const CVector& r) {
  detail::require_finite(r, "poly", "roots");
  const detail::ConjugateSplit split = detail::split_conjugates(r, "poly", "roots");
  Vector c = Vector::Ones(1);
  for (const double x : split.real) c = convolve(c, Vector{{1.0, -x}});
  for (const Complex& x : split.pairs) c = convolve(c, Vector{{1.0, -2.0 * x.real(), std::norm(x)}});
  return c;
}

Zpk to_zpk(const TransferFunction& tf) {
  tf.validate();
  Index lead = 0;
  while (lead < tf.num.size() && tf.num(lead) == 0.0) ++lead;
  if (lead == tf.num.size()) return Zpk(CVector(), roots(tf.den), 0.0, tf.sample_time, tf.delay);
  const Vector num = tf.num.tail(tf.num.size() - lead);
  return Zpk(roots(num), roots(tf.den), num(0) / tf.den(0), tf.sample_time, tf.delay);
}

Zpk to_zpk(const StateSpace& sys, Index output, Index input) {
  sys.validate();
  require_index(output, sys.outputs(), "output");
  require_index(input, sys.inputs(), "input");
  const Matrix b = sys.B.col(input);
  const Matrix c = sys.C.row(output);
  const Matrix d = sys.D.block(output, input, 1, 1);
  const double delay = sys.channel_delay(output, input);
  const CVector p = detail::balanced_eigenvalues(sys.A);
  const detail::PencilZeros pz = detail::system_zeros(sys.A, b, c, d);
  if (pz.normal_rank == 0) return Zpk(CVector(), p, 0.0, sys.sample_time, delay);
  CVector z = pz.zeros;
  detail::sort_roots(z);
  const Complex s0 = gain_point(p, z);
  Complex k = detail::evaluate_dense(sys.A, b, c, d, s0)(0, 0);
  // k = H(s0) prod(s0 - p) / prod(s0 - z), factors interleaved to keep the product in range.
  for (Index i = 0; i < std::max(p.size(), z.size()); ++i) {
    if (i < p.size()) k *= s0 - p(i);
    if (i < z.size()) k /= s0 - z(i);
  }
  return Zpk(z, p, k.real(), sys.sample_time, delay);
}

TransferFunction to_transfer_function(const Zpk& zpk) {
  zpk.validate();
  const Vector den = poly(zpk.poles);
  Vector num = Vector::Zero(den.size());  // padded with leading zeros to the length of den (as tfdata)
  if (zpk.gain != 0.0) {
    const Vector nz = zpk.gain * poly(zpk.zeros);
    num.tail(nz.size()) = nz;
  }
  return TransferFunction(num, den, zpk.sample_time, zpk.delay);
}

TransferFunction to_transfer_function(const StateSpace& sys, Index output, Index input) {
  return to_transfer_function(to_zpk(sys, output, input));
}

StateSpace to_state_space(const Zpk& zpk) {
  zpk.validate();
  const double ts = zpk.sample_time;
  StateSpace out;
  if (zpk.poles.size() == 0) {
    out = StateSpace::gain(Matrix::Constant(1, 1, zpk.gain), ts);
  } else {
    const detail::ConjugateSplit poles = detail::split_conjugates(zpk.poles, "zpk", "poles");
    const detail::ConjugateSplit zeros = detail::split_conjugates(zpk.zeros, "zpk", "zeros");
    std::vector<Section> sections;
    sections.reserve(poles.pairs.size() + poles.real.size());
    for (const Complex& p : poles.pairs) {
      Section s;
      s.has_pair = true;
      s.pair = p;
      sections.push_back(s);
    }
    std::vector<double> real_poles = poles.real;
    std::sort(real_poles.begin(), real_poles.end());
    for (const double p : real_poles) {
      Section s;
      s.real_poles[0] = p;
      s.n_real_poles = 1;
      sections.push_back(s);
    }
    // Complex zero pairs go to the nearest second-order section still without zeros; when none is
    // left, two zero-free first-order sections are merged (always possible: at most as many zeros
    // as poles).
    for (const Complex& z : zeros.pairs) {
      std::size_t best = sections.size();
      for (std::size_t i = 0; i < sections.size(); ++i) {
        if (sections[i].pole_count() == 2 && sections[i].zero_count() == 0 &&
            (best == sections.size() || sections[i].distance(z) < sections[best].distance(z))) {
          best = i;
        }
      }
      if (best == sections.size()) {
        // The two zero-free first-order sections nearest to z.
        std::size_t keep = sections.size();
        std::size_t drop = sections.size();
        for (std::size_t i = 0; i < sections.size(); ++i) {
          if (sections[i].pole_count() != 1 || sections[i].zero_count() != 0) continue;
          if (keep == sections.size() || sections[i].distance(z) < sections[keep].distance(z)) {
            drop = keep;
            keep = i;
          } else if (drop == sections.size() || sections[i].distance(z) < sections[drop].distance(z)) {
            drop = i;
          }
        }
        assert(keep < sections.size() && drop < sections.size());
        sections[keep].real_poles[1] = sections[drop].real_poles[0];
        sections[keep].n_real_poles = 2;
        sections.erase(sections.begin() + static_cast<std::ptrdiff_t>(drop));
        best = drop < keep ? keep - 1 : keep;
      }
      sections[best].has_zero_pair = true;
      sections[best].zero_pair = z;
    }
    for (const double z : zeros.real) {
      std::size_t best = sections.size();
      for (std::size_t i = 0; i < sections.size(); ++i) {
        if (sections[i].zero_count() < sections[i].pole_count() &&
            (best == sections.size() || sections[i].distance(z) < sections[best].distance(z))) {
          best = i;
        }
      }
      assert(best < sections.size());
      Section& sec = sections[best];
      sec.real_zeros[static_cast<std::size_t>(sec.n_real_zeros++)] = z;
    }
    out = realize(sections[0], ts);
    for (std::size_t i = 1; i < sections.size(); ++i) out = series(out, realize(sections[i], ts));
    out.C *= zpk.gain;
    out.D *= zpk.gain;
    // Powers-of-two diagonal scaling: exact, and evens out the section gains.
    detail::balance_realization(out.A, out.B, out.C);
  }
  if (zpk.delay > 0.0) out.input_delay = Vector::Constant(1, zpk.delay);
  return out;
}

StateSpace to_state_space(const TransferFunction& tf) { return to_state_space(to_zpk(tf)); }

}  // namespace piezobench::lti
