#include "piezobench/metrology/capacitance.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "test_util.hpp"

namespace piezobench::metrology {
namespace {

using test::near;

// Report Table 1.2 (uF): sensor stack and actuator stacks of APA 1..7.
const std::vector<double> kSensor = {5.10, 4.99, 1.72, 4.94, 4.90, 4.99, 4.85};
const std::vector<double> kActuator = {10.03, 9.85, 5.18, 9.82, 9.66, 9.91, 9.85};

TEST(Capacitance, SpecificationRange) {
  const CapacitanceSpec spec;  // sensor 4..6 uF, actuator 8..12 uF
  const CapacitanceCheck good = check_capacitance(5.10e-6, 10.03e-6, spec);
  EXPECT_TRUE(good.ok());
  EXPECT_TRUE(good.reasons.empty());
  const CapacitanceCheck apa3 = check_capacitance(1.72e-6, 5.18e-6, spec);
  EXPECT_FALSE(apa3.sensor_in_spec);
  EXPECT_FALSE(apa3.actuator_in_spec);
  ASSERT_EQ(apa3.reasons.size(), 2u);
  EXPECT_TRUE(test::contains(apa3.reasons[0], "capacitance of the sensor stack 1.72 uF")) << apa3.reasons[0];
  EXPECT_TRUE(test::contains(apa3.reasons[1], "actuator stacks 5.18 uF")) << apa3.reasons[1];
  // Ends of the range are inside.
  EXPECT_TRUE(check_capacitance(4.0e-6, 12.0e-6, spec).ok());
}

// The report's batch: APA 3 is the only outlier, on both readings. Median and MAD by hand:
// sensor sorted 1.72 4.85 4.90 4.94 4.99 4.99 5.10 -> median 4.94, |dev| sorted 0 .04 .05 .05 .09
// .16 3.22 -> MAD .05, z(APA 3) = 0.6745 (1.72 - 4.94) / 0.05 = -43.4378, z(APA 1) = 2.1584.
TEST(Capacitance, ReportBatchFlagsApa3) {
  const OutlierAnalysis s = robust_outliers(kSensor);
  EXPECT_TRUE(near(s.median, 4.94, 1e-12));
  EXPECT_TRUE(near(s.mad, 0.05, 1e-9));
  EXPECT_TRUE(near(s.robust_z[2], 0.6745 * (1.72 - 4.94) / 0.05, 1e-9));
  EXPECT_TRUE(near(s.robust_z[0], 0.6745 * 0.16 / 0.05, 1e-9));
  const OutlierAnalysis a = robust_outliers(kActuator);
  for (std::size_t i = 0; i < kSensor.size(); ++i) {
    EXPECT_EQ(s.outlier[i], i == 2) << "sensor, APA " << i + 1;
    EXPECT_EQ(a.outlier[i], i == 2) << "actuator, APA " << i + 1;
  }
}

TEST(Capacitance, OutlierFloorsAndSmallBatches) {
  // Identical values but one 1 % off: MAD = 0 gives an infinite z, but 1 % < 5 % is no outlier.
  const OutlierAnalysis a = robust_outliers({5.0, 5.0, 5.0, 5.05});
  EXPECT_TRUE(std::isinf(a.robust_z[3]));
  EXPECT_FALSE(a.outlier[3]);
  const OutlierAnalysis b = robust_outliers({5.0, 5.0, 5.0, 6.0});
  EXPECT_TRUE(b.outlier[3]);
  // Two values: no verdict.
  const OutlierAnalysis c = robust_outliers({1.0, 100.0});
  EXPECT_FALSE(c.outlier[0] || c.outlier[1]);
}

TEST(Capacitance, BadInput) {
  test::input_error([] { (void)check_capacitance(std::nan(""), 1e-5, {}); }, "sensor");
  test::input_error([] { (void)check_capacitance(5e-6, -1e-5, {}); }, "actuator");
  CapacitanceSpec spec;
  spec.sensor = {6e-6, 4e-6};
  test::input_error([&] { (void)check_capacitance(5e-6, 1e-5, spec); }, "sensor");
  EXPECT_TRUE(test::contains(test::input_error([] { (void)robust_outliers({1.0, std::nan(""), 2.0}, {}, "batch", "C_sensor"); }, "C_sensor"), "index 1"));
  OutlierOptions o;
  o.threshold = 0.0;
  test::input_error([&] { (void)robust_outliers({1.0, 2.0, 3.0}, o); }, "threshold");
}

}  // namespace
}  // namespace piezobench::metrology
