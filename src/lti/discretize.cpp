#include "piezobench/lti/discretize.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

#include "check.hpp"
#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/lti/conversions.hpp"

namespace piezobench::lti {
namespace {

// Pade approximant r_m(A) = (V - U)^-1 (V + U) with U odd, V even in A (Higham 2005, eq. 2.3).
Matrix pade_exp(const Matrix& a, int m) {
  static constexpr std::array<double, 4> kB3 = {120.0, 60.0, 12.0, 1.0};
  static constexpr std::array<double, 6> kB5 = {30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0};
  static constexpr std::array<double, 8> kB7 = {17297280.0, 8648640.0, 1995840.0, 277200.0,
                                                25200.0,    1512.0,    56.0,      1.0};
  static constexpr std::array<double, 10> kB9 = {17643225600.0, 8821612800.0, 2075673600.0, 302702400.0,
                                                 30270240.0,    2162160.0,    110880.0,     3960.0,
                                                 90.0,          1.0};
  static constexpr std::array<double, 14> kB13 = {
      64764752532480000.0, 32382376266240000.0, 7771770303897600.0, 1187353796428800.0, 129060195264000.0,
      10559470521600.0,    670442572800.0,      33522128640.0,      1323241920.0,       40840800.0,
      960960.0,            16380.0,             182.0,              1.0};
  const Index n = a.rows();
  const Matrix ident = Matrix::Identity(n, n);
  const Matrix a2 = a * a;
  Matrix u;
  Matrix v;
  if (m == 13) {
    const auto& b = kB13;
    const Matrix a4 = a2 * a2;
    const Matrix a6 = a4 * a2;
    const Matrix u_inner = a6 * (b[13] * a6 + b[11] * a4 + b[9] * a2) + b[7] * a6 + b[5] * a4 + b[3] * a2 +
                           b[1] * ident;
    u = a * u_inner;
    v = a6 * (b[12] * a6 + b[10] * a4 + b[8] * a2) + b[6] * a6 + b[4] * a4 + b[2] * a2 + b[0] * ident;
  } else {
    const double* b = nullptr;
    switch (m) {
      case 3:
        b = kB3.data();
        break;
      case 5:
        b = kB5.data();
        break;
      case 7:
        b = kB7.data();
        break;
      default:
        b = kB9.data();
        break;
    }
    Matrix u_inner = b[1] * ident;
    v = b[0] * ident;
    Matrix power = ident;
    for (int k = 2; k <= m; k += 2) {
      power = power * a2;  // A^k
      u_inner += b[k + 1] * power;
      v += b[k] * power;
    }
    u = a * u_inner;
  }
  const Eigen::PartialPivLU<Matrix> lu(v - u);
  return lu.solve(v + u);
}

// I - a A must be invertible for the bilinear map; its LU is shared by Ad, Bd, Cd and Dd.
Eigen::PartialPivLU<Matrix> tustin_lu(const Matrix& a, double alpha) {
  const Index n = a.rows();
  Eigen::PartialPivLU<Matrix> lu(Matrix::Identity(n, n) - alpha * a);
  if (!(lu.rcond() > 10.0 * std::numeric_limits<double>::epsilon())) {
    throw NumericalError("c2d (tustin)",
                         "the system has a pole at s = " + format_number(1.0 / alpha, 10) +
                             " rad/s, which the bilinear map sends to infinity; choose another sample time",
                         /*retry_may_help=*/true);
  }
  return lu;
}

// Number of whole samples in a delay; InputError when it is not a whole multiple of Ts.
Index delay_samples(double delay, double ts, const std::string& field) {
  const double ratio = delay / ts;
  const double rounded = std::round(ratio);
  if (std::abs(ratio - rounded) > 1e-9 * std::max(1.0, rounded)) {
    throw InputError("lsim", field, "a whole multiple of the sample time " + format_number(ts, 10) + " s", format_number(delay, 10) + " s");
  }
  return static_cast<Index>(rounded);
}

}  // namespace

std::string to_string(DiscretizationMethod method) {
  switch (method) {
    case DiscretizationMethod::kZoh:
      return "zoh";
    case DiscretizationMethod::kTustin:
      return "tustin";
  }
  return "unknown";
}

DiscretizationMethod discretization_method_from_string(const std::string& name) {
  if (name == "zoh") return DiscretizationMethod::kZoh;
  if (name == "tustin") return DiscretizationMethod::kTustin;
  throw InputError("", "method", "one of zoh, tustin", "'" + name + "'");
}

void DiscretizeOptions::validate(double sample_time) const {
  if (!(sample_time > 0.0) || !std::isfinite(sample_time)) {
    throw InputError("c2d", "sample_time", "a finite time > 0 s", format_number(sample_time, 10));
  }
  if (method != DiscretizationMethod::kZoh && method != DiscretizationMethod::kTustin) {
    throw InputError("c2d", "method", "zoh or tustin", std::to_string(static_cast<int>(method)));
  }
  const double nyquist = std::numbers::pi / sample_time;
  if (!std::isfinite(prewarp_frequency) || prewarp_frequency < 0.0 || prewarp_frequency >= nyquist) {
    throw InputError("c2d", "prewarp_frequency", "0 or a frequency in (0, " + format_number(nyquist, 10) + ") rad/s",
                     format_number(prewarp_frequency, 10));
  }
}

Matrix expm(const Matrix& a) {
  if (a.rows() != a.cols()) {
    throw InputError("expm", "a", "a square matrix",
                     std::to_string(a.rows()) + "x" + std::to_string(a.cols()));
  }
  if (!a.allFinite()) throw InputError("expm", "a", "finite entries", "NaN or Inf");
  const Index n = a.rows();
  if (n == 0) return Matrix(0, 0);
  // Largest 1-norms for which the [m/m] approximant reaches unit round-off (Higham 2005, Table 2.3).
  static constexpr std::array<std::pair<int, double>, 4> kTheta = {
      {{3, 1.495585217958292e-2}, {5, 2.539398330063230e-1}, {7, 9.504178996162932e-1}, {9, 2.097847961257068e0}}};
  constexpr double kTheta13 = 5.371920351148152e0;
  const double norm1 = a.cwiseAbs().colwise().sum().maxCoeff();
  // Finite entries can still sum to infinity; the squaring count below must be a finite integer.
  if (!std::isfinite(norm1)) throw InputError("expm", "a", "entries whose column sums are finite", "an infinite 1-norm");
  for (const auto& [m, theta] : kTheta) {
    if (norm1 <= theta) return pade_exp(a, m);
  }
  int squarings = 0;
  if (norm1 > kTheta13) squarings = static_cast<int>(std::ceil(std::log2(norm1 / kTheta13)));
  Matrix e = pade_exp(a * std::ldexp(1.0, -squarings), 13);
  for (int k = 0; k < squarings; ++k) e = e * e;
  return e;
}

StateSpace c2d(const StateSpace& sys, double sample_time, const DiscretizeOptions& options) {
  sys.validate("c2d");
  if (sys.is_discrete()) {
    throw InputError("c2d", "sample_time", "a continuous system (sample_time 0)",
                     "a discrete one with Ts = " + format_number(sys.sample_time, 10) + " s");
  }
  options.validate(sample_time);
  const Index n = sys.states();
  const Index m = sys.inputs();
  StateSpace out = sys;
  out.sample_time = sample_time;
  if (n == 0) return out;
  if (options.method == DiscretizationMethod::kZoh) {
    Matrix big = Matrix::Zero(n + m, n + m);
    big.topLeftCorner(n, n) = sys.A * sample_time;
    big.topRightCorner(n, m) = sys.B * sample_time;
    const Matrix e = expm(big);
    out.A = e.topLeftCorner(n, n);
    out.B = e.topRightCorner(n, m);
    return out;
  }
  // Tustin: s = (1/alpha) (z - 1)/(z + 1) with alpha = Ts/2, or 1/w tan(w Ts/2) to match at w.
  // The realization is the one of scipy's cont2discrete('bilinear'):
  //   Ad = (I - alpha A)^-1 (I + alpha A),  Bd = 2 alpha (I - alpha A)^-1 B,
  //   Cd = C (I - alpha A)^-1,              Dd = D + alpha C (I - alpha A)^-1 B.
  const double w = options.prewarp_frequency;
  const double alpha = w > 0.0 ? std::tan(w * sample_time / 2.0) / w : sample_time / 2.0;
  const auto lu = tustin_lu(sys.A, alpha);
  const Matrix ident = Matrix::Identity(n, n);
  const Matrix tinv_b = lu.solve(sys.B);
  out.A = lu.solve(ident + alpha * sys.A);
  out.B = 2.0 * alpha * tinv_b;
  out.C = sys.C * lu.inverse();
  out.D = sys.D + alpha * sys.C * tinv_b;
  return out;
}

TransferFunction c2d(const TransferFunction& tf, double sample_time, const DiscretizeOptions& options) {
  tf.validate("c2d");
  if (tf.is_discrete()) {
    throw InputError("c2d", "sample_time", "a continuous transfer function (sample_time 0)",
                     "a discrete one with Ts = " + format_number(tf.sample_time, 10) + " s");
  }
  options.validate(sample_time);
  TransferFunction continuous = tf;
  continuous.delay = 0.0;
  TransferFunction out = to_transfer_function(c2d(to_state_space(continuous), sample_time, options));
  out.sample_time = sample_time;
  out.delay = tf.delay;
  return out;
}

TimeResponse lsim(const StateSpace& discrete_sys, const Matrix& u, const Vector& x0) {
  const StateSpace& sys = discrete_sys;
  sys.validate("lsim");
  if (!sys.is_discrete()) {
    throw InputError("lsim", "sample_time", "a discrete system (sample_time > 0); use c2d first", "0");
  }
  const Index n = sys.states();
  const Index m = sys.inputs();
  const Index p = sys.outputs();
  if (u.cols() != m) {
    throw InputError("lsim", "u", std::to_string(m) + " columns (one per input)", std::to_string(u.cols()));
  }
  if (!u.allFinite()) throw InputError("lsim", "u", "finite samples", "NaN or Inf");
  if (x0.size() != 0 && x0.size() != n) {
    throw InputError("lsim", "x0", "empty or " + std::to_string(n) + " entries", std::to_string(x0.size()));
  }
  if (!x0.allFinite()) throw InputError("lsim", "x0", "finite entries", "NaN or Inf");
  const Index samples = u.rows();
  const double ts = sys.sample_time;
  std::vector<Index> in_shift(static_cast<size_t>(m), 0);
  std::vector<Index> out_shift(static_cast<size_t>(p), 0);
  for (Index j = 0; j < sys.input_delay.size(); ++j) {
    in_shift[static_cast<size_t>(j)] = delay_samples(sys.input_delay(j), ts, "input_delay");
  }
  for (Index i = 0; i < sys.output_delay.size(); ++i) {
    out_shift[static_cast<size_t>(i)] = delay_samples(sys.output_delay(i), ts, "output_delay");
  }
  // Delayed inputs: u_j[k - d_j], zero before the delay has elapsed.
  Matrix ud = Matrix::Zero(samples, m);
  for (Index j = 0; j < m; ++j) {
    const Index d = in_shift[static_cast<size_t>(j)];
    if (d < samples) ud.col(j).tail(samples - d) = u.col(j).head(samples - d);
  }
  TimeResponse r;
  r.t.resize(samples);
  for (Index k = 0; k < samples; ++k) r.t(k) = ts * static_cast<double>(k);
  r.x.resize(samples, n);
  Matrix y(samples, p);
  Vector x = x0.size() == n ? x0 : Vector::Zero(n);
  Vector next(n);
  for (Index k = 0; k < samples; ++k) {
    const Vector uk = ud.row(k).transpose();
    r.x.row(k) = x.transpose();
    y.row(k) = (sys.C * x + sys.D * uk).transpose();
    next.noalias() = sys.A * x + sys.B * uk;
    x.swap(next);
  }
  r.y = Matrix::Zero(samples, p);
  for (Index i = 0; i < p; ++i) {
    const Index d = out_shift[static_cast<size_t>(i)];
    if (d < samples) r.y.col(i).tail(samples - d) = y.col(i).head(samples - d);
  }
  return r;
}

namespace {

// The discrete system that step() and impulse() simulate, and a check of their arguments.
StateSpace discrete_for_response(const StateSpace& sys, double sample_time, Index samples, Index input,
                                 const std::string& method) {
  sys.validate(method);
  if (samples < 0) throw InputError(method, "samples", "a count >= 0", std::to_string(samples));
  if (input < 0 || input >= sys.inputs()) {
    throw InputError(method, "input", "an input index below " + std::to_string(sys.inputs()),
                     std::to_string(input));
  }
  if (sys.is_discrete()) {
    if (sample_time != 0.0 && std::abs(sample_time - sys.sample_time) > 1e-12 * sys.sample_time) {
      throw InputError(method, "sample_time", "0 or the system's sample time " + format_number(sys.sample_time, 10) + " s",
                       format_number(sample_time, 10));
    }
    return sys;
  }
  return c2d(sys, sample_time);
}

}  // namespace

TimeResponse step(const StateSpace& sys, double sample_time, Index samples, Index input) {
  const StateSpace d = discrete_for_response(sys, sample_time, samples, input, "step");
  Matrix u = Matrix::Zero(samples, d.inputs());
  u.col(input).setOnes();
  return lsim(d, u);
}

TimeResponse impulse(const StateSpace& sys, double sample_time, Index samples, Index input) {
  const StateSpace d = discrete_for_response(sys, sample_time, samples, input, "impulse");
  Matrix u = Matrix::Zero(samples, d.inputs());
  if (samples > 0) u(0, input) = sys.is_discrete() ? 1.0 : 1.0 / d.sample_time;
  return lsim(d, u);
}

}  // namespace piezobench::lti
