#include "piezobench/core/fields.hpp"
#include "piezobench/core/field_types.hpp"

#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

namespace piezobench::core {
namespace {

struct Probe {
  double gap = 0.0;                    // m
  std::optional<double> stiffness;     // N/m
  std::vector<double> frequencies_Hz;  // Hz
  std::string label;
};

constexpr auto describe(Type<Probe>) {
  using S = Probe;
  return fields<S>("Probe", "a test struct",
                   field("gap", &S::gap, shown::kMetreAsUm, "gap to the target"),
                   field("stiffness", &S::stiffness, shown::kNewtonPerMetreAsNPerUm, "spring").key("springs.main").in_report(),
                   field("frequencies_Hz", &S::frequencies_Hz, shown::kHertz, "lines"),
                   field("label", &S::label, shown::kNone, "name").part_only());
}

TEST(Fields, DeclarationIsACompileTimeTableVisitedInOrder) {
  static_assert(Described<Probe>);
  static_assert(!Described<double>);
  static_assert(field_count<Probe>() == 4);
  static_assert(kFields<Probe>.name == "Probe");
  Probe p{2.5e-6, 3e6, {1.0, 2.0}, "x"};
  std::vector<std::string> names;
  double gap = 0.0;
  for_each_field<Probe>([&](const auto& f) {
    names.emplace_back(f.name);
    if constexpr (std::is_same_v<typename std::remove_cvref_t<decltype(f)>::Member, double>) gap = f.of(p) * f.shown.per_si;
  });
  EXPECT_EQ(names, (std::vector<std::string>{"gap", "stiffness", "frequencies_Hz", "label"}));
  EXPECT_DOUBLE_EQ(gap, 2.5);  // um: the one factor of kMetreAsUm
}

TEST(Fields, ResultsKeysNameTheShownUnitOnce) {
  EXPECT_EQ(unit_key_suffix("um/V"), "um_per_V");
  EXPECT_EQ(unit_key_suffix("m/s^2"), "m_per_s2");
  EXPECT_EQ(unit_key_suffix("N s/m"), "N_s_per_m");
  EXPECT_EQ(results_key("gap", shown::kMetreAsUm), "gap_um");
  EXPECT_EQ(results_key("resonance_Hz", shown::kHertz), "resonance_Hz");   // not resonance_Hz_Hz
  EXPECT_EQ(results_key("damping", shown::kRatio), "damping");
  EXPECT_EQ(results_key("k1", shown::kNewtonPerMetreAsNPerUm), "k1_N_per_um");
  EXPECT_EQ(results_key("k1", shown::kNewtonPerMetreAsNPerUm, "stiffness.k1"), "stiffness.k1");
  EXPECT_EQ(unit_heading(shown::kMetrePerVoltAsUmPerV), "[um/V]");
  EXPECT_EQ(unit_heading(shown::kRatio), "");
  EXPECT_EQ(report_heading("static_gain", shown::kMetrePerVoltAsUmPerV), "static gain [um/V]");
  EXPECT_EQ(report_heading("resonance_Hz", shown::kHertz), "resonance [Hz]");
  EXPECT_EQ(report_heading("resonance_damping", shown::kRatio), "resonance damping");
}

TEST(Fields, WhereAFieldAppears) {
  const auto& f = std::get<1>(kFields<Probe>.fields);
  EXPECT_TRUE(f.in(kResults));
  EXPECT_TRUE(f.in(kReport));
  const auto& label = std::get<3>(kFields<Probe>.fields);
  EXPECT_FALSE(label.in(kResults));
  EXPECT_DOUBLE_EQ(shown::kRadPerSecondAsHz.per_si * 2.0 * 3.141592653589793, 1.0);
}

// A struct that shows a number one of its parts holds: a derived field, read by its getter.
struct Holder {
  Probe probe;
};
constexpr std::optional<double> gap_of(const Holder& h) { return h.probe.gap; }
constexpr const Probe* probe_of(const Holder& h) { return &h.probe; }

constexpr auto describe(Type<Holder>) {
  using S = Holder;
  return fields<S>("Holder", "holds a probe",
                   field("probe", &S::probe, shown::kNone, "the part").part_only(),
                   derived("gap", &gap_of, shown::kMetreAsUm, "the probe's gap").in_report(),
                   derived("probe_again", &probe_of, shown::kNone, "a pointer into the holder").part_only());
}

TEST(Fields, ADerivedFieldIsReadByItsGetterAndFoundByIt) {
  const Holder h{{2.5e-6, std::nullopt, {}, ""}};
  const auto& gap = std::get<1>(kFields<Holder>.fields);
  static_assert(std::remove_cvref_t<decltype(gap)>::kDerived && !std::remove_cvref_t<decltype(std::get<0>(kFields<Holder>.fields))>::kDerived);
  EXPECT_DOUBLE_EQ(*gap.of(h), 2.5e-6);
  EXPECT_TRUE(gap.in(kReport) && gap.in(kResults));
  EXPECT_EQ(std::get<2>(kFields<Holder>.fields).of(h), &h.probe);
  static_assert(std::is_same_v<element_t<const Probe*>, Probe>);
  const Declared d = declared<Holder>(&gap_of);
  EXPECT_EQ(d.name, "gap");
  EXPECT_DOUBLE_EQ(d.shown.per_si, 1e6);
  EXPECT_EQ(declared<Holder>(&Holder::probe).name, "probe");
  EXPECT_EQ(declared<Probe>(&Probe::stiffness).meaning, "spring");
  EXPECT_TRUE(declared<Probe>(&Probe::label).name == "label");
}

TEST(FieldTypes, TheKindsADocumentTellsApart) {
  static_assert(kIsOptional<std::optional<double>> && !kIsOptional<double>);
  static_assert(kIsVector<std::vector<int>> && !kIsVector<std::array<int, 2>>);
  static_assert(kIsStdArray<std::array<int, 2>> && !kIsStdArray<std::vector<int>>);
  static_assert(kIsPair<std::pair<int, double>> && kIsComplex<std::complex<double>>);
  static_assert(kIsEigen<Eigen::VectorXd> && kIsEigen<Eigen::MatrixXd> && !kIsEigen<std::vector<double>>);
  static_assert(kIsPairList<std::vector<std::pair<std::string, std::string>>> && kIsVector<std::vector<std::pair<std::string, std::string>>>);
  static_assert(!kIsPairList<std::vector<double>>);
  SUCCEED();
}

}  // namespace
}  // namespace piezobench::core
