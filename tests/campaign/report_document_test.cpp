#include "piezobench/campaign/report_document.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>

#include "piezobench/campaign/pipeline.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "piezobench/report/html_report.hpp"
#include "synthetic.hpp"
#include "test_util.hpp"

namespace piezobench::campaign {
namespace {

namespace syn = test::synthetic;
using nlohmann::json;

TEST(ReportDocument, FiguresFollowTheReportLayout) {
  test::TempDir dir;
  io::write_timeseries(syn::frf_record(8.0), dir.path() / "frf.mat");
  io::write_timeseries(syn::hysteresis_record(20.0, 0.1), dir.path() / "h.mat");
  io::write_timeseries(syn::stiffness_record(1.9e6), dir.path() / "s.mat");
  io::write_timeseries(syn::damped_record(2 * M_PI * 90.0, 0.2, 1e5, 4.0), dir.path() / "iff.mat");
  std::ofstream(dir.path() / "c.toml") << R"(
title = "report <test> & co"
[specs]
flatness_um = 25.0
[channels]
u = "u_dac"
[[units]]
id = 1
frf = { file = "frf.mat", channels = { de = "d_enc", Vs = "V_sensor" } }
hysteresis = "h.mat"
stiffness = "s.mat"
iff = "iff.mat"
capacitance_uF = { sensor = 5.0, actuator = 10.0 }
[[units]]
id = 2
name = "APA \"two\" </script>"
stiffness = "s.mat"
)";
  const Campaign c = read_campaign(dir.path() / "c.toml");
  const CampaignResult r = run_campaign(c);
  const json results = results_json(r);
  const json doc = report_document(r);
  EXPECT_EQ(doc["title"], "report <test> & co");
  EXPECT_EQ(doc["results"], results);
  std::set<std::string> sections, figures;
  for (const auto& s : doc["sections"]) {
    sections.insert(s["id"].get<std::string>());
    for (const auto& f : s["figures"]) {
      EXPECT_TRUE(figures.insert(f["id"].get<std::string>()).second) << f["id"];
      for (const auto& p : f["panels"]) {
        for (const auto& t : p["traces"]) EXPECT_EQ(t["x"].size(), t["y"].size()) << f["id"] << " " << t["name"];
      }
    }
  }
  for (const char* s : {"frf", "quasi-static", "stiffness", "iff", "batch"}) EXPECT_EQ(sections.count(s), 1u) << s;
  for (const char* f : {"frf-de", "frf-vs", "model-vs", "hysteresis-1", "stiffness", "root-locus", "damped-plants",
                        "batch-capacitance", "batch-stiffness"}) {
    EXPECT_EQ(figures.count(f), 1u) << f;
  }
  // Experiments no unit has: a line saying so, never an empty plot (issue 33).
  for (const char* f : {"batch-flatness", "batch-stroke", "hammer"}) EXPECT_EQ(figures.count(f), 0u) << f;
  std::string texts;
  for (const auto& s : doc["sections"]) {
    if (s.contains("text")) texts += s["text"].get<std::string>() + "\n";
    if (s["id"] == "modes") EXPECT_TRUE(s["figures"].empty());
  }
  EXPECT_TRUE(test::contains(texts, "Not measured on any analysed unit, so not drawn: flatness, stroke.")) << texts;
  EXPECT_TRUE(test::contains(texts, "Not measured in this campaign: no analysed unit has a hammer test record (hammer)")) << texts;
  // The batch's spread with display names and units, in the report's order (no results keys).
  const json* spread = nullptr;
  for (const auto& s : doc["sections"]) {
    if (s["id"] != "batch") continue;
    for (const auto& t : s["tables"]) {
      if (t["title"] == "Spread over the batch") spread = &t;
    }
  }
  ASSERT_NE(spread, nullptr);
  EXPECT_EQ((*spread)["columns"][0], "quantity");
  EXPECT_EQ((*spread)["rows"][0][0], "capacitance of the sensor stack [uF]");
  EXPECT_FALSE(test::contains((*spread).dump(), "_uF")) << (*spread).dump();
  // The vector fits' cross-checks with half their 95 % intervals (issue 30): results.json's values, and
  // 1.96 of its standard errors.
  const json* vf = nullptr;
  for (const auto& t : doc["sections"][0]["tables"]) {
    if (test::contains(t["title"].get<std::string>(), "Vector fits per unit")) vf = &t;
  }
  ASSERT_NE(vf, nullptr);
  ASSERT_EQ((*vf)["rows"].size(), 1u);  // unit 1 has the FRF
  const json& vrow = (*vf)["rows"][0];
  const json& ufrf = results["units"][0]["frf"];
  EXPECT_EQ((*vf)["columns"][5], "anti-resonance [Hz]");
  EXPECT_EQ((*vf)["columns"][6], "+- (95 %) [Hz]");
  ASSERT_TRUE(ufrf["antiresonance_vector_fit_Hz"].is_number()) << ufrf.dump();
  ASSERT_TRUE(ufrf["antiresonance_vector_fit_standard_error_Hz"].is_number()) << ufrf.dump();
  EXPECT_EQ(vrow[5], ufrf["antiresonance_vector_fit_Hz"]);
  EXPECT_DOUBLE_EQ(vrow[6].get<double>(), 1.959963984540054 * ufrf["antiresonance_vector_fit_standard_error_Hz"].get<double>());
  EXPECT_GT(vrow[6].get<double>(), 0.0);
  ASSERT_TRUE(ufrf["static_gain_vector_fit_standard_error_um_per_V"].is_number()) << ufrf.dump();
  EXPECT_NEAR(vrow[10].get<double>(), 1.959963984540054 * ufrf["static_gain_vector_fit_standard_error_um_per_V"].get<double>(),
              1e-12 * std::abs(vrow[10].get<double>()));
  // The frequency responses overlay the measurement's 95 % band (issue 30), the measurement (solid)
  // and the model (dashed) of unit 1.
  const json& frf_de = doc["sections"][0]["figures"][0];
  ASSERT_GE(frf_de["panels"][0]["traces"].size(), 3u);
  const json& band = frf_de["panels"][0]["traces"][0];
  EXPECT_EQ(band["mode"], "band");
  ASSERT_EQ(band["y_upper"].size(), band["y"].size());
  for (std::size_t k = 0; k < band["y"].size(); ++k) EXPECT_LE(band["y"][k].get<double>(), band["y_upper"][k].get<double>());
  EXPECT_FALSE(frf_de["panels"][0]["traces"][1]["dash"].get<bool>());
  EXPECT_TRUE(frf_de["panels"][0]["traces"][2]["dash"].get<bool>());
  EXPECT_EQ(frf_de["panels"].size(), 3u);  // magnitude, phase, coherence
  // The report module accepts the document, and names are escaped.
  const std::string html = report::render_html(doc);
  EXPECT_FALSE(test::contains(html, "APA \"two\" </script>"));
}

}  // namespace
}  // namespace piezobench::campaign
