#include "piezobench/ident/vector_fitting.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/dsp/frf.hpp"
#include "test_util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {
namespace {

using test::all_near;
using test::near;
using test::Tolerance;

// Noise-free data from an exact rational model of the fitted order: vector fitting converges to the
// generating poles up to the conditioning of the lightly damped pairs (issue 3 asks for 1e-6).
constexpr double kExactPoles = 1e-6;
// 1 % complex Gaussian noise on ~1000 points: the pole estimates scatter by about
// 0.01 / sqrt(points in the half-power band) * |p|; issue 3 asks for 2e-3 relative.
constexpr double kNoisyPoles = 2e-3;

Complex pole_from(double f_Hz, double zeta) {
  const double wn = kTwoPi * f_Hz;
  return {-zeta * wn, wn * std::sqrt(1.0 - zeta * zeta)};
}

// Canonical order of the result: real poles, then pairs by increasing Im, Im > 0 first.
struct Model {
  CVector poles;
  CMatrix residues;  // outputs x N
  Vector d;
  Vector e;
  CMatrix response(const Vector& omega) const {
    CMatrix h(omega.size(), residues.rows());
    for (Index k = 0; k < omega.size(); ++k) {
      const Complex s(0.0, omega(k));
      for (Index i = 0; i < residues.rows(); ++i) {
        Complex v = d(i) + s * e(i);
        for (Index n = 0; n < poles.size(); ++n) v += residues(i, n) / (s - poles(n));
        h(k, i) = v;
      }
    }
    return h;
  }
};

// Order 6: three lightly damped pairs, damping 0.4 % to 5 % (issue 3).
Model six_pole_model() {
  Model m;
  const Complex p1 = pole_from(41.0, 0.004), p2 = pole_from(95.0, 0.02), p3 = pole_from(280.0, 0.05);
  m.poles.resize(6);
  m.poles << p1, std::conj(p1), p2, std::conj(p2), p3, std::conj(p3);
  const Complex r1(2.0e2, 30.0), r2(-5.0e3, 1.0e3), r3(8.0e3, -4.0e3);
  m.residues.resize(1, 6);
  m.residues << r1, std::conj(r1), r2, std::conj(r2), r3, std::conj(r3);
  m.d = Vector::Constant(1, 0.5);
  m.e = Vector::Zero(1);
  return m;
}

using test::log_grid;

CMatrix add_relative_noise(const CMatrix& h, double level, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, level / std::sqrt(2.0));
  CMatrix out = h;
  for (Index i = 0; i < h.size(); ++i) out.data()[i] *= Complex(1.0 + gauss(rng), gauss(rng));
  return out;
}

TEST(VectorFitting, RecoversSixLightlyDampedPolesWithoutNoise) {
  const Model m = six_pole_model();
  const Vector omega = log_grid(5.0, 1000.0, 800);
  VectorFittingOptions o;
  o.order = 6;
  const VectorFittingResult r = vector_fit(omega, m.response(omega), o);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.convergence, Convergence::kPolesSettled);
  EXPECT_LT(r.iterations, o.max_iterations);
  EXPECT_TRUE(all_near(r.poles, m.poles, Tolerance{kExactPoles, 0.0}));
  EXPECT_TRUE(all_near(r.residues, m.residues, Tolerance{1e-5, 0.0}));
  EXPECT_TRUE(near(r.d(0), 0.5, 1e-6));
  EXPECT_LT(r.relative_rms_error, 1e-8);
}

TEST(VectorFitting, RecoversPolesWithOnePercentNoise) {
  const Model m = six_pole_model();
  const Vector omega = log_grid(5.0, 1000.0, 1000);
  const CMatrix noisy = add_relative_noise(m.response(omega), 0.01, 7);
  VectorFittingOptions o;
  o.order = 6;
  o.weighting = Weighting::kInverseMagnitude;  // relative noise: weight by 1/|H|
  const VectorFittingResult r = vector_fit(omega, noisy, o);
  EXPECT_TRUE(r.converged) << r.brief_report();
  // Noise keeps the poles moving slightly; the fit error settles first.
  EXPECT_EQ(r.convergence, Convergence::kResidualSettled);
  EXPECT_TRUE(all_near(r.poles, m.poles, Tolerance{kNoisyPoles, 0.0}));
  // The residual is the noise itself: about 1 % of the data in relative rms.
  EXPECT_GT(r.relative_rms_error, 0.003);
  EXPECT_LT(r.relative_rms_error, 0.02);
}

TEST(VectorFitting, NonRelaxedFormulationAlsoRecoversThePoles) {
  const Model m = six_pole_model();
  const Vector omega = log_grid(5.0, 1000.0, 800);
  VectorFittingOptions o;
  o.order = 6;
  o.relaxed = false;
  const VectorFittingResult r = vector_fit(omega, m.response(omega), o);
  EXPECT_TRUE(all_near(r.poles, m.poles, Tolerance{kExactPoles, 0.0}));
}

TEST(VectorFitting, SeveralOutputsShareThePolesWithRealPoleAndDE) {
  Model m;
  const Complex p1 = pole_from(12.0, 0.01), p2 = pole_from(150.0, 0.03);
  m.poles.resize(5);
  m.poles << Complex(-kTwoPi * 30.0, 0.0), p1, std::conj(p1), p2, std::conj(p2);
  m.residues.resize(3, 5);
  const Complex a(1.0, 2.0), b(-30.0, 5.0), c(3.0, -1.0), dd(10.0, 10.0), e1(-2.0, 0.5), f(40.0, -7.0);
  m.residues << 50.0, a, std::conj(a), b, std::conj(b),  //
      -20.0, c, std::conj(c), dd, std::conj(dd),          //
      5.0, e1, std::conj(e1), f, std::conj(f);
  m.d = Vector(3);
  m.d << 0.1, -0.2, 0.0;
  m.e = Vector(3);
  m.e << 1e-4, 0.0, -2e-4;
  Vector omega = Vector::LinSpaced(600, 0.0, kTwoPi * 400.0);  // includes DC
  VectorFittingOptions o;
  o.order = 5;
  o.asymptote = Asymptote::kConstantAndLinear;
  o.starting_spacing = PoleSpacing::kLinear;
  const VectorFittingResult r = vector_fit(omega, m.response(omega), o);
  EXPECT_TRUE(r.converged);
  EXPECT_TRUE(all_near(r.poles, m.poles, Tolerance{kExactPoles, 0.0}));
  EXPECT_TRUE(all_near(r.residues, m.residues, Tolerance{1e-6, 1e-6}));
  EXPECT_TRUE(all_near(r.d, m.d, Tolerance{1e-6, 1e-9}));
  EXPECT_TRUE(all_near(r.e, m.e, Tolerance{1e-6, 1e-12}));
}

TEST(VectorFitting, WideFrequencySpanIsHandledByScaling) {
  // Poles from 0.05 Hz to 20 kHz: 5.6 decades; the data span 0.01 Hz .. 50 kHz.
  Model m;
  const Complex p1 = pole_from(0.05, 0.02), p2 = pole_from(30.0, 0.004), p3 = pole_from(20e3, 0.05);
  m.poles.resize(7);
  m.poles << Complex(-kTwoPi * 2.0, 0.0), p1, std::conj(p1), p2, std::conj(p2), p3, std::conj(p3);
  m.residues.resize(1, 7);
  m.residues << 3.0, Complex(0.01, 0.001), Complex(0.01, -0.001), Complex(1.0, 0.5), Complex(1.0, -0.5),
      Complex(2.0e3, 100.0), Complex(2.0e3, -100.0);
  m.d = Vector::Constant(1, 1e-3);
  m.e = Vector::Zero(1);
  const Vector omega = log_grid(0.01, 5e4, 1200);
  VectorFittingOptions o;
  o.order = 7;
  const VectorFittingResult r = vector_fit(omega, m.response(omega), o);
  EXPECT_TRUE(r.converged) << r.brief_report();
  EXPECT_TRUE(all_near(r.poles, m.poles, Tolerance{kExactPoles, 0.0}));
  EXPECT_LT(r.relative_rms_error, 1e-8);
}

TEST(VectorFitting, OrderCloseToHalfThePointsStillFits) {
  // 10 poles from 21 points: 42 real equations against 2*10 + 1 + 1 unknowns per output.
  Model m;
  m.poles.resize(10);
  m.residues.resize(1, 10);
  for (int i = 0; i < 5; ++i) {
    const Complex p = pole_from(10.0 * (i + 1), 0.02);
    const Complex res(10.0 * (i + 1), -3.0 * i);
    m.poles(2 * i) = p;
    m.poles(2 * i + 1) = std::conj(p);
    m.residues(0, 2 * i) = res;
    m.residues(0, 2 * i + 1) = std::conj(res);
  }
  m.d = Vector::Constant(1, 0.2);
  m.e = Vector::Zero(1);
  const Vector omega = Vector::LinSpaced(21, kTwoPi * 5.0, kTwoPi * 60.0);
  VectorFittingOptions o;
  o.order = 10;
  o.starting_spacing = PoleSpacing::kLinear;
  const VectorFittingResult r = vector_fit(omega, m.response(omega), o);
  EXPECT_TRUE(r.converged) << r.brief_report();
  EXPECT_TRUE(all_near(r.poles, m.poles, Tolerance{1e-6, 0.0}));
}

TEST(VectorFitting, TooFewPointsIsAnInputErrorNamingTheOrder) {
  const Model m = six_pole_model();
  const Vector omega = log_grid(5.0, 1000.0, 6);  // 12 equations < 2*6 + 1 + 1
  VectorFittingOptions o;
  o.order = 6;
  try {
    (void)vector_fit(omega, m.response(omega), o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "order");
    EXPECT_NE(std::string(e.what()).find("at most 5 poles"), std::string::npos) << e.what();
  }
  // One point more is enough: 7 points, 14 equations.
  EXPECT_NO_THROW((void)vector_fit(log_grid(5.0, 1000.0, 7), m.response(log_grid(5.0, 1000.0, 7)),
                                   [] {
                                     VectorFittingOptions x;
                                     x.order = 6;
                                     x.fail_if_not_converged = false;
                                     return x;
                                   }()));
}

TEST(VectorFitting, BadInputIsRejectedWithTheField) {
  const Model m = six_pole_model();
  const Vector omega = log_grid(5.0, 1000.0, 100);
  const CMatrix h = m.response(omega);
  VectorFittingOptions o;
  const auto field_of = [&](const Vector& w, const CMatrix& data, const Matrix& weights) {
    try {
      (void)vector_fit(w, data, weights, o);
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  CMatrix with_nan = h;
  with_nan(10, 0) = Complex(std::nan(""), 0.0);
  EXPECT_EQ(field_of(omega, with_nan, Matrix()), "data(10, 0)");
  Vector unsorted = omega;
  std::swap(unsorted(3), unsorted(4));
  EXPECT_EQ(field_of(unsorted, h, Matrix()), "omega[4]");
  Vector negative = omega;
  negative(0) = -1.0;
  EXPECT_EQ(field_of(negative, h, Matrix()), "omega[0]");
  EXPECT_EQ(field_of(omega, h.topRows(50), Matrix()), "data");
  EXPECT_EQ(field_of(omega, CMatrix::Zero(100, 1), Matrix()), "data");
  EXPECT_EQ(field_of(omega, h, Matrix::Ones(99, 1)), "weights");
  EXPECT_EQ(field_of(omega, h, Matrix::Zero(100, 1)), "weights");
  EXPECT_EQ(field_of(omega, h, Matrix::Ones(100, 1)), "no error");
  o.point_weights = Vector::Ones(99);
  EXPECT_EQ(field_of(omega, h, Matrix()), "point_weights");
}

TEST(VectorFitting, PointWeightsDiscountCorruptedPoints) {
  // Every 10th point off by 30 %: with unit weights the poles move (by more than 1e-6); with those
  // points weighted 1e-9 (as 1/std weighs points of huge variance) the fit finds the generating poles.
  const Model m = six_pole_model();
  const Vector omega = log_grid(5.0, 1000.0, 800);
  CMatrix h = m.response(omega);
  Vector point_weights = Vector::Ones(omega.size());
  for (Index k = 0; k < omega.size(); k += 10) {
    h(k, 0) *= 1.3;
    point_weights(k) = 1e-9;
  }
  VectorFittingOptions o;
  o.order = 6;
  o.fail_if_not_converged = false;
  const VectorFittingResult plain = vector_fit(omega, h, o);
  EXPECT_FALSE(all_near(plain.poles, m.poles, Tolerance{1e-6, 0.0}));
  o.point_weights = point_weights;
  const VectorFittingResult weighted = vector_fit(omega, h, o);
  EXPECT_TRUE(all_near(weighted.poles, m.poles, Tolerance{1e-6, 0.0})) << weighted.brief_report();
  // The same as the explicit weights argument, and they multiply the weighting's own weights.
  const VectorFittingResult explicit_weights = vector_fit(omega, h, Matrix(point_weights), [] {
    VectorFittingOptions x;
    x.order = 6;
    x.fail_if_not_converged = false;
    return x;
  }());
  EXPECT_TRUE(all_near(weighted.poles, explicit_weights.poles, Tolerance{1e-12, 0.0}));
  o.weighting = Weighting::kInverseMagnitude;
  Matrix combined(omega.size(), 1);
  for (Index k = 0; k < omega.size(); ++k) combined(k, 0) = point_weights(k) / std::abs(h(k, 0));
  const VectorFittingResult both = vector_fit(omega, h, o);
  VectorFittingOptions unit = o;
  unit.weighting = Weighting::kUnit;
  unit.point_weights = Vector();
  EXPECT_TRUE(all_near(both.poles, vector_fit(omega, h, combined, unit).poles, Tolerance{1e-12, 0.0}));
}

TEST(VectorFitting, OptionsValidateNamesTheField) {
  const auto field_of = [](const VectorFittingOptions& o) {
    try {
      o.validate();
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  VectorFittingOptions o;
  EXPECT_EQ(field_of(o), "no error");
  o.order = 0;
  EXPECT_EQ(field_of(o), "order");
  o = VectorFittingOptions{};
  o.pole_tolerance = -1.0;
  EXPECT_EQ(field_of(o), "pole_tolerance");
  o = VectorFittingOptions{};
  o.starting_damping = 0.0;
  EXPECT_EQ(field_of(o), "starting_damping");
  o = VectorFittingOptions{};
  o.max_iterations = -1;
  EXPECT_EQ(field_of(o), "max_iterations");
  o = VectorFittingOptions{};
  o.order = 2;
  o.starting_poles = CVector(2);
  o.starting_poles << Complex(-1.0, 5.0), Complex(-1.0, 4.0);  // not a conjugate pair
  EXPECT_EQ(field_of(o), "starting_poles");
  o.starting_poles << Complex(-1.0, 5.0), Complex(-1.0, -5.0);
  EXPECT_EQ(field_of(o), "no error");
  o.starting_poles = CVector::Constant(3, Complex(-1.0, 0.0));
  EXPECT_EQ(field_of(o), "starting_poles");
  o = VectorFittingOptions{};
  o.frequency_scale = -3.0;
  EXPECT_EQ(field_of(o), "frequency_scale");
  o = VectorFittingOptions{};
  o.residual_tolerance = -1.0;
  EXPECT_EQ(field_of(o), "residual_tolerance");
  o = VectorFittingOptions{};
  o.significance_floor = 1.0;
  EXPECT_EQ(field_of(o), "significance_floor");
  o = VectorFittingOptions{};
  o.point_weights = Vector::Ones(5);
  EXPECT_EQ(field_of(o), "no error");
  o.point_weights(3) = 0.0;
  EXPECT_EQ(field_of(o), "point_weights[3]");
  o.point_weights(3) = std::nan("");
  EXPECT_EQ(field_of(o), "point_weights[3]");
}

TEST(VectorFitting, NotSettlingIsANumericalErrorThatMayBeRetried) {
  // Pure noise has no rational structure: the poles keep moving.
  const Vector omega = log_grid(1.0, 100.0, 200);
  const CMatrix noise = add_relative_noise(CMatrix::Ones(200, 1), 1.0, 3);
  VectorFittingOptions o;
  o.order = 8;
  o.max_iterations = 3;
  o.pole_tolerance = 1e-14;
  o.residual_tolerance = 0.0;
  try {
    (void)vector_fit(omega, noise, o);
    FAIL() << "expected NumericalError";
  } catch (const NumericalError& e) {
    EXPECT_TRUE(e.retry_may_help());
    EXPECT_EQ(e.exit_code(), ExitCode::kNumerical);
  }
  o.fail_if_not_converged = false;
  const VectorFittingResult r = vector_fit(omega, noise, o);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 3);
  EXPECT_GT(r.last_pole_change, 1e-14);
}

TEST(VectorFitting, UnstablePolesAreFlippedUnlessAllowed) {
  Model m;
  const Complex stable = pole_from(20.0, 0.02);
  const Complex unstable(+0.03 * kTwoPi * 60.0, kTwoPi * 60.0);
  m.poles.resize(4);
  m.poles << stable, std::conj(stable), unstable, std::conj(unstable);
  m.residues.resize(1, 4);
  m.residues << Complex(5.0, 1.0), Complex(5.0, -1.0), Complex(20.0, 3.0), Complex(20.0, -3.0);
  m.d = Vector::Zero(1);
  m.e = Vector::Zero(1);
  const Vector omega = log_grid(2.0, 300.0, 400);
  VectorFittingOptions o;
  o.order = 4;
  o.asymptote = Asymptote::kNone;
  o.fail_if_not_converged = false;
  const VectorFittingResult flipped = vector_fit(omega, m.response(omega), o);
  EXPECT_TRUE((flipped.poles.real().array() < 0.0).all());
  o.enforce_stable_poles = false;
  o.fail_if_not_converged = true;
  const VectorFittingResult free = vector_fit(omega, m.response(omega), o);
  EXPECT_TRUE(all_near(free.poles, m.poles, Tolerance{kExactPoles, 0.0}));
}

TEST(VectorFitting, StateSpaceModelReproducesThePoleResidueForm) {
  const Model m = six_pole_model();
  const Vector omega = log_grid(5.0, 1000.0, 400);
  VectorFittingOptions o;
  o.order = 6;
  const VectorFittingResult r = vector_fit(omega, m.response(omega), o);
  const lti::StateSpace& ss = r.model;
  ASSERT_EQ(ss.states(), 6);
  ASSERT_EQ(ss.inputs(), 1);
  ASSERT_EQ(ss.outputs(), 1);
  // Real block-diagonal form: no complex arithmetic in A, B, C, D.
  const Vector probe = log_grid(1.0, 2000.0, 50);
  const CMatrix expected = r.evaluate(probe);
  for (Index k = 0; k < probe.size(); ++k) {
    const Complex s(0.0, probe(k));
    const CMatrix sI_A = s * CMatrix::Identity(6, 6) - ss.A.cast<Complex>();
    const CMatrix h = ss.C.cast<Complex>() * sI_A.partialPivLu().solve(ss.B.cast<Complex>()) + ss.D.cast<Complex>();
    EXPECT_TRUE(near(h(0, 0), expected(k, 0), Tolerance{1e-12, 0.0})) << "at " << probe(k) << " rad/s";
  }
  // And the data it was fitted to.
  EXPECT_TRUE(all_near(r.evaluate(omega), m.response(omega), Tolerance{1e-7, 0.0}));
}

TEST(VectorFitting, UserStartingPolesAndZeroIterationsGiveTheResidues) {
  const Model m = six_pole_model();
  const Vector omega = log_grid(5.0, 1000.0, 300);
  VectorFittingOptions o;
  o.order = 6;
  o.starting_poles = m.poles;
  o.max_iterations = 0;
  const VectorFittingResult r = vector_fit(omega, m.response(omega), o);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(all_near(r.poles, m.poles, Tolerance{1e-15, 0.0}));
  EXPECT_TRUE(all_near(r.residues, m.residues, Tolerance{1e-9, 0.0}));
}

TEST(VectorFitting, FrfOverloadUsesHertzAndAllOutputs) {
  const Model m = six_pole_model();
  dsp::Frf frf;
  frf.freq_Hz = log_grid(5.0, 1000.0, 500) / kTwoPi;
  frf.input = "u";
  frf.outputs = {"y"};
  frf.H = {m.response(kTwoPi * frf.freq_Hz).col(0)};
  frf.provenance.source = "data.csv";
  VectorFittingOptions o;
  o.order = 6;
  const VectorFittingResult r = vector_fit(frf, o);
  EXPECT_TRUE(all_near(r.poles, m.poles, Tolerance{kExactPoles, 0.0}));
  frf.freq_Hz(3) = frf.freq_Hz(2);
  try {
    (void)vector_fit(frf, o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("data.csv"), std::string::npos) << e.what();
  }
}

TEST(VectorFitting, EnumsRoundTripThroughStrings) {
  for (Asymptote a : {Asymptote::kNone, Asymptote::kConstant, Asymptote::kConstantAndLinear}) {
    EXPECT_EQ(asymptote_from_string(to_string(a)), a);
  }
  for (PoleSpacing p : {PoleSpacing::kLogarithmic, PoleSpacing::kLinear}) {
    EXPECT_EQ(pole_spacing_from_string(to_string(p)), p);
  }
  for (Weighting w : {Weighting::kUnit, Weighting::kInverseMagnitude, Weighting::kInverseSqrtMagnitude}) {
    EXPECT_EQ(weighting_from_string(to_string(w)), w);
  }
  for (Convergence c : {Convergence::kNotConverged, Convergence::kPolesSettled, Convergence::kResidualSettled}) {
    EXPECT_EQ(convergence_from_string(to_string(c)), c);
  }
  EXPECT_THROW((void)asymptote_from_string("D+E"), InputError);
  EXPECT_THROW((void)pole_spacing_from_string("octave"), InputError);
  EXPECT_THROW((void)weighting_from_string("none"), InputError);
}

// An FRF without std_H cannot be weighted by it: InputError naming the file and the output.
TEST(VectorFitting, InverseStdWeightingNeedsTheStdH) {
  dsp::Frf frf;
  frf.freq_Hz = Vector::LinSpaced(50, 10.0, 500.0);
  frf.input = "u";
  frf.outputs = {"d_e"};
  frf.H = {CVector::Constant(50, Complex(1.0, 0.1))};
  frf.provenance.source = "lab.csv";
  VectorFittingOptions o;
  o.order = 2;
  o.weighting = Weighting::kInverseStd;
  try {
    (void)vector_fit(frf, o);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lab.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("std_H of d_e"), std::string::npos) << e.what();
  }
  frf.std_H = {Vector::Constant(50, 0.01)};
  frf.std_H[0](7) = 0.0;  // a computed response's 0: no weight can be had
  EXPECT_THROW((void)vector_fit(frf, o), InputError);
  frf.std_H[0](7) = 0.02;
  const Matrix w = frf_row_weights(frf, o);
  ASSERT_EQ(w.rows(), 50);
  EXPECT_DOUBLE_EQ(w(7, 0), 50.0);
  EXPECT_DOUBLE_EQ(w(0, 0), 100.0);
  o.weighting = Weighting::kOutputScale;
  EXPECT_EQ(frf_row_weights(frf, o).size(), 0);
  EXPECT_EQ(weighting_from_string("inverse-std"), Weighting::kInverseStd);
  EXPECT_EQ(to_string(Weighting::kInverseStd), "inverse-std");
  // Without an FRF there is no std_H to weight by.
  o.weighting = Weighting::kInverseStd;
  EXPECT_THROW((void)vector_fit(kTwoPi * frf.freq_Hz, CMatrix(frf.H[0]), o), InputError);
}

}  // namespace
}  // namespace piezobench::ident
