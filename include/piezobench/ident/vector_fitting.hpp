#pragma once
// Vector fitting: a rational model with common poles fitted to complex frequency-response data.
//
//   f_i(s) = sum_n r_in / (s - p_n) + d_i + s e_i,     i = 1..outputs,  s = j omega
//
// Method: B. Gustavsen and A. Semlyen, "Rational approximation of frequency domain responses by
// vector fitting", IEEE Trans. Power Delivery 14(3), 1999 (pole relocation through the zeros of a
// weighting function sigma), with the relaxed non-triviality constraint of B. Gustavsen,
// "Improving the pole relocating properties of vector fitting", IEEE Trans. Power Delivery 21(3),
// 2006, and the fast QR-based solve of D. Deschrijver et al., "Macromodeling of multiport systems
// using a fast implementation of the vector fitting method", IEEE MWCL 18(6), 2008 (as in vectfit3:
// each output's sigma equations are reduced by a QR factorization and only the reduced blocks are
// stacked, so the cost grows linearly with the number of outputs).
//
// Numerical safeguards: s is divided by a frequency scale (default: the highest frequency) so that
// the basis stays well scaled over wide spans; the stacked least-squares problems are column
// scaled; unstable poles are mirrored into the left half plane after every relocation.
#include <Eigen/Dense>
#include <complex>
#include <string>

#include "piezobench/core/fields.hpp"
#include "piezobench/core/fit_quality.hpp"
#include "piezobench/lti/state_space.hpp"

namespace piezobench::dsp {
struct Frf;
}

namespace piezobench::ident {

using Index = Eigen::Index;
using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
using CVector = Eigen::VectorXcd;
using CMatrix = Eigen::MatrixXcd;
using Complex = std::complex<double>;

// Terms fitted besides the partial fractions: none, a constant d ("d"), or d + s e ("de").
enum class Asymptote { kNone, kConstant, kConstantAndLinear };
std::string to_string(Asymptote a);
Asymptote asymptote_from_string(const std::string& s);  // throws InputError (field "asymptote")

// Spacing of the automatic starting poles over the data band ("log" or "lin").
enum class PoleSpacing { kLogarithmic, kLinear };
std::string to_string(PoleSpacing p);
PoleSpacing pole_spacing_from_string(const std::string& s);  // throws InputError

// Row weights used when none are passed explicitly ("unit", "inverse-magnitude",
// "inverse-sqrt-magnitude"; the magnitude ones use |f_i(s_k)| per output, as vectfit3 suggests
// for data with relative noise or a large dynamic range; "output-scale" weighs each output by
// 1 / rms |f_i| over the band, so that outputs in different units (m/V and V/V) count alike).
// kInverseStd: each point of each output by 1 / its standard deviation (an FRF's std_H: the
// maximum-likelihood fit under the estimate's own noise); only through vector_fit(const dsp::Frf&)
// and frf_row_weights, which have the std_H, or with explicit weights.
enum class Weighting { kUnit, kInverseMagnitude, kInverseSqrtMagnitude, kOutputScale, kInverseStd };
std::string to_string(Weighting w);
Weighting weighting_from_string(const std::string& s);  // throws InputError

// How the relocations ended.
enum class Convergence { kNotConverged, kPolesSettled, kResidualSettled };
std::string to_string(Convergence c);  // "not-converged", "poles-settled", "residual-settled"
Convergence convergence_from_string(const std::string& s);  // throws InputError

struct VectorFittingOptions {
  // Number of poles N (real poles count one, complex pairs two). Data must supply at least
  // 2 N + (asymptotic terms) + 1 real equations (2 per point with omega > 0, 1 at omega = 0).
  Index order = 6;
  Asymptote asymptote = Asymptote::kConstant;
  // Relaxed non-triviality constraint (Gustavsen 2006); false = sigma's constant fixed to 1 (1999).
  bool relaxed = true;
  // Mirror relocated poles with Re > 0 into the left half plane.
  bool enforce_stable_poles = true;
  // Relocations stop when the poles settle: the relative distance between old and new poles (each
  // new pole to its nearest old one, and back) is below pole_tolerance. If not all poles settled,
  // the residues are identified for the new poles and only significant poles are compared: those
  // whose peak contribution |r| / |Re p| (|r| / |p| if real) is at least significance_floor times
  // the largest data magnitude; the others are not determined by the data (e.g. a pole cancelled
  // by a zero) and wander at round-off level. Relocations also stop when the relative weighted rms
  // error of the fit changes by less than residual_tolerance (relative) between two relocations:
  // with noise and more poles than the data need, spurious poles keep moving while the fit no
  // longer improves. Setting both significance_floor and residual_tolerance to 0 skips the
  // per-iteration residue identification (fastest). At most max_iterations relocations.
  int max_iterations = 50;
  double pole_tolerance = 1e-9;      // relative
  double significance_floor = 1e-8;  // ratio
  double residual_tolerance = 1e-4;  // relative
  // When the poles have not settled after max_iterations: true = throw NumericalError
  // (retry_may_help), false = return the last model with converged = false.
  bool fail_if_not_converged = true;
  // Starting poles, rad/s: empty = automatic, i.e. N/2 complex pairs -a + j b with b spaced over
  // [lowest positive omega, highest omega] and a = starting_damping * b (plus one real pole at
  // -b_mid when N is odd), as recommended by Gustavsen & Semlyen. Otherwise exactly N values,
  // complex ones in conjugate pairs.
  CVector starting_poles;
  PoleSpacing starting_spacing = PoleSpacing::kLogarithmic;
  double starting_damping = 0.01;
  Weighting weighting = Weighting::kUnit;
  // Per-frequency-point weights, one per data point (e.g. 1 / the standard deviation of each FRF
  // point), finite and > 0; empty = none. They multiply the row weights: those of the explicit
  // weights argument of vector_fit if given, else those of `weighting` (so "output-scale" and
  // point weights combine). vector_fit checks the length against the data (field "point_weights").
  Vector point_weights;
  // rad/s; 0 = automatic (highest omega).
  double frequency_scale = 0.0;

  // Throws InputError naming the bad field (source "vector fitting options").
  void validate() const;
};

struct VectorFittingResult {
  // Poles, rad/s: real poles first (increasing magnitude), then complex pairs by increasing
  // imaginary part, each pair as (p, conj(p)) with Im p > 0 first.
  CVector poles;
  CMatrix residues;  // outputs x N, same column order as poles (conjugate residues for pairs)
  Vector d;          // data units, outputs; zero unless asymptote includes d
  Vector e;          // outputs, s; zero unless asymptote is d + s e
  // The proper part (partial fractions + d) as a real state space with one input and `outputs`
  // outputs: A is block diagonal (1x1 for a real pole, [[Re p, Im p], [-Im p, Re p]] for a pair),
  // B has 1 for a real pole and [2, 0] for a pair, C holds [Re r, Im r] for a pair. The s e term,
  // if any, is not representable in state space and is left out.
  lti::StateSpace model;
  double rms_error = 0.0;           // sqrt(mean |fit - data|^2) over points and outputs, data units
  double relative_rms_error = 0.0;  // rms_error / sqrt(mean |data|^2)
  Vector relative_rms_error_per_output;  // the same per output: sqrt(sum |fit - data|^2 / sum |data|^2)
  // Poor when an output's relative error is above core::kPoorRelativeError, a complex pole lies
  // outside [lowest / 2, 2 highest] frequency of the data (a resonance the data cannot show; real
  // poles only shape the slope), a pole is unstable, or the poles did not settle.
  core::FitQuality quality;
  int iterations = 0;               // pole relocations performed
  bool converged = false;
  Convergence convergence = Convergence::kNotConverged;
  double last_pole_change = 0.0;    // relative, of the last relocation (significant poles)
  double frequency_scale = 0.0;     // rad/s, the scale that was used

  [[nodiscard]] Index outputs() const { return residues.rows(); }
  // The fitted model at s = j omega: omega.size() x outputs.
  [[nodiscard]] CMatrix evaluate(const Vector& omega) const;
  // At an arbitrary complex s, all outputs.
  [[nodiscard]] CVector evaluate_at(Complex s) const;
  // One line: order, iterations, converged, rms.
  [[nodiscard]] std::string brief_report() const;
};

// The row weights vector_fit uses: `weights` if given, else those of options.weighting (points x 1
// or points x outputs), times options.point_weights.
[[nodiscard]] Matrix vector_fitting_weights(const CMatrix& data, const Matrix& weights, const VectorFittingOptions& options);

// omega: rad/s, strictly increasing, >= 0, finite. data: points x outputs (data(k, i) = f_i(j
// omega_k)), finite, not all zero. weights: empty (options.weighting is used), points x 1 (common
// to all outputs) or points x outputs, finite and > 0; options.point_weights multiply them.
// Throws InputError (source "vector fitting") for bad input, including too few data for the
// order; NumericalError when the relocation system is singular or, with fail_if_not_converged,
// when the poles do not settle.
VectorFittingResult vector_fit(const Vector& omega, const CMatrix& data, const Matrix& weights,
                               const VectorFittingOptions& options);
// omega: rad/s.
VectorFittingResult vector_fit(const Vector& omega, const CMatrix& data,
                               const VectorFittingOptions& options);
// All outputs of an FRF (frequencies in Hz are converted to rad/s); errors name frf.provenance.source.
// The verdict names the outputs and is also poor when an output's coherence is below 0.5 at more
// than half of the points (a band the input did not excite).
VectorFittingResult vector_fit(const dsp::Frf& frf, const VectorFittingOptions& options);
// The explicit row weights vector_fit(frf, options) passes: with options.weighting kInverseStd, 1 /
// std_H (points x outputs; InputError naming frf.provenance.source when an output has no std_H or a
// value that is not finite and > 0); otherwise empty (options.weighting decides).
[[nodiscard]] Matrix frf_row_weights(const dsp::Frf& frf, const VectorFittingOptions& options);

// The state space `model` is not declared: it is rebuilt from the poles and residues (evaluate()
// uses those), so part.json does not carry it.
constexpr auto describe(core::Type<VectorFittingResult>) {
  using S = VectorFittingResult;
  using namespace core::shown;
  return core::fields<S>("VectorFittingResult", "a rational model fitted by vector fitting",
      core::field("poles", &S::poles, kRadPerSecond, "real poles first, then pairs (Im > 0 first)"),
      core::field("residues", &S::residues, kNone, "outputs x poles"),
      core::field("d", &S::d, kNone, "constant term per output"),
      core::field("e", &S::e, kNone, "s term per output (s)"),
      core::field("rms_error", &S::rms_error, kNone, "sqrt(mean |fit - data|^2), data units"),
      core::field("relative_rms_error", &S::relative_rms_error, kRatio, "rms_error / rms data"),
      core::field("relative_rms_error_per_output", &S::relative_rms_error_per_output, kRatio, "the same per output"),
      core::field("quality", &S::quality, kNone, "the verdict").key("."),
      core::field("iterations", &S::iterations, kNone, "pole relocations"),
      core::field("converged", &S::converged, kNone, "the poles settled"),
      core::field("convergence", &S::convergence, kNone, "how the iteration ended"),
      core::field("last_pole_change", &S::last_pole_change, kRatio, "relative, of the last relocation"),
      core::field("frequency_scale", &S::frequency_scale, kRadPerSecond, "the scale used"));
}

}  // namespace piezobench::ident
