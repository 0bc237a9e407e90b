#include "piezobench/campaign/results_json.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "test_util.hpp"

namespace piezobench::campaign {
namespace {

using nlohmann::json;

// The serializer turns SI fields into the units its keys name, and absent analyses into null.
TEST(ResultsJson, UnitsOfTheKeysAndNullsForAbsentAnalyses) {
  UnitAnalysis u;
  u.id = 4;
  u.name = "APA 4";
  u.stroke_analysis = StrokeAnalysis{};
  u.stroke_analysis->result.stroke = 250e-6;
  u.stroke_analysis->result.sensitivity = -1.5e-6;
  u.stroke_analysis->provenance = {"stroke.mat", "units[0].stroke", {{"Va", "V_stack"}, {"de", "d_enc"}}, 100, 1e3, "", {}};
  u.stiffness_analysis = StiffnessAnalysis{};  // the unit's stiffness_N_per_um and stroke_um are read from the analyses
  u.stiffness_analysis->result.k1 = 1.7e6;
  u.stiffness_analysis->result.k2 = 1.9e6;
  u.capacitance_analysis = CapacitanceAnalysis{5.1e-6, 10e-6, std::nullopt, "units[0].capacitance_uF"};
  u.accepted = false;
  u.reasons = {"stroke too small"};
  const json j = unit_json(u);
  EXPECT_EQ(j["id"], 4);
  EXPECT_DOUBLE_EQ(j["stroke_um"].get<double>(), 250.0);
  EXPECT_DOUBLE_EQ(j["stroke"]["sensitivity_um_per_V"].get<double>(), -1.5);
  EXPECT_EQ(j["stroke"]["provenance"]["channels"]["de"], "d_enc");
  EXPECT_EQ(j["stroke"]["provenance"]["input"], "");  // every declared field is written; only FRF records have an input
  EXPECT_DOUBLE_EQ(j["stiffness_N_per_um"]["k1"].get<double>(), 1.7);
  EXPECT_DOUBLE_EQ(j["stiffness_N_per_um"]["k2"].get<double>(), 1.9);
  EXPECT_TRUE(j["stiffness_N_per_um"]["resonance"].is_null());
  EXPECT_DOUBLE_EQ(j["capacitance_uF"]["sensor"].get<double>(), 5.1);
  EXPECT_EQ(j["capacitance_provenance"], json({{"key", "units[0].capacitance_uF"}}));
  for (const char* k : {"flatness_um", "frf", "hpf_corner_Hz", "model_2dof"}) EXPECT_TRUE(j[k].is_null()) << k;
  EXPECT_FALSE(j["accepted"].get<bool>());
  EXPECT_EQ(j["reasons"][0], "stroke too small");
}

// Frequencies in Hz from rad/s, non-finite numbers as strings, the IFF study without a plant.
TEST(ResultsJson, BatchAndIffStudy) {
  CampaignResult r;
  r.campaign.title = "t";
  r.units.resize(2);
  r.accepted = 1;
  r.rejected = 1;
  r.batch.similarity = FrfSimilarity{1.0, 100.0, {{1, 0.5, std::nan("")}}, 0.5};
  r.iff.controller.w_hpf = 2.0 * M_PI * 3.0;
  r.iff.note = "no plant";
  const json j = results_json(r);
  EXPECT_EQ(j["summary"], json({{"units", 2}, {"accepted", 1}, {"marginal", 0}, {"rejected", 1}, {"not_analysed", 0}}));
  EXPECT_EQ(j["batch"]["similarity"]["units"][0]["Vs_rms_dB"], "nan");
  EXPECT_NEAR(j["iff"]["controller"]["hpf_Hz"].get<double>(), 3.0, 1e-12);
  EXPECT_TRUE(j["iff"]["unit"].is_null());
  EXPECT_EQ(j["iff"]["note"], "no plant");
  EXPECT_TRUE(j["superelement"].is_null());
  // A failed study keeps the keys a reader looks for.
  r.iff.failed = "root locus failed";
  const json f = results_json(r)["iff"];
  EXPECT_TRUE(f["optimal_gain"].is_null());
  EXPECT_EQ(f["failed"], "root locus failed");
}

}  // namespace
}  // namespace piezobench::campaign
