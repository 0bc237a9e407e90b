#include "piezobench/campaign/part.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "piezobench/campaign/demo.hpp"
#include "piezobench/campaign/pipeline.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "test_util.hpp"

namespace piezobench::campaign {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The demo campaign on three units, short records (about 2 s of analysis per run on 2 threads).
struct DemoRun {
  test::TempDir dir;
  DemoFiles files;
  Campaign campaign;
  CampaignResult full;
  DemoRun() {
    DemoOptions o;
    o.fast = true;
    o.units = {1, 2, 3};
    o.threads = 2;
    files = write_demo_campaign(dir.path(), o);
    campaign = read_campaign(files.campaign);
    PipelineOptions po;
    po.threads = 2;
    full = run_campaign(campaign, po);
  }
};

const DemoRun& demo() {
  static const DemoRun d;
  return d;
}

// write -> read -> write gives the same document, and the unit read back serializes to the same
// results.json entry (every number exactly, curves and FRFs included).
TEST(Part, TypedUnitsRoundTripExactly) {
  for (const UnitAnalysis& u : demo().full.units) {
    const json once = typed_unit_json(u);
    const UnitAnalysis back = typed_unit_from_json(json::parse(once.dump()), "test");
    EXPECT_EQ(typed_unit_json(back).dump(), once.dump()) << u.name;
    EXPECT_EQ(unit_json(back).dump(), unit_json(u).dump()) << u.name;
    ASSERT_EQ(frf_of(back) != nullptr, frf_of(u) != nullptr);
    if (frf_of(u)) {
      EXPECT_TRUE(frf_of(back)->H[1] == frf_of(u)->H[1]);  // bit for bit
    }
  }
  // Non-finite numbers, empty optionals and vectors survive.
  UnitAnalysis u;
  u.id = 9;
  u.stiffness_analysis = StiffnessAnalysis{};
  u.stiffness_analysis->result.k1 = std::numeric_limits<double>::infinity();
  u.stiffness_analysis->result.k2 = std::nan("");
  u.stroke_analysis = StrokeAnalysis{};
  u.stroke_analysis->result.sensitivity = -std::numeric_limits<double>::infinity();
  const UnitAnalysis back = typed_unit_from_json(json::parse(typed_unit_json(u).dump()), "test");
  EXPECT_TRUE(std::isinf(*k1_of(back)) && *k1_of(back) > 0);
  EXPECT_TRUE(std::isnan(back.stiffness_analysis->result.k2));
  EXPECT_TRUE(std::isinf(back.stroke_analysis->result.sensitivity) && back.stroke_analysis->result.sensitivity < 0);
  EXPECT_FALSE(back.frf_analysis.has_value());
  EXPECT_FALSE(static_gain_of(back).has_value());
}

// run == merge(part 1/2, part 2/2): results.json, results.mat and report.html byte for byte.
TEST(Part, MergeOfTwoPartsEqualsTheSingleRun) {
  const DemoRun& d = demo();
  test::TempDir out;
  PipelineOptions po;
  po.threads = 2;
  std::vector<CampaignPart> parts;
  for (int k = 1; k <= 2; ++k) {
    const auto indices = part_indices(d.campaign, k, 2);
    const fs::path dir = out.path() / ("part-" + std::to_string(k));
    (void)write_part(d.campaign, analyze_units(d.campaign, indices, po), dir);
    parts.push_back(read_part(dir));
  }
  ASSERT_EQ(parts[0].units.size(), 2u);  // units 1 and 3
  ASSERT_EQ(parts[1].units.size(), 1u);  // unit 2
  EXPECT_EQ(parts[0].units[1].id, 3);
  // Given in reverse order: the merge puts the units back in the campaign's order.
  const CampaignResult merged = finish_campaign(d.campaign, merge_parts(d.campaign, {parts[1], parts[0]}), po);
  EXPECT_EQ(results_json(merged).dump(), results_json(d.full).dump());
  write_outputs(d.full, out.path() / "run");
  write_outputs(merged, out.path() / "merge");
  for (const std::string name : {"results.json", "results.mat", "report.html"}) {
    // The MAT-file's 116-byte text header holds its creation time.
    const std::size_t from = name == "results.mat" ? 116 : 0;
    EXPECT_TRUE(test::read_text(out.path() / "run" / name).substr(from) == test::read_text(out.path() / "merge" / name).substr(from)) << name;
  }
}

TEST(Part, PartsAreBalancedAndUnitsSelectedById) {
  Campaign c;
  for (int id : {4, 5, 6, 7, 8}) {
    UnitSpec s;
    s.id = id;
    c.units.push_back(s);
  }
  EXPECT_EQ(part_indices(c, 1, 2), (std::vector<std::size_t>{0, 2, 4}));
  EXPECT_EQ(part_indices(c, 2, 2), (std::vector<std::size_t>{1, 3}));
  EXPECT_TRUE(part_indices(c, 7, 7).empty());
  test::input_error([&] { (void)part_indices(c, 3, 2); }, "--part");
  test::input_error([&] { (void)part_indices(c, 0, 2); }, "--part");
  EXPECT_EQ(unit_indices(c, {8, 5}), (std::vector<std::size_t>{1, 4}));
  test::expect_input_error([&] { (void)unit_indices(c, {3}); }, {"--units", "4, 5, 6, 7, 8", "found 3"});
}

// A missing, duplicated or foreign part, and documents that are not parts, are refused naming them.
TEST(Part, BadPartsAreRefusedNamingThem) {
  const DemoRun& d = demo();
  test::TempDir out;
  // Parts made of the full run's units (the analysis itself is the same function, tested above).
  const auto part_of = [&](std::vector<int> ids, const std::string& name) {
    std::vector<UnitAnalysis> units;
    for (const auto& u : d.full.units) {
      if (std::find(ids.begin(), ids.end(), u.id) != ids.end()) units.push_back(u);
    }
    return read_part(write_part(d.campaign, units, out.path() / name));
  };
  const CampaignPart a = part_of({1, 3}, "a");
  const CampaignPart b = part_of({2}, "b");
  const CampaignPart ab = part_of({2, 3}, "ab");
  EXPECT_EQ(merge_parts(d.campaign, {a, b}).size(), 3u);
  test::expect_input_error([&] { (void)merge_parts(d.campaign, {a}); }, {"units", "unit 2 in none of them", d.files.campaign.string()});
  test::expect_input_error([&] { (void)merge_parts(d.campaign, {a, ab}); },
                           {(out.path() / "ab" / "part.json").string(), "units[1].id", "unit 3", "also in", (out.path() / "a" / "part.json").string()});
  // A part of another campaign (or of this file before it changed).
  CampaignPart foreign = b;
  foreign.campaign_hash = "fnv1a64:0123456789abcdef";
  test::expect_input_error([&] { (void)merge_parts(d.campaign, {a, foreign}); }, {"b/part.json", "campaign_hash", "0123456789abcdef", "another campaign"});
  CampaignPart stranger = b;
  stranger.units[0].id = 42;
  test::expect_input_error([&] { (void)merge_parts(d.campaign, {a, stranger}); }, {"units[0].id", "found 42"});

  // Documents that are not parts, or not of this version.
  test::expect_input_error([&] { (void)read_part(out.path()); }, {"no part.json in it"});
  test::expect_input_error([&] { (void)read_part(out.path() / "nothing"); }, {"no such file"});
  const json doc = json::parse(test::read_text(out.path() / "b" / "part.json"));
  const auto refused = [&](json changed, const std::vector<std::string>& needles) {
    test::write_text(out.path() / "bad.json", changed.dump());
    test::expect_input_error([&] { (void)read_part(out.path() / "bad.json"); }, needles);
  };
  json j = doc;
  j["format_version"] = 2;  // before the FRF moved into frf_analysis (issue 32)
  refused(j, {"bad.json", "format_version", "expected 3", "found 2"});
  j = doc;
  j["generator"] = "piezobench 0.0.1";
  refused(j, {"generator", "piezobench 0.0.1"});
  j = {{"title", "a results.json"}, {"units", json::array()}};
  refused(j, {"format", "piezobench campaign part", "no format key"});
  j = doc;
  j["units"][0]["frf_analysis"]["welch"]["nfft"] = "many";
  refused(j, {"units[0].frf_analysis.welch.nfft", "an integer", "\"many\""});
  j = doc;
  j["units"][0]["stiffness_analysis"]["result"].erase("k1");
  refused(j, {"units[0].stiffness_analysis.result.k1", "missing"});
  j = doc;
  j["units"][0]["k1"] = "not read";  // a derived field (UnitAnalysis::k1 is its stiffness analysis'): the key is ignored
  EXPECT_EQ(k1_of(typed_unit_from_json(j["units"][0], "test")), k1_of(typed_unit_from_json(doc["units"][0], "test")));
  EXPECT_TRUE(k1_of(typed_unit_from_json(doc["units"][0], "test")).has_value());
  j = doc;
  j["units"][0]["model_2dof"]["tuning"]["status"] = "happy";
  refused(j, {"units[0].model_2dof.tuning.status", "tuning status name", "happy"});
  test::write_text(out.path() / "bad.json", "{\"format\": ");
  test::expect_input_error([&] { (void)read_part(out.path() / "bad.json"); }, {"bad.json", "JSON"});
}

}  // namespace
}  // namespace piezobench::campaign
