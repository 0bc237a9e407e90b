// The private FFTW wrapper against a naive DFT (the same test over both "backends").
#include "fft.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <future>
#include <numbers>
#include <random>
#include <thread>

#include "test_util.hpp"

namespace piezobench::dsp::detail {
namespace {

using Eigen::Index;

Eigen::VectorXcd naive_rfft(const Eigen::VectorXd& x) {
  const Index n = x.size();
  Eigen::VectorXcd X(n / 2 + 1);
  for (Index k = 0; k <= n / 2; ++k) {
    std::complex<double> s = 0.0;
    for (Index j = 0; j < n; ++j) {
      s += x(j) * std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>((j * k) % n) / static_cast<double>(n));
    }
    X(k) = s;
  }
  return X;
}

class FftLength : public ::testing::TestWithParam<Index> {};

TEST_P(FftLength, MatchesNaiveDftAndInvertsBack) {
  const Index n = GetParam();
  std::mt19937_64 rng(static_cast<std::uint64_t>(n));
  std::normal_distribution<double> normal;
  Eigen::VectorXd x(n);
  for (Index i = 0; i < n; ++i) x(i) = normal(rng);
  const Eigen::VectorXcd X = rfft(x);
  // O(n) sums of unit-modulus terms: absolute error ~ eps sqrt(n) |x|.
  EXPECT_TRUE(test::all_near(X, naive_rfft(x), test::Tolerance{0, 1e-12 * x.norm()}));
  EXPECT_TRUE(test::all_near(irfft(X, n), x, test::Tolerance{0, 1e-13}));
}

INSTANTIATE_TEST_SUITE_P(Lengths, FftLength, ::testing::Values(2, 3, 8, 97, 100, 127, 256, 1000, 1009),
                         [](const ::testing::TestParamInfo<Index>& param_info) {
                           std::string name = "n";  // not "n" + ...: GCC 12 -Wrestrict false positive
                           name += std::to_string(param_info.param);
                           return name;
                         });

TEST(Fft, PlansAreSharedAndUsableFromSeveralThreads) {
  const Index n = 720;
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  const Eigen::VectorXcd expected = rfft(x);
  std::vector<Eigen::VectorXcd> results(4);
  {
    std::vector<std::jthread> threads;
    for (std::size_t t = 0; t < results.size(); ++t) threads.emplace_back([&, t] { results[t] = rfft(x); });
  }
  for (const auto& r : results) EXPECT_EQ(r, expected);
}

TEST(Fft, PlansMadeInTheBackgroundGiveTheSameTransforms) {
  // The same numbers whichever thread made the plan, short (planned by get()) or long (a thread).
  for (const Index n : {Index{720}, Index{3} << 16}) {
    SCOPED_TRACE(n);
    Eigen::VectorXd x(n);
    for (Index i = 0; i < n; ++i) x(i) = std::sin(0.37 * static_cast<double>(i)) + 1e-3 * static_cast<double>(i % 7);
    std::future<void> plans = plan_in_background(n);
    // Meanwhile another thread uses the other plans (the planner is serialized by the cache).
    const Eigen::VectorXcd other = rfft(Eigen::VectorXd::LinSpaced(64, 0.0, 1.0));
    plans.get();
    const Eigen::VectorXcd X = rfft(x);
    EXPECT_NEAR(std::abs(X(0) - x.sum()), 0.0, 1e-9 * x.cwiseAbs().sum());
    EXPECT_TRUE(test::all_near(irfft(X, n), x, test::Tolerance{0, 1e-12}));
    EXPECT_EQ(other, rfft(Eigen::VectorXd::LinSpaced(64, 0.0, 1.0)));
    // Only the inverse (band_limited_noise's use): it too gives the same numbers.
    const Index m = n + 2;
    plan_in_background(m, PlanDirections::kInverse).get();
    const Eigen::VectorXd y = Eigen::VectorXd::LinSpaced(m, -1.0, 2.0).array().sin();
    EXPECT_TRUE(test::all_near(irfft(rfft(y), m), y, test::Tolerance{0, 1e-12}));
  }
}

}  // namespace
}  // namespace piezobench::dsp::detail
