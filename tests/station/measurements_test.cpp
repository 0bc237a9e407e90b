#include "piezobench/station/measurements.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace piezobench::station {
namespace {

TEST(Measurements, VerdictsWithTheMargin) {
  const MeasurementKind& stroke = *find_measurement("stroke_um");
  const Limit min200{200.0, std::nullopt};
  // U = 1 % of 200 um = 2 um: the limit inside value +- 2 um is marginal, on either side.
  EXPECT_EQ(judge(stroke, 203.0, min200, 0.01).verdict, Verdict::kPass);
  EXPECT_EQ(judge(stroke, 201.0, min200, 0.01).verdict, Verdict::kMarginal);
  EXPECT_EQ(judge(stroke, 199.0, min200, 0.01).verdict, Verdict::kMarginal);
  EXPECT_EQ(judge(stroke, 197.9, min200, 0.01).verdict, Verdict::kFail);
  EXPECT_EQ(judge(stroke, 158.3, min200, 0.0).reason, "stroke, max - min of d_e over the stack range 158.3 um below the minimum 200 um");
  EXPECT_EQ(judge(stroke, std::nullopt, min200, 0.01).verdict, Verdict::kFail);
  EXPECT_EQ(judge(stroke, 1.0, Limit{}, 0.01).verdict, Verdict::kPass);  // no limit: recorded only
  const MeasurementKind& cs = *find_measurement("capacitance_sensor_uF");
  const MeasuredValue m = judge(cs, 6.05, Limit{4.0, 6.0}, 0.01);
  EXPECT_EQ(m.verdict, Verdict::kMarginal);
  EXPECT_TRUE(test::contains(m.reason, "within the margin of the maximum 6 uF (margin +-0.06 uF)")) << m.reason;
  EXPECT_EQ(judge(cs, 1.73, Limit{4.0, 6.0}, 0.01).verdict, Verdict::kFail);
}

TEST(Measurements, WorstOfAndNames) {
  EXPECT_EQ(worst(Verdict::kPass, Verdict::kMarginal), Verdict::kMarginal);
  EXPECT_EQ(worst(Verdict::kFail, Verdict::kMarginal), Verdict::kFail);
  EXPECT_EQ(verdict_from_string("marginal"), Verdict::kMarginal);
  EXPECT_THROW(verdict_from_string("ok"), InputError);
  EXPECT_EQ(find_measurement("k3_N_per_um"), nullptr);
}

TEST(Measurements, ValuesComeFromTheUnitAnalysisInTheirUnits) {
  campaign::UnitAnalysis u;
  u.stroke_analysis = campaign::StrokeAnalysis{};
  u.stroke_analysis->result.stroke = 250e-6;
  u.capacitance_analysis = campaign::CapacitanceAnalysis{4.95e-6, 10e-6, std::nullopt, ""};
  u.stiffness_analysis = campaign::StiffnessAnalysis{};
  u.stiffness_analysis->result.k1 = 1.7e6;
  u.frf_analysis = campaign::FrfAnalysis{};
  u.frf_analysis->resonance_Hz = 95.0;
  campaign::HysteresisLoop a, b;
  a.provenance.file = "/d/h4.mat";
  a.result.relative_width = 0.05;
  b.provenance.file = "/d/h80.mat";
  b.result.relative_width = 0.12;
  b.result.width = 30e-6;
  u.hysteresis = {a, b};
  EXPECT_DOUBLE_EQ(*measured_value(u, "stroke_um", ""), 250.0);
  EXPECT_DOUBLE_EQ(*measured_value(u, "capacitance_sensor_uF", ""), 4.95);
  EXPECT_DOUBLE_EQ(*measured_value(u, "k1_N_per_um", ""), 1.7);
  EXPECT_DOUBLE_EQ(*measured_value(u, "resonance_Hz", ""), 95.0);
  EXPECT_DOUBLE_EQ(*measured_value(u, "hysteresis_relative_width", "/d/h80.mat"), 0.12);
  EXPECT_DOUBLE_EQ(*measured_value(u, "hysteresis_width_um", "/d/h80.mat"), 30.0);
  EXPECT_FALSE(measured_value(u, "k_oc_N_per_um", "").has_value());
  EXPECT_FALSE(measured_value(u, "hysteresis_relative_width", "/d/other.mat").has_value());
}

}  // namespace
}  // namespace piezobench::station
