// A super element as the bench's actuator (src/bench/superelement_plant.hpp): the TOML checks, and
// the reduced plant of the APA95ML (shared data) against the full constrained structural model.
#include "superelement_plant.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/core/units.hpp"
#include "test_util.hpp"

namespace piezobench::bench::detail {
namespace {

using test::near;

const std::string kData = std::string(PIEZOBENCH_SHARED_DATA_DIR) + "/apa95ml-ansys/";

std::string write_toml(const test::TempDir& dir, const std::string& extra, bool with_files = true) {
  const auto path = dir.path() / "se.toml";
  std::ofstream out(path);
  if (with_files) {
    out << "k_file = \"" << kData << "piezo_amplified_K.txt\"\n"
        << "m_file = \"" << kData << "piezo_amplified_M.txt\"\n"
        << "nodes_file = \"" << kData << "piezo_amplified.txt\"\n";
  }
  out << extra;
  return path.string();
}

const std::string kNodes = "fix = [76429]\nactuator = \"76430:76433:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:y\"\n";

Electrics electrics() {
  Electrics e;
  e.amplifier_bandwidth = 2 * kPi * 5000.0;
  e.hpf_resistance = 80.6e3;
  e.capacitance_sensor = 4.95e-6;
  e.capacitance_actuator = 9.87e-6;
  e.ground_resistance = 0.0;
  e.adc_bandwidth = 2 * kPi * 1000.0;
  return e;
}

TEST(SuperElementBench, ReadsTheKeysAndResolvesRelativePaths) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const test::TempDir dir;
  std::ofstream(dir.path() / "K.txt") << "x";
  std::ofstream(dir.path() / "M.txt") << "x";
  std::ofstream(dir.path() / "dofs.txt") << "x";
  const std::string file = write_toml(dir,
                                      "k_file = \"K.txt\"\nm_file = \"M.txt\"\nnodes_file = \"dofs.txt\"\nformat = \"ansys\"\n" +
                                          kNodes + "ga = 12.5\ngs = 3e5\nmodal_damping = 0.02\nmax_mode_Hz = 9000\nguided = false\n",
                                      false);
  const SuperElementBench s = read_superelement_spec(file);
  EXPECT_EQ(s.setup.k_file, dir.path() / "K.txt");
  EXPECT_EQ(s.setup.source, file);
  EXPECT_EQ(s.setup.model.fixed_nodes, std::vector<long>{76429});
  EXPECT_EQ(s.actuator().node_a, 76430);
  EXPECT_EQ(s.actuator().node_b, 76433);
  EXPECT_EQ(s.sensor().node_b, 76440);
  EXPECT_EQ(s.output().node_b, 76423);
  EXPECT_EQ(s.output().direction, fem::Direction::kY);
  EXPECT_EQ(s.ga, 12.5);
  EXPECT_EQ(s.gs, 3e5);
  EXPECT_EQ(s.modal_damping, 0.02);
  EXPECT_EQ(s.max_mode_Hz, 9000.0);
  EXPECT_FALSE(s.guided);
}

TEST(SuperElementBench, RefusesBadDescriptionsNamingTheKey) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const test::TempDir dir;
  const auto refused = [&](const std::string& text, const std::string& field, bool with_files = true) {
    const std::string file = write_toml(dir, text, with_files);
    const std::string message = test::input_error([&] { (void)read_superelement_spec(file); }, field);
    EXPECT_TRUE(test::contains(message, file)) << message;
  };
  refused("fix = [76429]\n", "k_file", false);                                      // missing required key
  refused(kNodes + "colour = \"blue\"\n", "colour");                                // unknown key
  refused(kNodes + "ga = \"twenty\"\n", "ga");                                      // wrong type
  refused(kNodes + "modal_damping = 1.5\n", "modal_damping");                       // out of range
  refused("fix = []\nactuator = \"76430:76433:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:y\"\n", "fix");
  refused("fix = [76429]\nactuator = \"76430:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:y\"\n", "actuator");
  refused("fix = [76429]\nactuator = \"76430:76433:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:76429:y\"\n", "output");
  refused("fix = [76429]\nactuator = \"76430:76433:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:ry\"\n", "output");
  refused("fix = [76423]\nactuator = \"76430:76433:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:y\"\n", "fix");
  refused("k_file = \"missing.txt\"\nm_file = \"m\"\nnodes_file = \"n\"\n" + kNodes, "k_file", false);
  const std::string broken = write_toml(dir, "fix = [76429\n");
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)read_superelement_spec(broken); }), "valid TOML"));
  // A node the element does not have: found when the element is read.
  const std::string unknown = write_toml(dir, "fix = [76429]\nactuator = \"76430:99999:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:y\"\n");
  const std::string message = test::input_error([&] { (void)load_superelement(unknown); });
  EXPECT_TRUE(test::contains(message, "99999")) << message;
}

// The reduced plant (modes below max_mode_Hz + static correction, modal damping) against the full
// constrained model with the same modal damping (fem::frequency_response on every DOF).
TEST(SuperElementPlant, MatchesTheFullStructuralModel) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const test::TempDir dir;
  const SuperElementMechanics mech = load_superelement(write_toml(dir, kNodes + "ga = 20.0\ngs = 0.2e6\n"));
  SuperElementPlantInfo info;
  const ContinuousPlant plant = superelement_plant(mech, 5.7, 1.0, electrics(), &info);
  EXPECT_GT(info.kept_modes, 3);
  EXPECT_LT(info.kept_modes, info.total_modes);
  EXPECT_GT(info.first_mode_Hz, 100.0);  // the axial mode of 5.7 kg on the APA95ML
  EXPECT_LT(info.first_mode_Hz, 500.0);

  fem::StructuralModel full = bench_structure(mech, 5.7);
  // Modal damping of 1 % on every mode: C = M Phi diag(2 zeta w) Phi^T M.
  const fem::Modes modes = fem::modes(full);
  const Eigen::MatrixXd mphi = full.M * modes.shapes;
  const Eigen::VectorXd two_zeta_w = 2.0 * 0.01 * 2 * kPi * modes.frequencies_Hz;
  full.C = mphi * two_zeta_w.asDiagonal() * mphi.transpose();
  const Eigen::VectorXd hz = lti::logspace(0, 3.3, 60);
  const std::vector<Eigen::MatrixXcd> h = fem::frequency_response(full, 2 * kPi * hz).H;
  // Plant: from the extra actuator force (N) to d_e, and from the force on the mass to d_e.
  const lti::StateSpace force(plant.A, plant.B.rightCols(2), plant.C.row(kOutDe), plant.D.block(kOutDe, 1, 1, 2));
  const lti::FrequencyResponse r = lti::freqresp(force, 2 * kPi * hz);
  for (Eigen::Index k = 0; k < hz.size(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    EXPECT_TRUE(near<std::complex<double>>(r.H[kk](0, 0), h[kk](0, 0), {2e-3, 0.0})) << hz(k) << " Hz";
    EXPECT_TRUE(near<std::complex<double>>(r.H[kk](0, 1), h[kk](0, 1), {2e-3, 0.0})) << hz(k) << " Hz";
  }
  // At DC the static correction makes it exact: d_e per newton of the actuator pair.
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(full.K);
  const Eigen::MatrixXd statics = full.T * ldlt.solve(full.F);
  const lti::Matrix dc = lti::dc_gain(force);
  EXPECT_TRUE(near(dc(0, 0), statics(0, 0), 1e-9));
  EXPECT_TRUE(near(dc(0, 1), statics(0, 1), 1e-9));
}

TEST(SuperElementPlant, VoltageDrivesTheActuatorPairThroughGaAndTheAmplifier) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const test::TempDir dir;
  const SuperElementMechanics mech = load_superelement(write_toml(dir, kNodes + "ga = 20.0\ngs = 0.2e6\n"));
  const ContinuousPlant plant = superelement_plant(mech, 5.7, 0.5, electrics());
  const lti::StateSpace sys(plant.A, plant.B, plant.C, plant.D);
  const lti::Matrix dc = lti::dc_gain(sys);
  // d_e per volt of amplifier command = 0.5 * 20 N/V times d_e per newton; Vs is high-passed: 0 at DC.
  EXPECT_TRUE(near(dc(kOutDe, kInVa), 0.5 * 20.0 * dc(kOutDe, kInForce), 1e-9));
  EXPECT_LT(dc(kOutDe, kInVa), 0.0);  // pushing the stack ends apart shortens the APA
  EXPECT_NEAR(dc(kOutVs, kInVa), 0.0, 1e-9);
  EXPECT_NEAR(dc(kOutVa, kInVa), 1.0, 1e-9);
}

TEST(SuperElementPlant, GuidedMassRemovesTheLateralModes) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const test::TempDir dir;
  const SuperElementMechanics guided = load_superelement(write_toml(dir, kNodes));
  const fem::Modes g = fem::modes(bench_structure(guided, 5.7));
  const SuperElementMechanics free = load_superelement(write_toml(dir, kNodes + "guided = false\n"));
  const fem::Modes f = fem::modes(bench_structure(free, 5.7));
  // Unguided, the 5.7 kg sways on the actuator at about 60 Hz; on the air bearing only the axial
  // mode is left low.
  EXPECT_LT(f.frequencies_Hz(0), 100.0);
  EXPECT_GT(g.frequencies_Hz(0), 100.0);
  EXPECT_EQ(g.frequencies_Hz.size(), f.frequencies_Hz.size() - 5);
}

}  // namespace
}  // namespace piezobench::bench::detail
