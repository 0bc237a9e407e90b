#include "piezobench/io/fields_json.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <optional>
#include <vector>

namespace piezobench::io {
namespace {

struct Reading {
  double value = 0.0;  // m
  double spread = 0.0;
};
struct Record {
  std::optional<double> stiffness;  // N/m
  double before = 0.0, after = 0.0;  // m
  Reading reading;
  std::vector<std::pair<std::string, std::string>> channels;
  std::vector<double> curve;         // m
};

constexpr auto describe(core::Type<Reading>) {
  using S = Reading;
  return core::fields<S>("Reading", "a reading", core::field("value", &S::value, core::shown::kMetreAsUm, "the value"),
                         core::field("spread", &S::spread, core::shown::kRatio, "relative"));
}
constexpr auto describe(core::Type<Record>) {
  using S = Record;
  using namespace core::shown;
  return core::fields<S>("Record", "a record", core::field("stiffness", &S::stiffness, kNewtonPerMetreAsNPerUm, "k"),
                         core::field("before", &S::before, kMetreAsUm, "before").key("readings_um.before"),
                         core::field("after", &S::after, kMetreAsUm, "after").key("readings_um.after"),
                         core::field("reading", &S::reading, kNone, "merged").key("."),
                         core::field("channels", &S::channels, kNone, "role -> name"),
                         core::field("curve", &S::curve, kMetre, "a curve").part_only());
}

TEST(FieldsJson, ResultsObjectConvertsOnceNestsAndMerges) {
  Record r{2.5e6, 1e-6, -2e-6, {3e-6, 0.25}, {{"de", "ch1"}}, {1.0}};
  const auto j = results_object(r);
  EXPECT_DOUBLE_EQ(j["stiffness_N_per_um"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(j["readings_um"]["before"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["readings_um"]["after"].get<double>(), -2.0);
  EXPECT_DOUBLE_EQ(j["value_um"].get<double>(), 3.0);  // the nested struct merged into its parent
  EXPECT_DOUBLE_EQ(j["spread"].get<double>(), 0.25);
  EXPECT_EQ(j["channels"]["de"], "ch1");
  EXPECT_FALSE(j.contains("curve"));
  EXPECT_FALSE(j.contains("reading"));
}

TEST(FieldsJson, OneEncodingOfNonFiniteAndAbsentValues) {
  Record r;
  r.before = std::numeric_limits<double>::quiet_NaN();
  r.after = -std::numeric_limits<double>::infinity();
  const auto j = results_object(r);
  EXPECT_TRUE(j["stiffness_N_per_um"].is_null());
  EXPECT_EQ(j["readings_um"]["before"], "nan");
  EXPECT_EQ(j["readings_um"]["after"], "-inf");
  EXPECT_EQ(shown_json(std::optional<double>(std::numeric_limits<double>::infinity())), "inf");
}

TEST(FieldsJson, NameNonFiniteRewritesAWholeDocument) {
  nlohmann::json d = {{"a", std::numeric_limits<double>::quiet_NaN()},
                      {"b", {1.0, std::numeric_limits<double>::infinity(), "text"}},
                      {"c", {{"d", -std::numeric_limits<double>::infinity()}}}};
  name_non_finite(d);
  EXPECT_EQ(d["a"], "nan");
  EXPECT_EQ(d["b"][1], "inf");
  EXPECT_DOUBLE_EQ(d["b"][0].get<double>(), 1.0);
  EXPECT_EQ(d["c"]["d"], "-inf");
  EXPECT_EQ(d.dump().find("null"), std::string::npos);
}

}  // namespace
}  // namespace piezobench::io
