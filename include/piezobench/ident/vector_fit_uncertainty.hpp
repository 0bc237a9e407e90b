#pragma once
// Standard errors of a vector fit (issue 30): its poles, their natural frequencies and damping
// ratios, and the zeros of each output, from the covariance of the fitted rational model
//
//   f_i(s) = sum_n r_in / (s - p_n) + d_i + s e_i
//
// linearized at the solution in all its real parameters: each complex pair's Re p and Im p (a real
// pole's p), each output's residues (Re r and Im r of a pair, r of a real pole), d_i and e_i when
// fitted. The relocation and the residue identification of vector fitting end at a least-squares
// solution of the weighted error w_k (f_i(j omega_k) - H_ik), so the covariance is
// core::fit_covariance's of that error (the sandwich form and the local misfit widening) with the
// FRF's standard deviation std_ik, or without it each output's noise estimated from the fit's
// residuals, additive plus proportional (dsp::estimate_frf_noise, as the plant fits do). Zeros by the implicit function theorem: f_i(z) = 0 gives dz = -(df_i / dtheta) dtheta /
// f_i'(z).
#include <Eigen/Dense>
#include <complex>
#include <string>
#include <vector>

#include "piezobench/core/fit_covariance.hpp"
#include "piezobench/ident/vector_fitting.hpp"

namespace piezobench::ident {

// One pole or zero with its standard errors (rad/s for the frequencies, the damping dimensionless).
struct RootUncertainty {
  Complex root;                   // rad/s
  double natural_frequency = 0.0; // |root|, rad/s
  double natural_frequency_se = 0.0;  // rad/s
  double damping = 0.0;           // -Re root / |root| (negative: a right-half-plane root)
  double damping_se = 0.0;        // dimensionless
  double real_se = 0.0, imag_se = 0.0;  // of Re root and Im root, rad/s
};

constexpr auto describe(core::Type<RootUncertainty>) {
  using S = RootUncertainty;
  using namespace core::shown;
  return core::fields<S>("RootUncertainty", "a pole or zero of a vector fit with its standard errors",
      core::field("root", &S::root, kRadPerSecond, "[re, im]"),
      core::field("natural_frequency", &S::natural_frequency, kRadPerSecondAsHz, "|root|"),
      core::field("natural_frequency_se", &S::natural_frequency_se, kRadPerSecondAsHz, "standard error of |root|"),
      core::field("damping", &S::damping, kRatio, "-Re root / |root|"),
      core::field("damping_se", &S::damping_se, kRatio, "standard error of the damping"),
      core::field("real_se", &S::real_se, kRadPerSecond, "standard error of Re root"),
      core::field("imag_se", &S::imag_se, kRadPerSecond, "standard error of Im root"));
}

struct VectorFitUncertainty {
  core::FitCovariance covariance;  // of the model's real parameters, in the order of `names`
  std::vector<std::string> names;  // "p3.re", "p3.im" (pair), "p0" (real pole), "r1.3.re", "d1", "e1"
  std::vector<RootUncertainty> poles;  // one per fit.poles entry, same order (a pair's two share errors)
  bool from_data_variance = false;     // std_H given; else the noise estimated from the residuals
};

constexpr auto describe(core::Type<VectorFitUncertainty>) {
  using S = VectorFitUncertainty;
  using namespace core::shown;
  return core::fields<S>("VectorFitUncertainty", "a vector fit's covariance, and its poles with their standard errors",
      core::field("covariance", &S::covariance, kNone, "of the model's real parameters, in the order of names"),
      core::field("names", &S::names, kNone, "\"p3.re\", \"p3.im\" (pair), \"p0\" (real pole), \"r1.3.re\" (residue), \"d1\", \"e1\""),
      core::field("poles", &S::poles, kNone, "one per pole of the fit, same order (a pair's two share errors)"),
      core::field("from_data_variance", &S::from_data_variance, kNone, "true: the FRF's std_H; false: the noise estimated from the residuals"));
}

// omega: rad/s, the fit's points; data: points x outputs, as fitted; fit: vector_fit's result on
// them with `options` and `weights` (the fit's own row weights follow: vector_fitting_weights);
// std_H: the data's standard deviation per part (points x outputs, data units; empty: unknown).
// adjacent_correlation: with std_H, the real correlation of the data's (circular) error between
// points k and k+1 of every output (omega.size() - 1 values; a Welch estimate's neighbouring lines,
// dsp::adjacent_line_pairs; empty: none), which core::fit_covariance's sandwich takes in.
// InputError (source "vector fit uncertainty") for mismatched sizes or fewer residuals than
// parameters.
[[nodiscard]] VectorFitUncertainty vector_fit_uncertainty(const Vector& omega, const CMatrix& data, const VectorFittingResult& fit,
                                                          const VectorFittingOptions& options, const Matrix& weights = {},
                                                          const Matrix& std_H = {}, const Vector& adjacent_correlation = {});

// All outputs of an FRF, as vector_fit(frf, options) fitted them: its std_H when every output
// carries one, with the correlation of neighbouring lines its provenance gives (the Welch window and
// overlap: dsp::resolution_kernel, as the plant fits take it), else the noise estimated from the
// residuals. Errors as above.
[[nodiscard]] VectorFitUncertainty vector_fit_uncertainty(const dsp::Frf& frf, const VectorFittingResult& fit,
                                                          const VectorFittingOptions& options);

// The covariance of (Re, Im) of output `output` of the fit at s (rad/s; s = 0: the DC gain, whose Im
// is 0), from u by the delta method. InputError as zero_uncertainty; infinite when u is singular.
[[nodiscard]] Eigen::Matrix2d response_covariance(const VectorFittingResult& fit, const VectorFitUncertainty& u, Index output, Complex s);

// The zeros `zeros` (rad/s) of output `output` of the fit, with their standard errors from u.
[[nodiscard]] std::vector<RootUncertainty> zero_uncertainty(const VectorFittingResult& fit, const VectorFitUncertainty& u,
                                                            Index output, const CVector& zeros);

}  // namespace piezobench::ident
