#include "piezobench/station/record_json.hpp"

#include <gtest/gtest.h>

namespace piezobench::station {
namespace {

TEST(RecordJson, AQualificationWithItsTriesMeasurementsAndFiles) {
  QualificationRow q;
  q.id = 7, q.serial = "SN1", q.batch = "B1", q.status = "complete", q.verdict = "marginal";
  q.deciding_phase = "stroke", q.deciding_measurement = "stroke_um";
  PhaseTryRow t;
  t.phase_name = "stroke", t.try_number = 2, t.status = "complete", t.verdict = "marginal";
  t.measurements.push_back({"stroke_um", "um", 199.0, 200.0, std::nullopt, "marginal", "", true});
  t.measurements.push_back({"sensitivity_um_per_V", "um/V", std::nullopt, std::nullopt, std::nullopt, "fail", "no value", false});
  t.raw_files.push_back({"/data/SN1/q7-stroke-try2.mat", "stroke", "ab12", 4096});
  const nlohmann::json j = qualification_json(q, {t});
  EXPECT_EQ(j["id"], 7);
  EXPECT_EQ(j["verdict"], "marginal");
  EXPECT_EQ(j["deciding_measurement"], "stroke_um");
  const auto& m = j["phase_tries"][0]["measurements"];
  EXPECT_DOUBLE_EQ(m[0]["value"].get<double>(), 199.0);
  EXPECT_DOUBLE_EQ(m[0]["min"].get<double>(), 200.0);
  EXPECT_TRUE(m[0]["max"].is_null());
  EXPECT_TRUE(m[0]["stop_on_fail"].get<bool>());
  EXPECT_TRUE(m[1]["value"].is_null());
  EXPECT_EQ(m[1]["reason"], "no value");
  EXPECT_EQ(j["phase_tries"][0]["try"], 2);
  EXPECT_EQ(j["phase_tries"][0]["raw_files"][0]["bytes"], 4096);
  EXPECT_TRUE(qualification_json(q, {})["phase_tries"].empty());
}

TEST(RecordJson, ControlChartsKeepLimitsStatisticsAndPoints) {
  ControlChart c;
  c.quantity = "stroke_um", c.unit = "um", c.min = 200.0, c.mean = 250.0, c.sigma = 14.1, c.marginal = 1;
  c.points.push_back({"SN1", "B1", 240.0, 200.0, std::nullopt, "pass"});
  const nlohmann::json j = control_charts_json({c});
  ASSERT_EQ(j.size(), 1u);
  EXPECT_DOUBLE_EQ(j[0]["min"].get<double>(), 200.0);
  EXPECT_TRUE(j[0]["max"].is_null());
  EXPECT_DOUBLE_EQ(j[0]["sigma"].get<double>(), 14.1);
  EXPECT_EQ(j[0]["marginal"], 1);
  EXPECT_EQ(j[0]["points"][0]["serial"], "SN1");
  EXPECT_DOUBLE_EQ(j[0]["points"][0]["value"].get<double>(), 240.0);
}

}  // namespace
}  // namespace piezobench::station
