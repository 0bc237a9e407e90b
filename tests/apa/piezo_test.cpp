// Sensitivities from piezo constants (eq. 4.1) against Table 4.1 and REFERENCE.md.
#include "piezobench/apa/piezo.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::apa {
namespace {

using test::kRoundoff;
using test::near;

TEST(Piezo, Table41) {
  const PiezoSensitivities s = piezo_sensitivities(PiezoConstants{});
  // Exact arithmetic of eq. 4.1 with Table 4.1's numbers:
  //   ka = 48e9 * 1e-4 / 0.02 = 2.4e8 N/m
  //   ga = 680e-12 * 160 * 2.4e8 = 26.112 N/V
  //   gs = 680e-12 / (4e-8 * 21e-12 * 160) = 680 / 0.1344 * 1e3 = 5.0595238095...e6 V/m
  EXPECT_TRUE(near(s.ka, 2.4e8, kRoundoff));
  EXPECT_TRUE(near(s.ga, 26.112, kRoundoff));
  EXPECT_TRUE(near(s.gs, 680.0 / 0.1344 * 1e3, kRoundoff));
  // REFERENCE.md (derived): ga = 26.11 N/V, gs = 5.06 V/um, within 0.2 %.
  EXPECT_TRUE(near(s.ga, 26.11, 0.002));
  EXPECT_TRUE(near(s.gs, 5.06e6, 0.002));
}

TEST(Piezo, ScalesAsTheFormulas) {
  PiezoConstants c;
  c.layers = 80;     // half the layers: ga halves, gs doubles
  c.length = 40e-3;  // twice the length: ka halves
  const PiezoSensitivities s = piezo_sensitivities(c);
  EXPECT_TRUE(near(s.ka, 1.2e8, kRoundoff));
  EXPECT_TRUE(near(s.ga, 26.112 / 4.0, kRoundoff));
  EXPECT_TRUE(near(s.gs, 2.0 * 680.0 / 0.1344 * 1e3, kRoundoff));
}

TEST(Piezo, ValidationNamesTheField) {
  const struct {
    const char* field;
    void (*apply)(PiezoConstants&);
  } bad[] = {
      {"d33", [](PiezoConstants& c) { c.d33 = 0.0; }},
      {"eps_t", [](PiezoConstants& c) { c.eps_t = -1.0; }},
      {"s_d", [](PiezoConstants& c) { c.s_d = NAN; }},
      {"c_e", [](PiezoConstants& c) { c.c_e = INFINITY; }},
      {"length", [](PiezoConstants& c) { c.length = 0.0; }},
      {"area", [](PiezoConstants& c) { c.area = -1e-4; }},
      {"layers", [](PiezoConstants& c) { c.layers = 0.0; }},
      {"layers", [](PiezoConstants& c) { c.layers = 160.5; }},
      {"layers", [](PiezoConstants& c) { c.layers = 0.5; }},
  };
  for (const auto& b : bad) {
    PiezoConstants c;
    b.apply(c);
    try {
      (void)piezo_sensitivities(c);
      ADD_FAILURE() << b.field << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), b.field);
    }
  }
  PiezoConstants one;
  one.layers = 1;
  EXPECT_NO_THROW((void)piezo_sensitivities(one));
}

}  // namespace
}  // namespace piezobench::apa
