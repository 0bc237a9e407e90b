// The report's batch of seven APA300ML (batch_unit): Table 1.1, 1.2 and 3.1 values with spread,
// unit 3 defective, reproducible from the seed.
#include <gtest/gtest.h>

#include <array>

#include "flatness.hpp"
#include "piezobench/bench/virtual_bench.hpp"
#include "test_util.hpp"

namespace piezobench::bench {
namespace {

using test::near;

constexpr std::array<double, 7> kFlatnessUm = {8.9, 3.1, 9.1, 3.0, 1.9, 7.1, 18.7};
constexpr std::array<double, 7> kSensorUf = {5.10, 4.99, 1.72, 4.94, 4.90, 4.99, 4.85};
constexpr std::array<double, 7> kActuatorUf = {10.03, 9.85, 5.18, 9.82, 9.66, 9.91, 9.85};

double flatness_um(const UnitTruth& u) {
  const Eigen::Matrix<double, 8, 3> p = detail::probe_layout();
  return detail::plane_flatness(p.col(0), p.col(1), detail::probe_heights(u)) * 1e6;
}

TEST(BatchUnit, AroundTheReportsTables) {
  for (const std::uint64_t seed : {1ULL, 2ULL, 12345ULL}) {
    for (int id = 1; id <= 7; ++id) {
      const UnitTruth u = batch_unit(id, seed);
      const auto k = static_cast<std::size_t>(id - 1);
      EXPECT_EQ(u.id, id);
      u.validate();
      // Capacitance (Table 1.2) within 1 %, flatness (Table 1.1) within 10 %.
      EXPECT_TRUE(near(u.capacitance_sensor * 1e6, kSensorUf[k], 0.01)) << id;
      EXPECT_TRUE(near(u.capacitance_actuator * 1e6, kActuatorUf[k], 0.01)) << id;
      EXPECT_TRUE(near(flatness_um(u), kFlatnessUm[k], 0.1)) << id;
      // Stiffness around Table 3.1 (k_tot 2.05 N/um) within about 2 % (3 % at 2.5 sigma).
      EXPECT_TRUE(near(u.model.total_stiffness(), 2.0467e6, 0.03)) << id;
      EXPECT_TRUE(near(u.model.ke / u.model.ka, 2.0, 1e-12));  // one sensor stack against two in series
      EXPECT_EQ(u.defective, id == 3);
      if (id == 3) {
        EXPECT_NEAR(u.stroke_factor, 0.6, 0.03);
        EXPECT_TRUE(near(u.model.ga, -2.58 * u.stroke_factor, 0.03));
        EXPECT_FALSE(u.defect.empty());
      } else {
        EXPECT_NEAR(u.stroke_factor, 1.0, 0.03);
        EXPECT_TRUE(u.defect.empty());
      }
      EXPECT_NEAR(u.mode_y_Hz, 280.0, 280.0 * 0.03);
      EXPECT_NEAR(u.mode_x_Hz, 412.0, 412.0 * 0.03);
    }
  }
}

TEST(BatchUnit, SameSeedSameUnitsOtherSeedOtherSpread) {
  const UnitTruth a = batch_unit(5, 77), b = batch_unit(5, 77), c = batch_unit(5, 78);
  EXPECT_EQ(a.model.k1, b.model.k1);
  EXPECT_EQ(a.capacitance_sensor, b.capacitance_sensor);
  EXPECT_EQ(a.flatness_tilt, b.flatness_tilt);
  EXPECT_NE(a.model.k1, c.model.k1);
  EXPECT_NE(a.flatness_tilt_direction, c.flatness_tilt_direction);
  // Units of one batch differ from each other.
  EXPECT_NE(batch_unit(1, 77).model.k1, batch_unit(2, 77).model.k1);
}

TEST(BatchUnit, RefusesUnitsOutsideTheBatch) {
  for (const int id : {0, 8, -3}) {
    const std::string message = test::input_error([&] { (void)batch_unit(id, 1); }, "unit");
    EXPECT_TRUE(test::contains(message, "1 to 7")) << message;
  }
}

}  // namespace
}  // namespace piezobench::bench
