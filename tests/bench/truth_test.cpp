// truth_json: what a perfect campaign would find, against the 2-DoF model's closed forms and the
// report's numbers.
#include "piezobench/bench/truth.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "test_util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::bench {
namespace {

using test::near;

TEST(Truth, TwoDofUnitOnTheReportsBench) {
  const UnitTruth u = batch_unit(1, 1);
  const nlohmann::json t = truth_json(u, BenchOptions{});
  const apa::TwoDofParams& p = u.model;
  EXPECT_EQ(t["model"], "2dof");
  EXPECT_EQ(t["model_2dof"]["k1"].get<double>(), p.k1);
  EXPECT_EQ(t["model_2dof"]["m"].get<double>(), 5.7);
  EXPECT_DOUBLE_EQ(t["delay_s"].get<double>(), 200e-6);
  // Resonance near sqrt(k_tot / m) (report: 95 Hz), anti-resonance near sqrt(k1 / m) (41 Hz),
  // non-minimum phase with a small negative damping (report's fit: 0.4 %).
  EXPECT_TRUE(near(t["resonance_Hz"].get<double>(), std::sqrt(p.total_stiffness() / 5.7) / kTwoPi, 5e-3));
  EXPECT_TRUE(near(t["antiresonance_Hz"].get<double>(), std::sqrt(p.k1 / 5.7) / kTwoPi, 5e-3));
  EXPECT_LT(t["antiresonance_damping"].get<double>(), -0.002);
  EXPECT_GT(t["antiresonance_damping"].get<double>(), -0.006);
  EXPECT_TRUE(t["zero_is_nonminimum_phase"].get<bool>());
  // The report's -17 um/V: 20 ga ke / (ke + ka) / k_tot.
  EXPECT_TRUE(near(t["static_gain_um_per_V"].get<double>(), 20 * p.ga * p.ke / (p.ke + p.ka) / p.total_stiffness() * 1e6, 1e-12));
  EXPECT_NEAR(t["static_gain_um_per_V"].get<double>(), -17.0, 1.0);
  EXPECT_LT(t["static_gain_um_per_V"].get<double>(), t["dc_gain_um_per_V"].get<double>());  // softer... at DC the gain is smaller
  EXPECT_TRUE(near(t["hpf_corner_Hz"].get<double>(), 1.0 / (kTwoPi * 80.6e3 * u.capacitance_sensor), 1e-12));
  EXPECT_TRUE(near(t["capacitance_uF"]["sensor"].get<double>(), u.capacitance_sensor * 1e6, 1e-12));
  const auto& k = t["stiffness_N_per_um"];
  EXPECT_TRUE(near(k["k_tot"].get<double>(), p.total_stiffness() * 1e-6, 1e-12));
  EXPECT_TRUE(near(k["resonance"].get<double>(), k["k_tot"].get<double>(), 0.01));
  // Table 2.1: k1 1.68..1.73, k2 1.90..1.98; both below the resonance's 2.05.
  EXPECT_GT(k["k1"].get<double>(), 1.6);
  EXPECT_LT(k["k1"].get<double>(), 1.8);
  EXPECT_GT(k["k2"].get<double>(), 1.85);
  EXPECT_LT(k["k2"].get<double>(), k["static"].get<double>());
  EXPECT_LT(k["static"].get<double>(), k["k_tot"].get<double>());
  // Section 2.2: k_oc about 2.3 N/um (every stack open), k_sc about 1.7 (the stacks on the
  // amplifier and R: this bench's k1); without creep, open, k_oc is the static open-circuit value.
  EXPECT_EQ(k["k_sc"].get<double>(), k["k1"].get<double>());
  EXPECT_NEAR(k["k_oc"].get<double>(), 2.3, 0.08);
  EXPECT_GT(k["open_circuit"].get<double>(), k["k_oc"].get<double>());
  EXPECT_TRUE(near(k["k_oc"].get<double>(), k["open_circuit"].get<double>(), 0.06));
  // Without the resistor only the ADC's 10 MOhm discharges the sensor stack: a corner far below
  // the 0.05 Hz a record of tens of seconds resolves.
  EXPECT_TRUE(near(t["hpf_corner_without_resistor_Hz"].get<double>(), 1.0 / (kTwoPi * 10e6 * u.capacitance_sensor), 1e-12));
  EXPECT_LT(t["hpf_corner_without_resistor_Hz"].get<double>(), 0.005);
  EXPECT_GT(t["stroke_um"].get<double>(), 220.0);
  EXPECT_LT(t["stroke_um"].get<double>(), 290.0);
  EXPECT_TRUE(near(t["flatness_um"].get<double>(), 8.9, 0.1));  // Table 1.1, APA 1
  EXPECT_EQ(t["bending_modes_Hz"]["y"].get<double>(), u.mode_y_Hz);
  EXPECT_FALSE(t["defective"].get<bool>());
}

TEST(Truth, SwitchesChangeWhatAPerfectCampaignFinds) {
  const UnitTruth u = batch_unit(2, 1);
  BenchOptions o;
  o.nonminimum_phase_zero = false;
  o.creep = false;
  const nlohmann::json t = truth_json(u, o);
  EXPECT_FALSE(t["zero_is_nonminimum_phase"].get<bool>());
  // The shell's damping c1 / (2 sqrt(k1 m)).
  EXPECT_TRUE(near(t["antiresonance_damping"].get<double>(), u.model.c1 / (2 * std::sqrt(u.model.k1 * 5.7)), 0.05));
  // Without creep both readings are the static stiffness (the sensor stack short-circuited by R).
  const auto& k = t["stiffness_N_per_um"];
  EXPECT_TRUE(near(k["k1"].get<double>(), k["static"].get<double>(), 5e-3));
  EXPECT_TRUE(near(k["k2"].get<double>(), k["static"].get<double>(), 5e-3));
}

TEST(Truth, DefectiveUnitThree) {
  const nlohmann::json good = truth_json(batch_unit(1, 1), BenchOptions{});
  const nlohmann::json bad = truth_json(batch_unit(3, 1), BenchOptions{});
  EXPECT_TRUE(bad["defective"].get<bool>());
  EXPECT_LT(bad["stroke_um"].get<double>(), 0.7 * good["stroke_um"].get<double>());
  EXPECT_NEAR(bad["capacitance_uF"]["sensor"].get<double>(), 1.72, 0.02);
}

TEST(Truth, SuperElementBench) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const test::TempDir dir;
  const std::string data = std::string(PIEZOBENCH_SHARED_DATA_DIR) + "/apa95ml-ansys/";
  const auto toml = dir.path() / "apa95ml.toml";
  std::ofstream(toml) << "k_file = \"" << data << "piezo_amplified_K.txt\"\n"
                      << "m_file = \"" << data << "piezo_amplified_M.txt\"\n"
                      << "nodes_file = \"" << data << "piezo_amplified.txt\"\n"
                      << "fix = [76429]\nactuator = \"76430:76433:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:y\"\n"
                      << "ga = 20.0\ngs = 0.2e6\n";
  BenchOptions o;
  o.superelement = toml;
  const nlohmann::json t = truth_json(batch_unit(1, 1), o);
  EXPECT_EQ(t["model"], "superelement");
  EXPECT_TRUE(t["model_2dof"].is_null());
  EXPECT_GT(t["resonance_Hz"].get<double>(), 150.0);  // the 5.7 kg on the much stiffer APA95ML
  EXPECT_LT(t["resonance_Hz"].get<double>(), 500.0);
  EXPECT_LT(t["static_gain_um_per_V"].get<double>(), 0.0);
  EXPECT_GT(t["stroke_um"].get<double>(), 0.0);
}

}  // namespace
}  // namespace piezobench::bench
