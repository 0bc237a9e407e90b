#include "piezobench/io/hysteresis_toml.hpp"

#include <gtest/gtest.h>

#include "piezobench/core/error.hpp"

namespace piezobench::io {
namespace {

ident::HysteresisModel model() {
  ident::HysteresisModel m;
  m.hysteresis = {1.0, {5.0, 15.0}, {0.1, 0.25}};
  m.creep_time_constants = {1.0, 10.0};
  m.creep_coefficients = {0.01, 0.02};
  m.gain = -1.6e-6;
  m.offset = 2e-8;
  m.reference_slope = 1.4;
  m.reference_intercept = -3.0;
  m.input_min = -15.0;
  m.input_max = 145.0;
  return m;
}

TEST(HysteresisToml, RoundTripsExactly) {
  ident::HysteresisFit fit;
  fit.rms_residual = 1e-8;
  fit.samples = 100;
  const std::string text = hysteresis_model_toml(model(), &fit, "rec \"1\".mat");
  const ident::HysteresisModel back = parse_hysteresis_model(text, "m.toml");
  const ident::HysteresisModel m = model();
  EXPECT_EQ(back.hysteresis.thresholds, m.hysteresis.thresholds);
  EXPECT_EQ(back.hysteresis.weights, m.hysteresis.weights);
  EXPECT_EQ(back.creep_time_constants, m.creep_time_constants);
  EXPECT_EQ(back.creep_coefficients, m.creep_coefficients);
  EXPECT_EQ(back.gain, m.gain);
  EXPECT_EQ(back.offset, m.offset);
  EXPECT_EQ(back.reference_slope, m.reference_slope);
  EXPECT_EQ(back.reference_intercept, m.reference_intercept);
  EXPECT_EQ(back.input_max, m.input_max);
  EXPECT_TRUE(back.output.identity());
  // Kuhnen's modified PI: its output map S round-trips too.
  ident::HysteresisModel mod = model();
  mod.output = {{-40.0, 0.0, 25.0}, {-30.0, 0.0, 20.0}, 0.6, 0.7};
  const ident::HysteresisModel mb = parse_hysteresis_model(hysteresis_model_toml(mod), "mod.toml");
  EXPECT_EQ(mb.output.x, mod.output.x);
  EXPECT_EQ(mb.output.y, mod.output.y);
  EXPECT_EQ(mb.output.slope_below, 0.6);
  EXPECT_EQ(mb.output.slope_above, 0.7);
}

// A file written by hand (as a user would), without creep or fit sections.
TEST(HysteresisToml, ReadsAHandWrittenFile) {
  const std::string text =
      "format = \"piezobench-hysteresis-1\"\n"
      "gain_m_per_V = -1.5e-6\noffset_m = 0\nreference_slope = 1\nreference_intercept_V = 0\n"
      "input_min_V = 0\ninput_max_V = 100\n[hysteresis]\nthresholds_V = [10, 20]\nweights = [0.2, 0.1]\n";
  const ident::HysteresisModel m = parse_hysteresis_model(text, "hand.toml");
  EXPECT_EQ(m.hysteresis.thresholds.size(), 2u);
  EXPECT_TRUE(m.creep_time_constants.empty());
  EXPECT_DOUBLE_EQ(m.hysteresis.weights[1], 0.1);
}

void expect_error(const std::string& text, const std::string& field) {
  try {
    (void)parse_hysteresis_model(text, "bad.toml");
    FAIL() << "no error for " << field;
  } catch (const InputError& e) {
    EXPECT_EQ(e.source().rfind("bad.toml", 0), 0u) << e.source();  // "bad.toml" or "bad.toml: line L"
    EXPECT_EQ(e.field(), field) << e.what();
  }
}

TEST(HysteresisToml, NamesTheBadKey) {
  const std::string head =
      "format = \"piezobench-hysteresis-1\"\ngain_m_per_V = -1.5e-6\noffset_m = 0\nreference_slope = 1\n"
      "reference_intercept_V = 0\ninput_min_V = 0\ninput_max_V = 100\n";
  expect_error(head + "[hysteresis]\nthresholds_V = [10, 5]\nweights = [0.2, 0.1]\n", "thresholds[1]");
  expect_error(head + "[hysteresis]\nthresholds_V = [10]\nweights = [\"a\"]\n", "hysteresis.weights[0]");
  expect_error(head + "[hysteresis]\nthresholds_V = [10]\n", "hysteresis.weights");
  expect_error(head + "[hysteresis]\nthresholds_V = [10]\nweights = [0.1]\nextra = 1\n", "hysteresis.extra");
  expect_error(head + "[hysteresis]\nthresholds_V = [10]\nweights = [-2]\n", "weights");
  expect_error(head, "hysteresis");
  expect_error("format = \"other\"\n", "format");
  expect_error("format = [\n", "line 1, column 12");
  EXPECT_THROW(read_hysteresis_model("/nonexistent/model.toml"), InputError);
}

}  // namespace
}  // namespace piezobench::io
