// Adding one field to a result (issue 32): the struct and its declaration line are the only edits,
// and the field shows up in results.json, part.json, the report's table and docs/fields.md. A
// test-only result struct goes through the same generic code the campaign's results go through
// (io::results_object, part.json's codec, the report's table, the field reference's table), so a
// field that needed another edit anywhere would fail here. Python's classes come from the same
// declaration (python/src/described.hpp, def_fields) and every declared field is an attribute there
// (python/tests/test_campaign.py, test_every_declared_result_member_is_reachable_from_python).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "piezobench/campaign/field_table.hpp"
#include "part_codec.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/io/fields_json.hpp"
#include "report_table.hpp"

namespace piezobench::campaign::test_only {

// A nested result, as a unit's analyses hold their fits.
struct ProbeFit {
  double gain = 0.0;                    // m/V
  std::optional<double> corner_Hz;      // Hz; nullopt: not fitted
};

constexpr auto describe(core::Type<ProbeFit>) {
  using S = ProbeFit;
  using namespace core::shown;
  return core::fields<S>("TestOnlyProbeFit", "a test-only fit",
      core::field("gain", &S::gain, kMetrePerVoltAsUmPerV, "static gain").in_report(),
      core::field("corner_Hz", &S::corner_Hz, kHertz, "corner of the fit"));
}

struct ProbeAnalysis {
  int id = 0;
  ProbeFit fit;
  double added_stiffness = 0.0;  // N/m: THE ADDED FIELD (one member here, one declaration line below)
};

constexpr auto describe(core::Type<ProbeAnalysis>) {
  using S = ProbeAnalysis;
  using namespace core::shown;
  return core::fields<S>("TestOnlyProbeAnalysis", "a test-only analysis",
      core::field("id", &S::id, kNone, "unit id"),
      core::field("fit", &S::fit, kNone, "its fit"),
      core::field("added_stiffness", &S::added_stiffness, kNewtonPerMetreAsNPerUm, "the field a test adds").in_report());
}

}  // namespace piezobench::campaign::test_only

namespace piezobench::campaign {
namespace {

using nlohmann::json;
using test_only::ProbeAnalysis;

ProbeAnalysis probe() {
  ProbeAnalysis p;
  p.id = 7;
  p.fit.gain = -2.5e-6;  // -2.5 um/V
  p.fit.corner_Hz = 0.33;
  p.added_stiffness = 1.75e6;  // 1.75 N/um
  return p;
}

TEST(AddedField, InResultsJsonUnderItsKeyInTheShownUnit) {
  const json r = io::results_object(probe());
  ASSERT_TRUE(r.contains("added_stiffness_N_per_um")) << r.dump();
  EXPECT_DOUBLE_EQ(r["added_stiffness_N_per_um"].get<double>(), 1.75);
  EXPECT_DOUBLE_EQ(r["fit"]["gain_um_per_V"].get<double>(), -2.5);
  EXPECT_DOUBLE_EQ(r["fit"]["corner_Hz"].get<double>(), 0.33);
}

TEST(AddedField, InPartJsonInSiAndReadBack) {
  const json j = part_codec::encode(probe());
  ASSERT_TRUE(j.contains("added_stiffness")) << j.dump();
  EXPECT_DOUBLE_EQ(j["added_stiffness"].get<double>(), 1.75e6);
  EXPECT_DOUBLE_EQ(j["fit"]["gain"].get<double>(), -2.5e-6);

  ProbeAnalysis back;
  part_codec::decode(j, back, part_codec::Where{"part.json", "units[0]"});
  EXPECT_EQ(back.id, 7);
  EXPECT_DOUBLE_EQ(back.added_stiffness, 1.75e6);
  EXPECT_DOUBLE_EQ(back.fit.gain, -2.5e-6);
  ASSERT_TRUE(back.fit.corner_Hz.has_value());
  EXPECT_DOUBLE_EQ(*back.fit.corner_Hz, 0.33);
}

TEST(AddedField, PartJsonWithoutItIsRefusedNamingTheField) {
  json j = part_codec::encode(probe());
  j.erase("added_stiffness");
  ProbeAnalysis back;
  try {
    part_codec::decode(j, back, part_codec::Where{"part.json", "units[0]"});
    FAIL() << "a part.json without the field was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("units[0].added_stiffness"), std::string::npos) << e.what();
  }
}

TEST(AddedField, NonFiniteWrittenOneWayEverywhere) {
  ProbeAnalysis p = probe();
  p.added_stiffness = std::numeric_limits<double>::quiet_NaN();
  p.fit.corner_Hz.reset();
  EXPECT_EQ(io::results_object(p)["added_stiffness_N_per_um"], "nan");
  EXPECT_TRUE(io::results_object(p)["fit"]["corner_Hz"].is_null());
  const json j = part_codec::encode(p);
  EXPECT_EQ(j["added_stiffness"], "nan");
  ProbeAnalysis back;
  part_codec::decode(j, back, part_codec::Where{"part.json", ""});
  EXPECT_TRUE(std::isnan(back.added_stiffness));
  EXPECT_FALSE(back.fit.corner_Hz.has_value());
  json row = json::array();
  report_cells(row, p);
  EXPECT_EQ(row.back(), "nan");
}

TEST(AddedField, InTheReportTableHeadedByNameAndUnit) {
  std::vector<std::string> columns;
  report_columns<ProbeAnalysis>(columns);
  report_columns<test_only::ProbeFit>(columns);
  EXPECT_EQ(columns, (std::vector<std::string>{"added stiffness [N/um]", "gain [um/V]"}));
  json row = json::array();
  report_cells(row, probe());
  report_cells(row, probe().fit);
  ASSERT_EQ(row.size(), 2U);
  EXPECT_DOUBLE_EQ(row[0].get<double>(), 1.75);
  EXPECT_DOUBLE_EQ(row[1].get<double>(), -2.5);
}

TEST(AddedField, InTheFieldReferenceWithItsUnitsKeyAndMeaning) {
  std::string doc;
  std::set<std::string> done;
  field_table<ProbeAnalysis>(doc, done);
  EXPECT_NE(doc.find("\n## TestOnlyProbeAnalysis\n"), std::string::npos) << doc;
  EXPECT_NE(doc.find("| `added_stiffness` |  | N/m | N/um (SI x 1e-06) | `added_stiffness_N_per_um` | the field a test adds (report table) |"),
            std::string::npos)
      << doc;
  // The nested struct gets its own table, once.
  EXPECT_NE(doc.find("| `fit` | TestOnlyProbeFit |"), std::string::npos) << doc;
  EXPECT_NE(doc.find("\n## TestOnlyProbeFit\n"), std::string::npos) << doc;
  EXPECT_EQ(done, (std::set<std::string>{"TestOnlyProbeAnalysis", "TestOnlyProbeFit"}));
}

}  // namespace
}  // namespace piezobench::campaign
