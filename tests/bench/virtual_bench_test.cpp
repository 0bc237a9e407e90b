// VirtualBench: allocation-free stepping, exactness against the linear model when the instruments
// are ideal, the instruments' limits (DAC, amplifier clamp, quantization, noise), the added mass,
// reproducibility and option checks.
#include "piezobench/bench/virtual_bench.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <vector>

#include "alloc_counter.hpp"
#include "plant.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/discretize.hpp"
#include "test_util.hpp"

namespace piezobench::bench {
namespace {

using test::near;

// Ideal instruments and no nonlinearity: what is left is the linear model.
BenchOptions ideal() {
  BenchOptions o;
  o.hysteresis = false;
  o.creep = false;
  o.noise = false;
  o.encoder_resolution = 0.0;
  o.adc_bits = 32;
  o.dac_bits = 32;
  return o;
}

// lti::c2d of the balanced realization, transformed back: accurate for every entry of a model whose
// states span many decades.
lti::StateSpace accurate_c2d(const lti::StateSpace& sys, double ts) {
  const lti::Index n = sys.states(), m = sys.inputs();
  lti::Matrix aug = lti::Matrix::Zero(n + m, n + m);
  aug.topLeftCorner(n, n) = sys.A;
  aug.topRightCorner(n, m) = sys.B;
  const lti::Vector d = detail::balancing_scales(aug).head(n);
  lti::StateSpace b(d.cwiseInverse().asDiagonal() * sys.A * d.asDiagonal(), d.cwiseInverse().asDiagonal() * sys.B,
                    sys.C * d.asDiagonal(), sys.D);
  return lti::c2d(b, ts);  // in the balanced coordinates: the outputs are the same
}

std::vector<double> test_command(int n) {
  std::vector<double> u(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) u[static_cast<std::size_t>(k)] = 0.3 * std::sin(0.011 * k) + 0.2 * std::sin(0.31 * k) + 0.1;
  return u;
}

std::string apa95ml_toml(const test::TempDir& dir) {
  const std::string data = std::string(PIEZOBENCH_SHARED_DATA_DIR) + "/apa95ml-ansys/";
  const auto path = dir.path() / "apa95ml.toml";
  std::ofstream(path) << "k_file = \"" << data << "piezo_amplified_K.txt\"\n"
                      << "m_file = \"" << data << "piezo_amplified_M.txt\"\n"
                      << "nodes_file = \"" << data << "piezo_amplified.txt\"\n"
                      << "fix = [76429]\nactuator = \"76430:76433:x\"\nsensor = \"76433:76440:x\"\noutput = \"76423:y\"\n"
                      << "ga = 20.0\ngs = 0.2e6\n";
  return path.string();
}

TEST(VirtualBench, StepAndRunAllocateNothing) {
  VirtualBench bench(batch_unit(1, 1), BenchOptions{}, 7);
  const std::vector<double> u = test_command(2000);
  std::vector<BenchSample> out(u.size());
  (void)bench.step(0.1);
  const test::AllocationCounter count;
  double sum = 0.0;
  for (const double v : u) sum += bench.step(v).de;
  bench.set_added_mass(6.4);  // precomputed: no allocation
  bench.set_load_fraction(0.5);
  for (const double v : u) sum += bench.step(v).vs;
  bench.set_added_mass(0.0);
  bench.run(u, out);
  EXPECT_EQ(count.allocations(), 0U);
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(VirtualBench, SuperElementBenchStepsWithoutAllocating) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const test::TempDir dir;
  BenchOptions o;
  o.superelement = apa95ml_toml(dir);
  VirtualBench bench(batch_unit(1, 1), o, 7);
  EXPECT_EQ(bench.model_name(), "superelement");
  const std::vector<double> u = test_command(500);
  std::vector<BenchSample> out(u.size());
  (void)bench.step(0.1);
  const test::AllocationCounter count;
  double sum = 0.0;
  for (const double v : u) sum += bench.step(v).de;
  bench.run(u, out);
  EXPECT_EQ(count.allocations(), 0U);
  EXPECT_TRUE(std::isfinite(sum));
}

// Whole-sample delay: the bench equals lti::c2d + lsim of its linear model, the input shifted by
// the delay line. The measurement of period k is taken at its end, with the feedthrough of the
// command held over it.
TEST(VirtualBench, EqualsItsLinearModelWithIdealInstruments) {
  BenchOptions o = ideal();
  o.delay = 2.5e-4;  // 2 samples of delay line + the hold's half sample
  VirtualBench bench(batch_unit(2, 5), o, 1);
  const lti::StateSpace model = bench.linear_model();
  EXPECT_DOUBLE_EQ(model.input_delay(0), 2.5e-4);
  lti::StateSpace plain = model;
  plain.input_delay.resize(0);
  const lti::StateSpace d = accurate_c2d(plain, 1e-4);
  const int n = 3000;
  const std::vector<double> u = test_command(n);
  lti::Matrix w = lti::Matrix::Zero(n, 1);
  for (int k = 2; k < n; ++k) w(k, 0) = u[static_cast<std::size_t>(k - 2)];
  const lti::TimeResponse r = lti::lsim(d, w);
  double max_de = 0.0, max_vs = 0.0;
  for (int k = 0; k + 1 < n; ++k) {
    const BenchSample m = bench.step(u[static_cast<std::size_t>(k)]);
    const lti::Vector y = d.C * r.x.row(k + 1).transpose() + d.D * w(k, 0);
    max_de = std::max(max_de, std::abs(y(0)));
    max_vs = std::max(max_vs, std::abs(y(1)));
    ASSERT_TRUE(near<double>(m.de, y(0), {1e-6, 1e-12})) << "sample " << k;  // d_e up to 10 um
    ASSERT_TRUE(near<double>(m.vs, y(1), {1e-6, 1e-8})) << "sample " << k;  // ADC: 32 bits over +-10 V
  }
  EXPECT_GT(max_de, 1e-6);  // the comparison saw a real response
  EXPECT_GT(max_vs, 0.05);
}

// The default 200 us: 1.5 samples of delay line. Against a plain ZOH simulation ten times finer
// with the input delayed by 15 fine samples (exact for a command held over each period).
TEST(VirtualBench, FractionalDelayIsExact) {
  VirtualBench bench(batch_unit(1, 1), ideal(), 1);
  EXPECT_DOUBLE_EQ(bench.effective_delay(), 200e-6);
  lti::StateSpace plain = bench.linear_model();
  plain.input_delay.resize(0);
  const lti::StateSpace fine = accurate_c2d(plain, 1e-5);
  const int n = 800;
  const std::vector<double> u = test_command(n);
  lti::Matrix w = lti::Matrix::Zero(10 * n, 1);
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < 10; ++i) {
      if (10 * k + i + 15 < 10 * n) w(10 * k + i + 15, 0) = u[static_cast<std::size_t>(k)];
    }
  }
  const lti::TimeResponse r = lti::lsim(fine, w);
  for (int k = 0; k + 1 < n; ++k) {
    const BenchSample m = bench.step(u[static_cast<std::size_t>(k)]);
    const lti::Index j = 10 * (k + 1);
    // Held over the period that just ended: the command of its second half.
    const lti::Vector y = fine.C * r.x.row(j).transpose() + fine.D * w(j - 1, 0);
    ASSERT_TRUE(near<double>(m.de, y(0), {1e-6, 1e-12})) << "sample " << k;  // d_e up to 10 um
    ASSERT_TRUE(near<double>(m.vs, y(1), {1e-6, 1e-8})) << "sample " << k;
  }
}

TEST(VirtualBench, RunEqualsStep) {
  VirtualBench a(batch_unit(4, 3), BenchOptions{}, 11), b(batch_unit(4, 3), BenchOptions{}, 11);
  const std::vector<double> u = test_command(5000);
  std::vector<BenchSample> out(u.size());
  a.run(u, out);
  for (std::size_t k = 0; k < u.size(); ++k) {
    const BenchSample m = b.step(u[k]);
    ASSERT_EQ(m.de, out[k].de) << k;
    ASSERT_EQ(m.vs, out[k].vs) << k;
    ASSERT_EQ(m.va, out[k].va) << k;
  }
  EXPECT_DOUBLE_EQ(a.time(), 5000 * 1e-4);
}

TEST(VirtualBench, DacHoldsNanAtZeroAndLimitsItsRange) {
  BenchOptions o = ideal();
  o.dac_bits = 16;
  VirtualBench zero(batch_unit(1, 1), o, 1), nan(batch_unit(1, 1), o, 1);
  VirtualBench ten(batch_unit(1, 1), o, 1), fifty(batch_unit(1, 1), o, 1);
  for (int k = 0; k < 200; ++k) {
    EXPECT_EQ(zero.step(0.0).de, nan.step(std::nan("")).de);
    EXPECT_EQ(ten.step(-10.0).va, fifty.step(-50.0).va);
  }
  // A 16-bit DAC over +-10 V: steps of 20/65536 V. 0.1 V is 327.68 codes -> 328 codes.
  VirtualBench q(batch_unit(1, 1), o, 1);
  BenchSample m;
  for (int k = 0; k < 100; ++k) m = q.step(0.1);
  EXPECT_TRUE(near(m.va, 20.0 * 328 * 20.0 / 65536.0, 1e-12));
}

TEST(VirtualBench, AmplifierOutputStaysInTheStackRange) {
  VirtualBench bench(batch_unit(1, 1), ideal(), 1);
  BenchSample m;
  double peak = 0.0;
  for (int k = 0; k < 100; ++k) peak = std::max(peak, (m = bench.step(9.0)).va);  // 180 V asked
  EXPECT_LE(peak, 150.0 + 1e-9);
  EXPECT_NEAR(m.va, 150.0, 1e-9);
  double low = 0.0;
  for (int k = 0; k < 100; ++k) low = std::min(low, (m = bench.step(-5.0)).va);  // -100 V asked
  EXPECT_GE(low, -20.0 - 1e-9);
  EXPECT_NEAR(m.va, -20.0, 1e-9);
}

TEST(VirtualBench, MeasurementNoiseAndQuantization) {
  const BenchOptions o;  // 1 nm rms + 2.5 nm steps; 1 mV rms + 16-bit ADC
  VirtualBench bench(batch_unit(1, 1), o, 3);
  const int n = 40000;
  double sde = 0.0, sde2 = 0.0, svs = 0.0, svs2 = 0.0;
  for (int k = 0; k < n; ++k) {
    const BenchSample m = bench.step(0.0);
    const double counts = m.de / 2.5e-9;
    ASSERT_NEAR(counts, std::round(counts), 1e-6);  // whole encoder counts
    const double codes = m.vs / (20.0 / 65536.0);
    ASSERT_NEAR(codes, std::round(codes), 1e-6);  // whole ADC codes
    sde += m.de, sde2 += m.de * m.de, svs += m.vs, svs2 += m.vs * m.vs;
  }
  const double std_de = std::sqrt(sde2 / n - std::pow(sde / n, 2));
  const double std_vs = std::sqrt(svs2 / n - std::pow(svs / n, 2));
  // Noise plus the quantization's uniform error: sqrt(sigma^2 + q^2 / 12).
  EXPECT_TRUE(near(std_de, std::sqrt(1e-18 + std::pow(2.5e-9, 2) / 12), 0.1));
  EXPECT_TRUE(near(std_vs, std::sqrt(1e-6 + std::pow(20.0 / 65536.0, 2) / 12), 0.1));
}

TEST(VirtualBench, SameSeedSameSamplesAndResetStartsOver) {
  VirtualBench a(batch_unit(1, 1), BenchOptions{}, 42), b(batch_unit(1, 1), BenchOptions{}, 42);
  VirtualBench c(batch_unit(1, 1), BenchOptions{}, 43);
  std::vector<double> first;
  bool differs = false;
  for (int k = 0; k < 1000; ++k) {
    const double u = 0.2 * std::sin(0.05 * k);
    const BenchSample ma = a.step(u), mb = b.step(u), mc = c.step(u);
    ASSERT_EQ(ma.de, mb.de);
    ASSERT_EQ(ma.vs, mb.vs);
    differs = differs || ma.vs != mc.vs;
    first.push_back(ma.vs);
  }
  EXPECT_TRUE(differs);
  a.reset(42);
  EXPECT_EQ(a.time(), 0.0);
  for (int k = 0; k < 1000; ++k) ASSERT_EQ(a.step(0.2 * std::sin(0.05 * k)).vs, first[static_cast<std::size_t>(k)]);
}

TEST(VirtualBench, AddedMassSinksTheMassByItsWeightOverTheStaticStiffness) {
  const UnitTruth unit = batch_unit(1, 1);
  BenchOptions o = ideal();
  VirtualBench bench(unit, o, 1);
  // Static stiffness with the sensor stack short-circuited through R (virtual_bench.hpp).
  const apa::TwoDofParams& p = unit.model;
  const double k_around = p.ke + p.ka * p.k1 / (p.ka + p.k1);
  const double cb = unit.capacitance_sensor * k_around / (k_around + p.gs * p.gs * unit.capacitance_sensor);
  const double ke_sc = p.ke - p.gs * p.gs * cb;
  const double k_static = p.k1 + ke_sc * p.ka / (ke_sc + p.ka);
  for (const double kg : {6.4, 3.0}) {
    bench.set_added_mass(kg);
    EXPECT_DOUBLE_EQ(bench.added_mass(), kg);
    BenchSample m;
    for (int k = 0; k < 60000; ++k) m = bench.step(0.0);  // 6 s: the mass rings down, R relaxes
    EXPECT_TRUE(near(m.de, -kg * 9.8 / k_static, 1e-3)) << kg << " kg";
  }
  bench.set_added_mass(-1.0);  // ignored
  EXPECT_DOUBLE_EQ(bench.added_mass(), 3.0);
  bench.set_added_mass(0.0);
  bench.set_load_fraction(0.5);  // nothing on it: no weight either way
  BenchSample m;
  for (int k = 0; k < 60000; ++k) m = bench.step(0.0);
  EXPECT_NEAR(m.de, 0.0, 1e-9);
}

TEST(VirtualBench, LinearModelAndDelays) {
  BenchOptions o;
  VirtualBench bench(batch_unit(1, 1), o, 1);
  const lti::StateSpace sys = bench.linear_model();
  EXPECT_EQ(sys.inputs(), 1);
  EXPECT_EQ(sys.outputs(), 2);
  EXPECT_EQ(bench.model_name(), "2dof");
  o.delay = 0.0;
  VirtualBench no_delay(batch_unit(1, 1), o, 1);
  EXPECT_DOUBLE_EQ(no_delay.effective_delay(), 0.5e-4);  // the DAC's hold remains
  EXPECT_DOUBLE_EQ(no_delay.linear_model().input_delay(0), 0.5e-4);
  // With the added mass on, the resonance moves down by sqrt(5.7 / 12.1).
  VirtualBench loaded(batch_unit(1, 1), BenchOptions{}, 1);
  loaded.set_added_mass(6.4);
  const auto resonance = [](const lti::StateSpace& s) {
    double best = 0.0, zeta = 1.0;
    for (const auto& pi : lti::damp(s)) {
      if (pi.pole.imag() > 0.0 && pi.damping < zeta) zeta = pi.damping, best = pi.natural_frequency;
    }
    return best;
  };
  EXPECT_TRUE(near(resonance(loaded.linear_model()) / resonance(sys), std::sqrt(5.7 / 12.1), 2e-3));
}

TEST(VirtualBench, HysteresisOpensALoop) {
  for (const bool hysteresis : {false, true}) {
    BenchOptions o = ideal();
    o.hysteresis = hysteresis;
    VirtualBench bench(batch_unit(1, 1), o, 1);
    // 2 Hz sine of 40 V about 65 V at the stacks; compare d_e going up and down through 65 V.
    double up = 0.0, down = 0.0;
    for (int k = 0; k < 20000; ++k) {
      const double phase = 2 * std::numbers::pi * 2.0 * k * 1e-4;
      const BenchSample m = bench.step((65.0 + 40.0 * std::sin(phase)) / 20.0);
      if (k >= 15000 && std::abs(m.va - 65.0) < 0.5) (std::cos(phase) > 0 ? up : down) = m.de;
    }
    if (hysteresis) {
      EXPECT_GT(std::abs(up - down), 4e-6);  // a loop several um wide
    } else {
      EXPECT_LT(std::abs(up - down), 1.5e-6);  // only the 2 Hz phase lag of the dynamics
    }
  }
}

TEST(VirtualBench, RefusesBadOptionsAndUnits) {
  const UnitTruth unit = batch_unit(1, 1);
  const auto bad = [&](auto change, const std::string& field) {
    BenchOptions o;
    change(o);
    (void)test::input_error([&] { VirtualBench b(unit, o, 1); }, field);
  };
  bad([](BenchOptions& o) { o.sample_rate = 0.0; }, "sample_rate");
  bad([](BenchOptions& o) { o.sample_rate = std::nan(""); }, "sample_rate");
  bad([](BenchOptions& o) { o.sample_rate = 1e12; }, "sample_rate");  // a 1 s delay line of 10^12 samples
  bad([](BenchOptions& o) { o.dac_bits = 1; }, "dac_bits");
  bad([](BenchOptions& o) { o.va_min = 5.0; }, "va_min");
  bad([](BenchOptions& o) { o.va_max = -30.0; }, "va_max");
  bad([](BenchOptions& o) { o.delay = -1e-4; }, "delay");
  bad([](BenchOptions& o) { o.suspended_mass = 0.0; }, "suspended_mass");
  bad([](BenchOptions& o) { o.hpf_resistance = 0.0; }, "hpf_resistance");
  bad([](BenchOptions& o) { o.superelement = ""; }, "superelement");
  bad([](BenchOptions& o) { o.adc_input_resistance = 0.0; }, "adc_input_resistance");
  bad([](BenchOptions& o) {
    o.superelement = "apa.toml";
    o.actuator_open_circuit = true;
  }, "actuator_open_circuit");
  UnitTruth u = unit;
  u.capacitance_sensor = -1.0;
  (void)test::input_error([&] { VirtualBench b(u, BenchOptions{}, 1); }, "capacitance_sensor");
  u = unit;
  u.model.k1 = std::nan("");
  (void)test::input_error([&] { VirtualBench b(u, BenchOptions{}, 1); });
  BenchOptions o;
  o.superelement = "/nonexistent/apa.toml";
  const std::string message = test::input_error([&] { VirtualBench b(unit, o, 1); });
  EXPECT_TRUE(test::contains(message, "/nonexistent/apa.toml"));
}

}  // namespace
}  // namespace piezobench::bench
