// Model updating of the shipped APA300ML super element (campaign/superelement_update.hpp) against
// scipy: scripts/superelement/update_apa300ml.py (numpy's own beams and eigensolver on the same
// Matrix Market files) gives the features and the updated scales quoted below.
#include "piezobench/campaign/superelement_update.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "test_util.hpp"

namespace piezobench::campaign {
namespace {

namespace fs = std::filesystem;

struct Shipped {
  fem::SuperElementSetup setup;
  fem::SuperElement se;
  SuperElementUpdateOptions options;
  Shipped() {
    const fs::path d = fs::path(PIEZOBENCH_SOURCE_DIR) / "data/superelement/apa300ml";
    setup.source = "test";
    setup.format = "matrix-market";
    setup.k_file = d / "apa300ml_K.mtx";
    setup.m_file = d / "apa300ml_M.mtx";
    setup.nodes_file = d / "apa300ml_dofs.txt";
    setup.model.fixed_nodes = {40893};
    setup.model.forces = {fem::ForcePair::parse("40895:40899:x", "actuator")};
    setup.model.outputs = {fem::DisplacementOutput::parse("40891:y", "output"), fem::DisplacementOutput::parse("40899:40897:x", "sensor")};
    se = setup.load();
    options.bench.moving_mass = 5.7;
    options.stacks = {StackBeam::parse("40895:40899:" + kStack, "stack"), StackBeam::parse("40899:40897:" + kStack, "stack")};
    options.shell_modulus_Pa = 210.8e9;
  }
  static inline const std::string kStack = "29.4e9,0.31,7800,1e-4";
};

// scipy (update_apa300ml.py --shell-modulus 210.8e9 --stack-modulus 29.4e9): the shipped element
// on the bench.
constexpr double kShippedResonance = 95.35757882364197;
constexpr double kShippedAntiresonance = 41.10454859271803;

TEST(SuperElementUpdate, FeaturesOfTheShippedElementAsScipy) {
  const Shipped s;
  const BenchFeatures f = bench_features(s.se, s.setup, s.options.bench);
  EXPECT_NEAR(f.resonance_Hz, kShippedResonance, 1e-6 * kShippedResonance);
  EXPECT_NEAR(f.antiresonance_Hz, kShippedAntiresonance, 1e-6 * kShippedAntiresonance);
}

// scipy's update to 100 Hz and 40 Hz (update_apa300ml.py --resonance 100 --antiresonance 40).
TEST(SuperElementUpdate, ShellAndStacksAsScipy) {
  const Shipped s;
  const SuperElementUpdate u = update_superelement(s.se, s.setup, {{"a", 100.0, 40.0}}, s.options);
  ASSERT_EQ(u.parameters.size(), 2u);
  EXPECT_NEAR(u.parameters[0].scale, 0.9469783149956141, 1e-5);
  EXPECT_NEAR(u.parameters[1].scale, 1.2226632347149908, 1e-5);
  EXPECT_NEAR(*u.parameters[0].modulus_Pa, 0.9469783149956141 * 210.8e9, 1e-5 * 210.8e9);
  EXPECT_NEAR(u.resonance_Hz, 100.0, 1e-6);
  EXPECT_NEAR(u.antiresonance_Hz, 40.0, 1e-6);
  EXPECT_EQ(u.rank, 2);
  // The anti-resonance sees the shell only (sqrt of its stiffness), the resonance both.
  EXPECT_NEAR(u.sensitivity(1, 0), 0.5, 0.02);
  EXPECT_NEAR(u.sensitivity(1, 1), 0.0, 0.02);
  // One unit: no scatter, no standard error, and a warning says so.
  EXPECT_FALSE(u.parameters[0].standard_error);
  EXPECT_EQ(u.warnings.size(), 1u);
  // The updated element has the updated features when read back by the bench model.
  const BenchFeatures f = bench_features(u.element, s.setup, s.options.bench);
  EXPECT_NEAR(f.resonance_Hz, 100.0, 1e-6);
}

// Two units: the standard error of the mean of two values is half their difference, so each
// scale's standard error is (to first order) half the difference of the scales each unit alone
// gives; the correlation is that of the two units' scale differences: +-1.
TEST(SuperElementUpdate, StandardErrorsFromTheUnitsScatter) {
  const Shipped s;
  const std::vector<UpdateTarget> units{{"a", 100.0, 40.0}, {"b", 100.5, 40.1}};
  const SuperElementUpdate both = update_superelement(s.se, s.setup, units, s.options);
  const SuperElementUpdate a = update_superelement(s.se, s.setup, {units[0]}, s.options);
  const SuperElementUpdate b = update_superelement(s.se, s.setup, {units[1]}, s.options);
  for (std::size_t i = 0; i < 2; ++i) {
    ASSERT_TRUE(both.parameters[i].standard_error);
    const double half = 0.5 * std::abs(b.parameters[i].scale - a.parameters[i].scale);
    EXPECT_NEAR(*both.parameters[i].standard_error, half, 0.02 * half) << i;
  }
  EXPECT_NEAR(std::abs(both.correlation(0, 1)), 1.0, 1e-6);
  EXPECT_NEAR(both.correlation(0, 0), 1.0, 1e-12);
  EXPECT_TRUE(both.warnings.empty());
}

// Three moduli from two features: refused, naming an undetermined parameter; a stack named twice
// (stacks and one of them) and unknown names are refused before any work.
TEST(SuperElementUpdate, RefusesWhatTheDataCannotDetermine) {
  Shipped s;
  s.options.parameters = {"shell", "stack:40895:40899", "stack:40899:40897"};
  test::expect_input_error([&] { (void)update_superelement(s.se, s.setup, {{"a", 100.0, 40.0}}, s.options); }, {"not determined by the data"});
  s.options.parameters = {"shell", "stacks", "stack:40899:40897"};
  test::expect_input_error([&] { (void)update_superelement(s.se, s.setup, {{"a", 100.0, 40.0}}, s.options); }, {"overlap"});
  s.options.parameters = {"shell", "blades"};
  test::expect_input_error([&] { (void)update_superelement(s.se, s.setup, {{"a", 100.0, 40.0}}, s.options); }, {"blades"});
  s.options.parameters = {"shell", "stacks"};
  test::expect_input_error([&] { (void)update_superelement(s.se, s.setup, {{"a", 40.0, 100.0}}, s.options); }, {"anti-resonance"});
  test::expect_input_error([&] { (void)StackBeam::parse("40895:x:48e9,0.31,7800,1e-4", "--stack"); }, {"--stack"});
}

}  // namespace
}  // namespace piezobench::campaign
