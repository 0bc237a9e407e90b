// The tracking experiment (bench/tracking.hpp) on the virtual bench with the second hysteresis law
// (Bouc-Wen: not the identified family), the check: at 80 V, hysteresis width below 3 % of
// the stroke with the inverse feedforward against about 18 % without, and the rms tracking error
// of the 1 Hz sine reduced at least 5 times. The figures are printed (docs/performance.md).
#include "piezobench/bench/tracking.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::bench {
namespace {

io::TimeSeries record(HysteresisLaw law, const ExperimentOptions& base = {}) {
  ExperimentOptions o = base;
  o.bench.hysteresis_law = law;
  return simulate(Experiment::kTracking, batch_unit(2, 1), o, 1);
}

void print(const char* what, const TrackingSummary& s) {
  for (const auto& [name, f] : {std::pair<const char*, const TrackingFigures&>{"sine", s.sine}, {"triangle", s.triangle}}) {
    std::printf("%s %-8s width %.2f %% -> %.2f %% of the stroke (%.1fx), rms tracking error %.3f um -> %.3f um (%.1fx), stroke %.1f um\n",
                what, name, 100.0 * f.width_open, 100.0 * f.width_ff, f.width_reduction(), 1e6 * f.rms_open, 1e6 * f.rms_ff,
                f.rms_reduction(), 1e6 * f.stroke_open);
  }
  std::printf("%s fit residual %.3f %% of the stroke, clamped samples %.0f\n", what, 100.0 * s.fit_relative_residual, s.clamped_samples);
}

TEST(Tracking, FeedforwardCancelsTheBoucWenHysteresis) {
  const io::TimeSeries r = record(HysteresisLaw::kBoucWen);
  EXPECT_EQ(r.names, (std::vector<std::string>{"c", "Va_open", "de_open", "Va_ff", "de_ff"}));
  const TrackingSummary s = tracking_summary(r);
  print("bouc-wen 80 V:", s);
  EXPECT_TRUE(s.identified);
  EXPECT_GT(s.sine.width_open, 0.15);
  EXPECT_LT(s.sine.width_open, 0.21);
  EXPECT_LT(s.sine.width_ff, 0.03);
  EXPECT_LT(s.triangle.width_ff, 0.03);
  EXPECT_GE(s.sine.rms_reduction(), 5.0);
  EXPECT_GE(s.triangle.rms_reduction(), 5.0);
  // The applied voltage stayed within the stacks' range.
  EXPECT_GE(r.data.col(3).minCoeff(), -20.0 - 1e-9);
  EXPECT_LE(r.data.col(3).maxCoeff(), 150.0 + 1e-9);
}

// The model given instead of identified: the same figures as the identified one when it is the
// identified one.
TEST(Tracking, GivenModelAndOptionChecks) {
  ExperimentOptions o;
  o.amplitude = 40.0;
  const io::TimeSeries first = record(HysteresisLaw::kPrandtlIshlinskii, o);
  const Eigen::VectorXd va = first.data.col(1), de = first.data.col(2);
  o.feedforward = ident::fit_hysteresis({va.data(), static_cast<std::size_t>(va.size())}, {de.data(), static_cast<std::size_t>(de.size())},
                                        first.sample_rate)
                      .model;
  const io::TimeSeries given = record(HysteresisLaw::kPrandtlIshlinskii, o);
  EXPECT_EQ(std::get<std::string>(given.settings.at("feedforward")), "given");
  const TrackingSummary a = tracking_summary(first), b = tracking_summary(given);
  EXPECT_NEAR(a.sine.rms_ff, b.sine.rms_ff, 1e-12);
  EXPECT_LT(b.sine.width_ff, 0.03);
  o.amplitude = 90.0;  // 65 + 90 > 150 V
  EXPECT_THROW(record(HysteresisLaw::kBoucWen, o), InputError);
  ExperimentOptions wrong;
  wrong.feedforward = o.feedforward;
  EXPECT_THROW(simulate(Experiment::kHysteresis, batch_unit(2, 1), wrong, 1), InputError);
  EXPECT_THROW(tracking_summary(simulate(Experiment::kCapacitance, batch_unit(2, 1), {}, 1)), InputError);
}

// A synthetic record whose figures are known: c = 65 + 80 sin(2 pi t), de_open = line + h cos(2 pi t)
// (an ellipse around the line: cos is orthogonal to sin and to 1 over whole periods, so the line
// is the best one, the width is 2 h / stroke and the rms error h / sqrt(2)); de_ff = the line.
TEST(Tracking, LayoutAndFiguresOfAKnownRecord) {
  const double fs = 1000.0, slope = -1.2e-6, intercept = 3e-6, h = 10e-6;
  const Eigen::Index n = 8000;  // 1 s ramp, 3 + 3 periods, 1 s ramp
  io::TimeSeries r;
  r.source = "known.mat";
  r.sample_rate = fs;
  r.names = {"c", "Va_open", "de_open", "Va_ff", "de_ff"};
  r.data.setZero(n, 5);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs, ph = 2.0 * std::numbers::pi * t;
    r.data(k, 0) = 65.0 + 80.0 * std::sin(ph);
    r.data(k, 2) = slope * r.data(k, 0) + intercept + h * std::cos(ph);
    r.data(k, 4) = slope * r.data(k, 0) + intercept;
  }
  r.settings = {{"ramp_s", 1.0}, {"periods", 3.0}, {"frequency_Hz", 1.0}, {"amplitude_V", 80.0},
                {"target_slope_m_per_V", slope}, {"target_intercept_m", intercept}};
  const TrackingLayout l = tracking_layout(r);
  EXPECT_EQ(l.sine_begin, 2000);
  EXPECT_EQ(l.sine_end, 4000);
  EXPECT_EQ(l.triangle_begin, 5000);
  EXPECT_EQ(l.triangle_end, 7000);
  EXPECT_EQ(l.amplitude, 80.0);
  const auto col = [&](Eigen::Index j) {
    return std::span<const double>(r.data.col(j).data() + l.sine_begin, static_cast<std::size_t>(l.sine_end - l.sine_begin));
  };
  const TrackingFigures f = tracking_figures(col(0), col(2), col(4), l.target_slope, l.target_intercept);
  const double stroke = f.stroke_open;
  EXPECT_NEAR(f.width_open, 2.0 * h / stroke, 1e-3 * 2.0 * h / stroke);
  EXPECT_NEAR(f.rms_open, h / std::sqrt(2.0), 1e-9 * h);
  EXPECT_NEAR(f.width_ff, 0.0, 1e-9);
  EXPECT_NEAR(f.rms_ff, 0.0, 1e-15);
  // Missing settings and too short a record name what is wrong.
  io::TimeSeries bad = r;
  bad.settings.erase("periods");
  EXPECT_THROW((void)tracking_layout(bad), InputError);
  bad = r;
  bad.settings["frequency_Hz"] = 0.5;  // 3 periods of 2 s: 14 s > 8 s
  EXPECT_THROW((void)tracking_layout(bad), InputError);
  EXPECT_THROW((void)tracking_figures(col(0), col(2).first(10), col(4), slope, intercept), InputError);
}

}  // namespace
}  // namespace piezobench::bench
