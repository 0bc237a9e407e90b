#include "piezobench/ident/added_mass.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "piezobench/core/error.hpp"

namespace piezobench::ident::added_mass_test {
namespace {

using Eigen::VectorXd;

constexpr double kFs = 1000.0;        // Hz
constexpr double kMass = 6.4;         // kg
constexpr double kGravity = 9.8;      // m/s^2
constexpr double kStiffness = 1.8e6;  // N/m
constexpr double kTon = 3.0, kToff = 13.0;  // s

// The added-mass record of an APA of stiffness kStiffness: d_e = d0 - (w + c1 F_1[w] + c10 F_10[w])
// / k, w the weight (N) on over [3, 13) s, F_j the Prony creep states of 1 and 10 s (fit_creep's
// model, its default time constants for a 20 s record).
struct Record {
  VectorXd t, de, mass;
};
Record record(double c1, double c10) {
  const Eigen::Index n = 20000;
  Record r;
  r.t = VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1) / kFs);
  r.mass = VectorXd::Zero(n);
  for (Eigen::Index k = 0; k < n; ++k) r.mass(k) = r.t(k) >= kTon && r.t(k) < kToff ? kMass : 0.0;
  std::vector<double> w(static_cast<std::size_t>(n));
  for (Eigen::Index k = 0; k < n; ++k) w[static_cast<std::size_t>(k)] = r.mass(k) * kGravity;
  const std::vector<double> tau = {1.0, 10.0};
  const Eigen::MatrixXd f = creep_states(w, tau, kFs);
  r.de.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) r.de(k) = 2e-6 - (w[static_cast<std::size_t>(k)] + c1 * f(k, 0) + c10 * f(k, 1)) / kStiffness;
  return r;
}

AddedMassOptions options() {
  AddedMassOptions o;
  o.stiffness.added_mass = kMass;
  o.stiffness.gravity = kGravity;
  o.source = "test";
  return o;
}

// Without creep: k1 = k2 = k, the Prony gain is the compliance -1/k and its coefficients 0; the
// weight from the mass log and from the detected [t_on, t_off) give the same fit.
TEST(AddedMass, ElasticRecordGivesTheStiffness) {
  const Record r = record(0.0, 0.0);
  const AddedMassAnalysis logged = analyze_added_mass(r.t, r.de, r.mass, kFs, options());
  EXPECT_TRUE(logged.failed.empty());
  EXPECT_TRUE(logged.mass_log);
  EXPECT_NEAR(logged.stiffness.k1, kStiffness, 1e-9 * kStiffness);
  EXPECT_NEAR(logged.stiffness.k2, kStiffness, 1e-9 * kStiffness);
  EXPECT_NEAR(logged.stiffness.t_on, kTon, 0.5 / kFs);
  ASSERT_TRUE(logged.creep.has_value());
  EXPECT_NEAR(logged.creep->gain, -1.0 / kStiffness, 1e-9 / kStiffness);
  EXPECT_NEAR(logged.creep->creep_per_decade, 0.0, 1e-9);
  const AddedMassAnalysis detected = analyze_added_mass(r.t, r.de, VectorXd(), kFs, options());
  EXPECT_FALSE(detected.mass_log);
  ASSERT_TRUE(detected.creep.has_value());
  EXPECT_NEAR(detected.creep->gain, logged.creep->gain, 1e-9 / kStiffness);
  EXPECT_NEAR(detected.stiffness.k1, kStiffness, 1e-9 * kStiffness);
}

// With creep: the Prony fit recovers the coefficients; k1 and k2 are the means of the reading
// windows (computed here from the samples), so k1 < k (the creep while loaded) and k1 < k2.
TEST(AddedMass, CreepRecordGivesTheReadingsAndThePronySeries) {
  const Record r = record(0.1, 0.05);
  const AddedMassAnalysis a = analyze_added_mass(r.t, r.de, r.mass, kFs, options());
  ASSERT_TRUE(a.creep.has_value());
  EXPECT_NEAR(a.creep->gain, -1.0 / kStiffness, 1e-6 / kStiffness);
  ASSERT_EQ(a.creep->coefficients.size(), 2u);
  EXPECT_NEAR(a.creep->coefficients[0], 0.1, 1e-6);
  EXPECT_NEAR(a.creep->coefficients[1], 0.05, 1e-6);
  const auto mean = [&](double from, double to) {
    double s = 0.0;
    int n = 0;
    for (Eigen::Index k = 0; k < r.t.size(); ++k) {
      if (r.t(k) >= from && r.t(k) < to) {
        s += r.de(k);
        ++n;
      }
    }
    return s / n;
  };
  const double before = mean(kTon - 1.0, kTon - 0.1), loaded = mean(kToff - 1.0, kToff - 0.1), after = mean(kToff + 1.0, kToff + 2.0);
  EXPECT_NEAR(a.stiffness.k1, kMass * kGravity / std::abs(before - loaded), 1e-6 * kStiffness);
  EXPECT_NEAR(a.stiffness.k2, kMass * kGravity / std::abs(after - loaded), 1e-6 * kStiffness);
  EXPECT_LT(a.stiffness.k1, kStiffness);
  EXPECT_LT(a.stiffness.k1, a.stiffness.k2);
}

TEST(AddedMass, WeightFromTheLogOrTheEvents) {
  const VectorXd t = VectorXd::LinSpaced(5, 0.0, 4.0);
  const VectorXd step = added_weight_N(t, VectorXd(), 1.0, 3.0, 2.0, 9.8);
  EXPECT_EQ(step, (VectorXd(5) << 0.0, 19.6, 19.6, 0.0, 0.0).finished());
  const VectorXd log = added_weight_N(t, (VectorXd(5) << 0.0, 1.0, 2.0, 1.0, 0.0).finished(), 1.0, 3.0, 2.0, 10.0);
  EXPECT_EQ(log, (VectorXd(5) << 0.0, 10.0, 20.0, 10.0, 0.0).finished());
  const Record r = record(0.0, 0.0);
  EXPECT_THROW(analyze_added_mass(r.t, r.de, r.mass.head(100), kFs, options()), InputError);
}

}  // namespace
}  // namespace piezobench::ident::added_mass_test
