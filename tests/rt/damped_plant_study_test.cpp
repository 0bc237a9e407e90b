#include "piezobench/rt/damped_plant_study.hpp"

#include <gtest/gtest.h>

#include "piezobench/control/iff.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/delay.hpp"
#include "piezobench/lti/interconnect.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
namespace {

// Figure 2.10b on the virtual bench: identified damped poles against the model's root locus.
TEST(DampedPlantStudy, IdentifiedPolesFollowTheRootLocus) {
  DampedPlantStudyOptions o;
  o.gains = {0.0, 1e5, 2e5};  // below the optimum (about 2.4e5 to 2.8e5 for the bench's units)
  o.duration = 2.0;
  o.settle = 1.0;
  const DampedPlantStudy s = run_damped_plant_study(o);
  ASSERT_EQ(s.points.size(), 3u);
  EXPECT_EQ(s.model, "2dof");
  EXPECT_DOUBLE_EQ(s.delay, 200e-6);
  // The model's optimum (lti::max_damping_on_branch) is of the report's order: its own model gives
  // a damping of 0.40 at g = 2.8e5 (docs/performance.md, lti section).
  EXPECT_GT(s.optimal_gain, 2.0e5);
  EXPECT_LT(s.optimal_gain, 4.0e5);
  EXPECT_GT(s.max_damping, 0.35);
  for (const auto& p : s.points) {
    SCOPED_TRACE("gain " + std::to_string(p.gain));
    EXPECT_LT(p.relative_error, 0.05);  // the check
    EXPECT_EQ(p.clamped_samples, 0u);
    EXPECT_EQ(p.safe_state_events, 0u);
    EXPECT_GT(p.mean_coherence, 0.95);
    // The measured FRF is the model's damped plant (g = 0: the Hann window's leakage at the
    // 0.6 % damped resonance dominates the difference, see DampedPlantPoint).
    if (p.gain > 0.0) {
      EXPECT_LT(p.frf_model_relative_rms, 0.03);
    }
    EXPECT_GT(p.identified_frequency_Hz, 50.0);
    EXPECT_LT(p.identified_frequency_Hz, 100.0);
  }
  EXPECT_TRUE(s.within_tolerance);
  EXPECT_LT(s.max_relative_error, 0.05);
  // Open loop: the bench's lightly damped 95 Hz resonance.
  EXPECT_TRUE(test::near(s.points[0].identified_frequency_Hz, s.points[0].model_frequency_Hz, 0.005));
  EXPECT_LT(s.points[0].identified_damping, 0.02);
  // Damping grows with the gain up to the optimum, and the pole moves to lower frequencies
  // (report section 2.6).
  EXPECT_TRUE(s.damping_increases_to_optimum);
  EXPECT_GT(s.points[1].identified_damping, 5.0 * s.points[0].identified_damping);
  EXPECT_GT(s.points[2].identified_damping, s.points[1].identified_damping);
  EXPECT_GT(s.points[2].identified_damping, 0.3);
  EXPECT_LT(s.points[2].identified_frequency_Hz, s.points[1].identified_frequency_Hz);
  // The model pole is a closed-loop pole of linear_model() (delay by a 6th-order Pade
  // approximant) with g K0(s) in positive feedback u = u' + g K0 Vs, computed here independently of
  // the root-locus code.
  const bench::VirtualBench bench(bench::batch_unit(1, 1), bench::BenchOptions{}, 1);
  const lti::StateSpace k = lti::scale(lti::to_state_space(control::iff_controller()), 1e5);
  const lti::StateSpace closed =
      lti::feedback(lti::pade(bench.linear_model(), 6), k, {0}, {1}, lti::FeedbackSign::kPositive);
  const lti::CVector poles = lti::poles(closed);
  double nearest = 1e300;
  for (const auto& pole : poles) nearest = std::min(nearest, std::abs(pole - s.points[1].model_pole));
  EXPECT_LT(nearest, 1e-6 * std::abs(s.points[1].model_pole));
}

TEST(DampedPlantStudy, OptionsAreValidated) {
  auto bad = [](auto mutate, const std::string& field) {
    DampedPlantStudyOptions o;
    mutate(o);
    test::input_error([&] { run_damped_plant_study(o); }, field);
  };
  bad([](DampedPlantStudyOptions& o) { o.gains = {}; }, "gains");
  bad([](DampedPlantStudyOptions& o) { o.gains = {1e5, -1.0}; }, "gains");
  bad([](DampedPlantStudyOptions& o) { o.duration = 0.5; }, "duration");  // shorter than one period
  bad([](DampedPlantStudyOptions& o) { o.f_high = 6000.0; }, "f_high");
  bad([](DampedPlantStudyOptions& o) { o.fit_fmax = 1.0; }, "fit_fmax");
  bad([](DampedPlantStudyOptions& o) { o.fit_order = 1; }, "fit_order");
  bad([](DampedPlantStudyOptions& o) { o.unit = 9; }, "unit");
}

}  // namespace
}  // namespace piezobench::rt
