#include "piezobench/campaign/demo.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/campaign/pipeline.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "test_util.hpp"

namespace piezobench::campaign {
namespace {

using nlohmann::json;
using test::near;

// The demo campaign on two units of the batch (1 good, 3 defective), short records: every
// figure the issue names against the virtual bench's truth, within the stated tolerances
// (docs/campaign.md, "Agreement with the virtual bench").
TEST(Demo, ResultsAgreeWithTheBenchTruth) {
  test::TempDir dir;
  DemoOptions o;
  o.fast = true;
  o.units = {1, 3};
  const DemoFiles files = write_demo_campaign(dir.path(), o);
  EXPECT_TRUE(std::filesystem::exists(files.campaign));
  // 11 records per unit (the stiffness test twice: stacks short-circuited and open), 4 IFF gains,
  // u -> Vs without the resistor and the tracking record on unit 1.
  EXPECT_EQ(files.data.size(), 2u * 11u + 6u);
  const json truth = json::parse(test::read_text(files.truth));
  const CampaignResult r = run_campaign(read_campaign(files.campaign));
  const json results = results_json(r);
  ASSERT_EQ(results["units"].size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const json& u = results["units"][i];
    const json& t = truth["units"][i];
    ASSERT_EQ(u["id"], t["id"]);
    SCOPED_TRACE("unit " + std::to_string(u["id"].get<int>()));
    EXPECT_TRUE(u["failed"].empty()) << u["failed"].dump();
    EXPECT_EQ(u["accepted"].get<bool>(), u["id"] != 3);
    const json& f = u["frf"];
    EXPECT_TRUE(near(f["resonance_Hz"].get<double>(), t["resonance_Hz"].get<double>(), 0.01));
    EXPECT_TRUE(near(f["antiresonance_Hz"].get<double>(), t["antiresonance_Hz"].get<double>(), 0.01));
    EXPECT_TRUE(near(f["static_gain_um_per_V"].get<double>(), t["static_gain_um_per_V"].get<double>(), 0.05));
    // The Hann window over 0.5 Hz bins (8 s records) widens the 1.2 Hz wide peak by ~16 %.
    EXPECT_TRUE(near(f["resonance_damping"].get<double>(), t["resonance_damping"].get<double>(), 0.25));
    // Issue 30: the vector fits' cross-checks carry standard errors. The DC gain lies within 3 of them
    // of the truth; the anti-resonance within 6 (the order-6 fit's bias at the narrow notch is 3-4
    // standard errors on the full demo, docs/uncertainty.md section 5), each known to a few per cent.
    {
      const double g = f["static_gain_vector_fit_um_per_V"].get<double>();
      const double g_se = f["static_gain_vector_fit_standard_error_um_per_V"].get<double>();
      EXPECT_GT(g_se, 0.0);
      EXPECT_LT(g_se, 0.05 * std::abs(g));
      EXPECT_LT(std::abs(g - t["dc_gain_um_per_V"].get<double>()), 3.0 * g_se) << g << " +- " << g_se;
      const double fz = f["antiresonance_vector_fit_Hz"].get<double>();
      const double fz_se = f["antiresonance_vector_fit_standard_error_Hz"].get<double>();
      EXPECT_GT(fz_se, 0.0);
      EXPECT_LT(fz_se, 0.05 * fz);
      EXPECT_LT(std::abs(fz - t["antiresonance_Hz"].get<double>()), 6.0 * fz_se) << fz << " +- " << fz_se;
      EXPECT_GT(f["antiresonance_vector_fit_damping_standard_error"].get<double>(), 0.0);
      // The resonance too (it was dropped when a spurious pole-zero pair sat within 2 % of it).
      ASSERT_FALSE(f["resonance_vector_fit_Hz"].is_null());
      EXPECT_TRUE(near(f["resonance_vector_fit_Hz"].get<double>(), t["resonance_Hz"].get<double>(), 0.01));
      EXPECT_GT(f["resonance_vector_fit_standard_error_Hz"].get<double>(), 0.0);
    }
    // Issue 30: the truth, or undetermined (null) when the 95 % interval of xz contains 0; never wrong.
    if (!f["zero_is_nonminimum_phase"].is_null()) {
      EXPECT_EQ(f["zero_is_nonminimum_phase"], t["zero_is_nonminimum_phase"]);
    }
    // Report section 2.2: k_oc about 2.3, k_sc about 1.7 N/um; the same readings as the truth's.
    for (const char* k : {"k1", "k2", "resonance", "k_sc", "k_oc"}) {
      EXPECT_TRUE(near(u["stiffness_N_per_um"][k].get<double>(), t["stiffness_N_per_um"][k].get<double>(), 0.05)) << k;
    }
    EXPECT_TRUE(near(u["hpf_corner_Hz"].get<double>(), t["hpf_corner_Hz"].get<double>(), 0.05));
    EXPECT_TRUE(near(u["stroke_um"].get<double>(), t["stroke_um"].get<double>(), 0.02));
    EXPECT_TRUE(near(u["capacitance_uF"]["sensor"].get<double>(), t["capacitance_uF"]["sensor"].get<double>(), 0.01));
    // Flatness: within twice the probe accuracy (+-0.5 um per point).
    EXPECT_NEAR(u["flatness_um"].get<double>(), t["flatness_um"].get<double>(), 1.0);
    // The tuned 2-DoF model: stiffnesses and gains (its damping split is not identifiable from
    // these FRFs, see docs/campaign.md).
    for (const auto& [k, tol] : {std::pair{"k1", 0.02}, {"ke", 0.02}, {"ka", 0.02}, {"ga", 0.03}, {"gs", 0.06}}) {
      EXPECT_TRUE(near(u["model_2dof"][k].get<double>(), t["model_2dof"][k].get<double>(), tol)) << k;
    }
  }
  // Unit 3 rejected for its capacitance and its stroke.
  std::string reasons;
  for (const auto& x : results["units"][1]["reasons"]) reasons += x.get<std::string>() + "\n";
  EXPECT_TRUE(test::contains(reasons, "capacitance")) << reasons;
  EXPECT_TRUE(test::contains(reasons, "stroke")) << reasons;
  // The IFF study of unit 1.
  const json& iff = results["iff"];
  EXPECT_EQ(iff["unit"], 1);
  EXPECT_EQ(iff["gains"].size(), 4u);
  EXPECT_GT(iff["optimal_gain"].get<double>(), 1e5);
  EXPECT_LT(iff["optimal_gain"].get<double>(), 1e6);
  // At every gain the identified damped pole sits on the model's root locus (report Figure 2.10b),
  // up to the optimum and beyond: within 5 %, so no warning.
  ASSERT_EQ(iff["relative_pole_distance"].size(), 4u);
  for (const auto& d : iff["relative_pole_distance"]) EXPECT_LT(d.get<double>(), 0.05);
  EXPECT_TRUE(iff["warning"].is_null());
  // k_oc > k_sc on every unit.
  for (const auto& u : results["units"]) {
    EXPECT_GT(u["stiffness_N_per_um"]["k_oc"].get<double>(), u["stiffness_N_per_um"]["k_sc"].get<double>());
  }
  // The resistor (report section 2.5, Figure 2.7) on unit 1: the corner with it near 1/(2 pi R C),
  // without it not observable in the record (the truth's 0.003 Hz is far below its lowest line).
  // The tracking record of unit 1 (issue 18's check on the bench's own PI law): the inverse of the
  // model the campaign identifies from the 80 V hysteresis record cuts the hysteresis width to
  // below 3 % of the stroke and the rms tracking error at least 5 times; unit 3 has none.
  const json& tr = results["units"][0]["tracking"];
  EXPECT_EQ(tr["feedforward"], "given");
  EXPECT_EQ(tr["amplitude_V"].get<double>(), 80.0);
  for (const char* w : {"sine", "triangle"}) {
    EXPECT_GT(tr[w]["width_open"].get<double>(), 0.15) << w;
    EXPECT_LT(tr[w]["width_ff"].get<double>(), 0.03) << w;
    EXPECT_GE(tr[w]["rms_reduction"].get<double>(), 5.0) << w;
  }
  EXPECT_TRUE(results["units"][1]["tracking"].is_null());  // every declared field is written: null when not run
  EXPECT_EQ(results["units"][1]["not_measured"].back(), "tracking");
  const json& hr = results["units"][0]["hpf_resistor"];
  EXPECT_TRUE(near(hr["with_resistor"]["corner_Hz"].get<double>(), truth["units"][0]["hpf_corner_with_resistor_Hz"].get<double>(), 0.1));
  EXPECT_FALSE(hr["without_resistor"]["observable"].get<bool>());
  EXPECT_TRUE(hr["without_resistor"]["corner_Hz"].is_null());
  EXPECT_LT(truth["units"][0]["hpf_corner_without_resistor_Hz"].get<double>(), hr["without_resistor"]["below_Hz"].get<double>());
}

TEST(Demo, BadOptions) {
  test::TempDir dir;
  DemoOptions o;
  o.units = {8};
  test::input_error([&] { (void)write_demo_campaign(dir.path(), o); }, "units");
  o = {};
  o.hysteresis_amplitudes = {90.0};
  test::input_error([&] { (void)write_demo_campaign(dir.path(), o); }, "hysteresis_amplitudes");
  o = {};
  o.units = {2};
  test::input_error([&] { (void)write_demo_campaign(dir.path(), o); }, "iff_unit");
  o.iff_unit = 2;
  test::input_error([&] { (void)write_demo_campaign(dir.path(), o); }, "tracking_unit");
}

}  // namespace
}  // namespace piezobench::campaign
