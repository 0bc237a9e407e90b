#include "piezobench/ident/hysteresis.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "piezobench/core/error.hpp"

namespace piezobench::ident {
namespace {

std::vector<double> sine(double offset, double amplitude, int periods, int per_period, double ramp_from = 0.0) {
  std::vector<double> v;
  // A ramp from `ramp_from` to the offset, then the periods.
  for (int k = 0; k < per_period; ++k) v.push_back(ramp_from + (offset - ramp_from) * k / per_period);
  for (int k = 0; k <= periods * per_period; ++k) {
    v.push_back(offset + amplitude * std::sin(2.0 * std::numbers::pi * k / per_period));
  }
  return v;
}

PrandtlIshlinskii random_operator(std::mt19937_64& rng, bool negative_weights) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  PrandtlIshlinskii h;
  const int n = 1 + static_cast<int>(u(rng) * 12);
  h.linear_weight = 0.2 + 2.0 * u(rng);
  double r = 0.0, sum = h.linear_weight;
  for (int i = 0; i < n; ++i) {
    r += 0.5 + 20.0 * u(rng);
    double w = 0.8 * u(rng);
    // Negative weights as long as every partial sum stays above 10 % of w_0.
    if (negative_weights && u(rng) < 0.4) w = -std::min(w, sum - 0.1 * h.linear_weight);
    sum += w;
    h.thresholds.push_back(r);
    h.weights.push_back(w);
  }
  return h;
}

std::vector<double> random_input(std::mt19937_64& rng, int n) {
  std::normal_distribution<double> step(0.0, 4.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> v(static_cast<std::size_t>(n));
  double x = 0.0;
  for (double& s : v) {
    x += u(rng) < 0.02 ? 60.0 * (u(rng) - 0.5) : step(rng);  // small steps and now and then a jump
    s = x;
  }
  return v;
}

// The property of the issue: the inverse composed with the operator is the identity to 1e-9 (both
// ways), on random operators and random inputs.
TEST(PrandtlIshlinskii, InverseComposedWithOperatorIsTheIdentity) {
  std::mt19937_64 rng(20261125);
  for (int trial = 0; trial < 200; ++trial) {
    const PrandtlIshlinskii h = random_operator(rng, trial % 2 == 1);
    const PrandtlIshlinskii g = inverse(h);
    const std::vector<double> v = random_input(rng, 2000);
    const std::vector<double> y = evaluate(h, v);
    const std::vector<double> back = evaluate(g, y);
    const std::vector<double> forth = evaluate(h, evaluate(g, v));
    for (std::size_t k = 0; k < v.size(); ++k) {
      ASSERT_NEAR(back[k], v[k], 1e-9) << "trial " << trial << " sample " << k;
      ASSERT_NEAR(forth[k], v[k], 1e-9) << "trial " << trial << " sample " << k;
    }
    // The inverse of the inverse is the operator.
    const PrandtlIshlinskii hh = inverse(g);
    for (std::size_t i = 0; i < h.thresholds.size(); ++i) {
      ASSERT_NEAR(hh.thresholds[i], h.thresholds[i], 1e-9 * h.thresholds.back());
      ASSERT_NEAR(hh.weights[i], h.weights[i], 1e-12);
    }
  }
}

// One play operator: H = v + w P_r has the inverse y - w / (1 + w) P_r[y] (r' = r).
TEST(PrandtlIshlinskii, InverseOfOnePlayOperatorIsAnalytic) {
  const PrandtlIshlinskii g = inverse({1.0, {5.0}, {0.5}});
  EXPECT_DOUBLE_EQ(g.linear_weight, 1.0);
  EXPECT_DOUBLE_EQ(g.thresholds[0], 5.0);
  EXPECT_DOUBLE_EQ(g.weights[0], -0.5 / 1.5);
}

// For a sine of amplitude A about any offset, once every operator has turned: the loop's half range
// is A + sum_{r_i < A} w_i (A - r_i) and its width at the offset sum_{r_i < A} 2 w_i min(r_i, A - r_i).
TEST(PrandtlIshlinskii, SineLoopMatchesTheClosedForm) {
  const PrandtlIshlinskii h{1.0, {10.0, 20.0, 30.0, 40.0, 90.0}, {0.2, 0.1, 0.3, 0.15, 0.4}};
  const double a = 50.0, offset = 65.0;
  const int per = 4000;
  const std::vector<double> v = sine(offset, a, 3, per);
  const std::vector<double> y = evaluate(h, v);
  double half = a, width = 0.0;
  for (std::size_t i = 0; i < h.thresholds.size(); ++i) {
    if (h.thresholds[i] < a) {
      half += h.weights[i] * (a - h.thresholds[i]);
      width += 2.0 * h.weights[i] * std::min(h.thresholds[i], a - h.thresholds[i]);
    }
  }
  // Last period: extremes and the two crossings of the offset (k = 0 and per / 2 into the period).
  const std::size_t start = v.size() - 1 - per;
  double lo = 1e300, hi = -1e300;
  for (std::size_t k = start; k < v.size(); ++k) {
    lo = std::min(lo, y[k]);
    hi = std::max(hi, y[k]);
  }
  EXPECT_NEAR(0.5 * (hi - lo), half, 1e-9);
  EXPECT_NEAR(y[start + per / 2] - y[start], width, 1e-9);  // descending minus ascending branch
}

HysteresisModel true_model(bool creep) {
  HysteresisModel m;
  m.hysteresis.thresholds.clear();
  const int n = 8;
  const double range = 80.0;  // half the range of the record below (65 +- 80 V)
  const double w[n] = {0.05, 0.2, 0.0, 0.12, 0.08, 0.0, 0.03, 0.01};
  for (int i = 0; i < n; ++i) {
    m.hysteresis.thresholds.push_back((i + 0.5) * range / n);
    m.hysteresis.weights.push_back(w[i]);
  }
  if (creep) {
    m.creep_time_constants = {0.5, 5.0};
    m.creep_coefficients = {0.02, 0.03};
  }
  m.gain = -1.5e-6;
  m.offset = 3e-6;
  return m;
}

// A record made by a PI operator with the fit's own thresholds: the fit finds its weights exactly.
TEST(HysteresisFit, RecoversAPrandtlIshlinskiiRecord) {
  for (bool creep : {false, true}) {
    const HysteresisModel truth = true_model(creep);
    std::vector<double> va = sine(65.0, 80.0, 3, 2000);
    for (std::size_t k = 0; k < 2000; ++k) va.push_back(65.0 - 65.0 * static_cast<double>(k) / 2000.0);  // back to 0
    const double fs = 1000.0;
    const std::vector<double> de = truth.predict(va, fs);
    HysteresisFitOptions o;
    o.operators = 8;
    o.creep_time_constants = truth.creep_time_constants;
    const HysteresisFit f = fit_hysteresis(va, de, fs, o);
    EXPECT_FALSE(f.quality.poor()) << f.quality.summary();
    EXPECT_LT(f.relative_residual, 1e-9);
    EXPECT_NEAR(f.model.gain, truth.gain, 1e-9 * std::abs(truth.gain));
    EXPECT_NEAR(f.model.offset, truth.offset, 1e-9 * std::abs(truth.offset));
    for (std::size_t i = 0; i < 8; ++i) {
      EXPECT_NEAR(f.model.hysteresis.thresholds[i], truth.hysteresis.thresholds[i], 1e-12);
      EXPECT_NEAR(f.model.hysteresis.weights[i], truth.hysteresis.weights[i], 1e-7) << i;
    }
    for (std::size_t j = 0; j < truth.creep_coefficients.size(); ++j) {
      EXPECT_NEAR(f.model.creep_coefficients[j], truth.creep_coefficients[j], 1e-7) << j;
    }
    EXPECT_DOUBLE_EQ(f.model.input_max, 145.0);
    EXPECT_GT(f.model.reference_slope, 1.0);  // the loop's large-signal gain
  }
}

// A loop the PI operator cannot draw (asymmetric: the output squared) gives a poor verdict.
TEST(HysteresisFit, AsymmetricLoopIsAPoorFit) {
  const std::vector<double> va = sine(0.0, 80.0, 3, 2000);
  std::vector<double> de = evaluate({1.0, {20.0}, {0.5}}, va);
  for (double& d : de) d = 1e-6 * d * d / 100.0;  // even in Va: a PI operator's loops are odd
  HysteresisFitOptions o;
  o.max_relative_residual = 0.02;
  const HysteresisFit f = fit_hysteresis(va, de, 1000.0, o);
  EXPECT_TRUE(f.quality.poor());
  EXPECT_NE(f.quality.summary().find("rms residual"), std::string::npos);
}

// Kuhnen's modified PI: the output dead-zone superposition's inverse composed with it is the
// identity to 1e-9 (both ways) on random maps and inputs, and the whole modified operator's
// inverse (S^-1 then H^-1) composed with it too.
TEST(DeadZoneSuperposition, InverseComposedWithItIsTheIdentity) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    DeadZoneSuperposition s;
    const int n = static_cast<int>(u(rng) * 8);
    double x = -100.0 * u(rng), y = -80.0 * u(rng);
    for (int k = 0; k < n; ++k) {
      s.x.push_back(x);
      s.y.push_back(y);
      x += 0.5 + 30.0 * u(rng);
      y += (0.5 + 30.0 * u(rng)) * (0.1 + 2.0 * u(rng));
    }
    s.slope_below = 0.05 + 3.0 * u(rng);
    s.slope_above = 0.05 + 3.0 * u(rng);
    const DeadZoneSuperposition inv = inverse(s);
    const PrandtlIshlinskii h = random_operator(rng, true);
    const PrandtlIshlinskii hinv = inverse(h);
    std::vector<double> z = random_input(rng, 300), sz(z.size()), hz(z.size());
    for (std::size_t k = 0; k < z.size(); ++k) {
      ASSERT_NEAR(inv(s(z[k])), z[k], 1e-9 * (1.0 + std::abs(z[k])));
      ASSERT_NEAR(s(inv(z[k])), z[k], 1e-9 * (1.0 + std::abs(z[k])));
    }
    // The modified operator S[H[v]] and its inverse H^-1[S^-1[y]].
    const std::vector<double> hv = evaluate(h, z);
    for (std::size_t k = 0; k < z.size(); ++k) sz[k] = inv(s(hv[k]));  // S^-1 S H = H
    const std::vector<double> back = evaluate(hinv, sz);
    for (std::size_t k = 0; k < z.size(); ++k) ASSERT_NEAR(back[k], z[k], 1e-9 * (1.0 + std::abs(z[k]))) << trial;
  }
  DeadZoneSuperposition bad{{0.0, 1.0}, {0.0, -1.0}, 1.0, 1.0};
  EXPECT_THROW(bad.validate(), InputError);
  bad = {{0.0, 1.0}, {0.0, 1.0}, 0.0, 1.0};
  EXPECT_THROW(bad.validate(), InputError);
}

// An asymmetric loop from a law outside both model families: Bouc-Wen (dh = alpha dv - beta |dv| h
// - gamma dv |h|, integrated in fine steps) seen through a smooth, asymmetric output (x + kappa x^2,
// x = v - h). The plain PI operator is flagged poor; Kuhnen's modified PI fits it.
TEST(HysteresisFit, ModifiedPrandtlIshlinskiiFitsAnAsymmetricBoucWenLoop) {
  const std::vector<double> va = sine(65.0, 80.0, 3, 2000);
  std::vector<double> de(va.size());
  double h = 0.0, prev = 0.0;
  for (std::size_t k = 0; k < va.size(); ++k) {
    const int sub = 20;
    const double dv = (va[k] - prev) / sub;
    for (int i = 0; i < sub; ++i) h += 0.3 * dv - 0.02 * std::abs(dv) * h - 0.005 * dv * std::abs(h);
    prev = va[k];
    const double x = va[k] - h;
    de[k] = -1e-6 * (x + 0.006 * x * x);
  }
  HysteresisFitOptions plain;
  const HysteresisFit p = fit_hysteresis(va, de, 1000.0, plain);
  HysteresisFitOptions modified;
  modified.dead_zones = 4;
  const HysteresisFit m = fit_hysteresis(va, de, 1000.0, modified);
  std::printf("asymmetric Bouc-Wen loop: plain PI residual %.2f %% of the stroke (%s), modified PI %.3f %% (%s)\n",
              100.0 * p.relative_residual, core::to_string(p.quality.verdict).c_str(), 100.0 * m.relative_residual,
              core::to_string(m.quality.verdict).c_str());
  EXPECT_TRUE(p.quality.poor());
  EXPECT_FALSE(m.quality.poor());
  EXPECT_LT(m.relative_residual, 0.5 * p.relative_residual);
  EXPECT_FALSE(m.model.output.identity());
  // Its prediction is the residual's: output error, not the equation error of the fit.
  const std::vector<double> pred = m.model.predict(va, 1000.0);
  double sum = 0.0;
  for (std::size_t k = 0; k < va.size(); ++k) sum += (pred[k] - de[k]) * (pred[k] - de[k]);
  EXPECT_NEAR(std::sqrt(sum / static_cast<double>(va.size())), m.rms_residual, 1e-15);
  HysteresisFitOptions bad;
  bad.dead_zones = 51;
  EXPECT_THROW(fit_hysteresis(va, de, 1000.0, bad), InputError);
}

TEST(HysteresisFit, RefusesBadRecords) {
  const std::vector<double> va = sine(65.0, 20.0, 1, 100);
  std::vector<double> de(va.size(), 1e-6);
  EXPECT_THROW(fit_hysteresis(va, std::span<const double>(de).first(10), 1000.0), InputError);
  EXPECT_THROW(fit_hysteresis(std::vector<double>(va.size(), 1.0), de, 1000.0), InputError);
  EXPECT_THROW(fit_hysteresis(va, de, 1000.0), NumericalError);  // d_e does not follow Va
  de[5] = std::nan("");
  EXPECT_THROW(fit_hysteresis(va, de, 1000.0), InputError);
  HysteresisFitOptions o;
  o.operators = 0;
  EXPECT_THROW(fit_hysteresis(va, va, 1000.0, o), InputError);
  EXPECT_THROW(inverse({1.0, {5.0, 4.0}, {0.1, 0.1}}), InputError);   // thresholds not increasing
  EXPECT_THROW(inverse({1.0, {5.0, 6.0}, {-0.6, -0.6}}), InputError); // not invertible
}

// A step record y = offset + gain (x + sum c_j F_j[x]): the creep fit finds it.
TEST(CreepFit, RecoversAPronySeries) {
  const double fs = 100.0;
  std::vector<double> x(6000, 0.0);
  for (std::size_t k = 300; k < 4000; ++k) x[k] = -62.7;  // a weight on, then off
  const std::vector<double> tau = {1.0, 10.0};
  const Eigen::MatrixXd f = creep_states(x, tau, fs);
  std::vector<double> y(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    const auto kk = static_cast<Eigen::Index>(k);
    y[k] = 1e-7 + 2e-8 * (x[k] + 0.1 * f(kk, 0) + 0.2 * f(kk, 1));
  }
  const CreepFit c = fit_creep(x, y, fs, tau);
  EXPECT_FALSE(c.quality.poor()) << c.quality.summary();
  EXPECT_NEAR(c.gain, 2e-8, 1e-16);
  EXPECT_NEAR(c.coefficients[0], 0.1, 1e-7);
  EXPECT_NEAR(c.coefficients[1], 0.2, 1e-7);
  EXPECT_NEAR(c.creep_per_decade, 0.15, 1e-7);
  // Default time constants: 1, 10 s for a 60 s record.
  const CreepFit d = fit_creep(x, y, fs);
  ASSERT_EQ(d.time_constants.size(), 2u);
  EXPECT_NEAR(d.coefficients[1], 0.2, 1e-7);
}

// y = sin + e cos against c = sin: best line slope 1, deviation e cos, width e / sqrt(1 + e^2).
TEST(LoopMetrics, EllipseHasTheAnalyticWidth) {
  const double e = 0.2;
  std::vector<double> c, y;
  for (int k = 0; k < 10000; ++k) {
    const double t = 2.0 * std::numbers::pi * k / 10000.0;
    c.push_back(3.0 + std::sin(t));
    y.push_back(2.0 * (std::sin(t) + e * std::cos(t)) - 1.0);
  }
  const LoopMetrics m = loop_metrics(c, y);
  EXPECT_NEAR(m.slope, 2.0, 1e-9);
  EXPECT_NEAR(m.intercept, -7.0, 1e-9);
  EXPECT_NEAR(m.width, e / std::sqrt(1.0 + e * e), 1e-6);
  EXPECT_NEAR(m.rms_deviation, 2.0 * e / std::sqrt(2.0), 1e-9);
  EXPECT_THROW(loop_metrics(std::vector<double>(5, 1.0), std::vector<double>(5, 2.0)), InputError);
  EXPECT_LT(m.asymmetry, 1e-12);  // an ellipse is point-symmetric about its centre
}

// The asymmetry: 0 for the loops a PI operator draws (point-symmetric about their centre), the x^2
// coefficient over the stroke for a bent loop: y = x + b x^2 + 0.05 cos on x = sin (mid-range 0,
// half-range 1) over whole periods has the cubic fit x + b x^2 (cos is orthogonal to 1, x, x^2, x^3).
TEST(LoopMetrics, AsymmetryIsTheBendOfTheLoop) {
  const double b = 0.1;
  std::vector<double> c, y, pi_c, pi_y;
  PrandtlIshlinskiiOperator h(PrandtlIshlinskii{1.0, {5.0, 15.0, 25.0}, {0.3, 0.2, 0.4}});
  for (int k = 0; k < 50000; ++k) {
    const double s = std::sin(2.0 * std::numbers::pi * k / 10000.0);
    c.push_back(s);
    y.push_back(s + b * s * s + 0.05 * std::cos(2.0 * std::numbers::pi * k / 10000.0));
    const double v = 40.0 + 30.0 * s;
    const double out = h.step(v);
    if (k >= 10000) {  // whole periods after the first
      pi_c.push_back(v);
      pi_y.push_back(out);
    }
  }
  const LoopMetrics bent = loop_metrics(c, y);
  EXPECT_NEAR(bent.asymmetry * bent.stroke, b, 1e-9);  // the cos (the loop's opening) is orthogonal to the cubic
  const LoopMetrics pi = loop_metrics(pi_c, pi_y);
  EXPECT_GT(pi.width, 0.1);
  EXPECT_LT(pi.asymmetry, 1e-6);
}

}  // namespace
}  // namespace piezobench::ident

namespace piezobench::ident {
namespace {

// Explicit thresholds (HysteresisFitOptions::thresholds): a record made by a PI operator with the
// same thresholds gives its weights back exactly; bad thresholds are refused.
TEST(FitHysteresis, ExplicitThresholdsGiveTheOperatorsWeightsBack) {
  PrandtlIshlinskii h;
  h.thresholds = {10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0};
  h.weights = {0.22, 0.1, 0.3, 0.0, 0.15, 0.25, 0.05, 0.2};
  const std::vector<double> v = sine(65.0, 80.0, 3, 2000);
  std::vector<double> d = evaluate(h, v);
  for (double& x : d) x *= -1.5e-6;  // m per effective volt, the APA shortens
  HysteresisFitOptions o;
  o.thresholds = h.thresholds;
  const HysteresisFit f = fit_hysteresis(v, d, 1000.0, o);
  ASSERT_EQ(f.model.hysteresis.weights.size(), 8u);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(f.model.hysteresis.weights[i], h.weights[i], 1e-9) << i;
  EXPECT_NEAR(f.model.gain, -1.5e-6, 1e-15);
  o.thresholds = {10.0, 10.0};
  EXPECT_THROW(fit_hysteresis(v, d, 1000.0, o), InputError);
}

}  // namespace
}  // namespace piezobench::ident
