#include "piezobench/report/html_report.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>

#include "piezobench/report/embedded_assets.hpp"
#include "report/sample_document.hpp"
#include "test_util.hpp"

namespace piezobench::report {
namespace {

using nlohmann::json;
namespace sample = test::report_sample;
using test::contains;

std::size_t count(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (auto at = text.find(part); at != std::string::npos; at = text.find(part, at + part.size())) ++n;
  return n;
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

// The text of <script id="pb-data">, exactly as embedded.
std::string embedded_data(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"pb-data\">";
  const auto begin = html.find(open);
  EXPECT_NE(begin, std::string::npos);
  const auto end = html.find("</script>", begin);
  return html.substr(begin + open.size(), end - begin - open.size());
}

// The `<tr>` of the acceptance table whose header cell is `unit`.
std::string row_of(const std::string& html, const std::string& unit) {
  const auto cell = html.find("<th scope=\"row\">" + unit + "</th>");
  if (cell == std::string::npos) return "";
  const auto begin = html.rfind("<tr", cell);
  return html.substr(begin, html.find("</tr>", cell) - begin);
}

TEST(HtmlReport, RendersEveryFigureTheTableAndTheContents) {
  const std::string html = render_html(sample::document());
  for (const auto& id : sample::figure_ids()) {
    EXPECT_EQ(count(html, "<div class=\"pb-plot\" id=\"fig-" + id + "\">"), 1u) << id;
    EXPECT_TRUE(contains(html, "<a href=\"#figure-" + id + "\">")) << "table of contents lacks " << id;
  }
  EXPECT_EQ(count(html, "class=\"pb-plot\""), sample::figure_ids().size());
  EXPECT_TRUE(contains(html, "data-figures=\"6\""));
  for (const auto* section : {"sec-frf", "sec-section-2", "sec-section-3", "sec-section-4"}) {
    EXPECT_TRUE(contains(html, std::string("<a href=\"#") + section + "\">")) << section;
    EXPECT_TRUE(contains(html, std::string("id=\"") + section + "\"")) << section;
  }
  // Numbers to 4 significant digits from results.units; a null one reads "not measured".
  const std::string unit1 = row_of(html, "APA 1");
  EXPECT_TRUE(contains(unit1, "<td class=\"status\">accepted</td>")) << unit1;
  EXPECT_TRUE(contains(unit1, "<td class=\"num\">93.86</td>")) << unit1;    // 95 * (1 - 0.012)
  EXPECT_TRUE(contains(unit1, "<td class=\"num\">-0.3137</td>")) << unit1;  // -0.31 * 1.012
  EXPECT_TRUE(contains(unit1, "<td class=\"num\">4.1</td>")) << unit1;      // flatness
  EXPECT_EQ(count(unit1, "<td class=\"nm\""), 0u) << unit1;
  EXPECT_EQ(count(row_of(html, "APA 7"), "<td class=\"nm\" title=\"not measured\">"), 1u);
  const std::string unit3 = row_of(html, "APA 3");
  EXPECT_TRUE(contains(unit3, "<tr class=\"rejected\">")) << unit3;
  EXPECT_TRUE(contains(unit3, "<td class=\"num\">2.3</td>")) << unit3;
  EXPECT_TRUE(contains(unit3, "<li>capacitance of the sensor stack 2.3 uF &lt; 4.0 uF (spec 4.0 .. 5.0 uF)</li>"));
  EXPECT_TRUE(contains(unit3, "<li>stroke 183 um &lt; 250 um (spec: at least 250 um)</li>"));
  EXPECT_EQ(count(html, "<tr class=\"accepted\">"), 6u);
  EXPECT_EQ(count(html, "<tr class=\"rejected\">"), 1u);
  // Batch summary: counts, the rejected unit by name and the IFF gain; results.batch is not dumped
  // (its tables, with display names, are the document's batch section).
  EXPECT_TRUE(contains(html, "<dt>Rejected</dt><dd>1: APA 3</dd>"));
  EXPECT_TRUE(contains(html, "<dt>IFF optimal gain g</dt><dd>103 (a factor on the controller of eq. 2.4)</dd>"));
  EXPECT_FALSE(contains(html, "resonance Hz"));
  EXPECT_FALSE(contains(html, "<dt>Not analysed</dt>"));
  // The library is inlined verbatim, once, and nothing is loaded from elsewhere.
  EXPECT_EQ(count(html, std::string(plotting_library().substr(0, 4096))), 1u);
  EXPECT_TRUE(contains(html, std::string(plotting_library().substr(plotting_library().size() - 4096))));
  EXPECT_FALSE(contains(lower(html), "<script src"));
  EXPECT_FALSE(contains(lower(html), "<link"));
}

TEST(HtmlReport, EmbeddedFiguresCarryDefaultsAndGaps) {
  json doc = sample::document();
  auto& trace = doc["sections"][0]["figures"][0]["panels"][2]["traces"][0];
  trace["y"][3] = "nan";
  trace["y"][4] = nullptr;
  trace["y"][5] = 0.1234567891234;
  trace.erase("mode");
  trace.erase("dash");
  const json data = json::parse(embedded_data(render_html(doc)));
  ASSERT_EQ(data["figures"].size(), 6u);
  const json& fig = data["figures"][0];
  EXPECT_EQ(fig["id"], "frf-de");
  EXPECT_EQ(fig["x_log"], true);
  EXPECT_EQ(fig["x_category"], false);
  EXPECT_EQ(fig["panels"].size(), 3u);
  const json& t = fig["panels"][2]["traces"][0];
  EXPECT_EQ(t["mode"], "lines");
  EXPECT_EQ(t["dash"], false);
  EXPECT_EQ(t["group"], "APA 1");
  EXPECT_TRUE(t["y"][3].is_null());
  EXPECT_TRUE(t["y"][4].is_null());
  EXPECT_TRUE(t["y"][10].is_null());                       // NaN double in the document
  EXPECT_DOUBLE_EQ(t["y"][5].get<double>(), 0.123456789);  // 9 significant digits
  EXPECT_EQ(t["x"].size(), 400u);
  EXPECT_DOUBLE_EQ(t["x"][0].get<double>(), 5.0);
  // A category axis for the batch bars.
  const json& bars = data["figures"][5];
  EXPECT_EQ(bars["x_category"], true);
  EXPECT_EQ(bars["panels"][0]["traces"][0]["x"][2], "APA 3");
  EXPECT_EQ(bars["panels"][0]["traces"][0]["mode"], "bars");
}

TEST(HtmlReport, EscapesEveryStringOfTheDocument) {
  json doc = sample::document();
  const std::string attack = "</script><script>alert(1)</script><!--<img src=x onerror=alert(2)>\"'&";
  doc["title"] = "Batch " + attack;
  doc["subtitle"] = attack;
  doc["results"]["units"][0]["id"] = attack;
  doc["results"]["units"][2]["reasons"][0] = attack;
  doc["results"]["units"][1]["flatness_um"] = attack;
  doc["results"]["batch"]["note"] = attack;
  doc["results"]["batch"][attack] = 1;
  doc["sections"][0]["title"] = attack;
  doc["sections"][0]["text"] = attack;
  doc["sections"][0]["figures"][0]["title"] = attack;
  doc["sections"][0]["figures"][0]["text"] = attack;
  doc["sections"][0]["figures"][0]["x_label"] = attack;
  const std::string separators = "line\xE2\x80\xA8separator\xE2\x80\xA9paragraph";
  doc["sections"][0]["figures"][0]["panels"][0]["traces"][0]["name"] = attack + separators;
  doc["sections"][0]["figures"][0]["panels"][0]["traces"][0]["group"] = attack;
  const std::string html = render_html(doc);

  // Exactly the three script elements of the page: the data, the library and the report script.
  EXPECT_EQ(count(lower(html), "<script"), 3u);
  EXPECT_EQ(count(lower(html), "</script"), 3u);
  EXPECT_FALSE(contains(html, "<img"));
  EXPECT_FALSE(contains(html, "<!--<"));
  const std::string escaped =
      "&lt;/script&gt;&lt;script&gt;alert(1)&lt;/script&gt;&lt;!--&lt;img src=x onerror=alert(2)&gt;&quot;&#39;&amp;";
  EXPECT_TRUE(contains(html, "<title>Batch " + escaped + "</title>"));
  EXPECT_TRUE(contains(html, "<th scope=\"row\">" + escaped + "</th>"));
  EXPECT_TRUE(contains(html, "<li>" + escaped + "</li>"));
  EXPECT_TRUE(contains(html, "<td class=\"num\">" + escaped + "</td>"));
  EXPECT_TRUE(contains(html, "<h3>" + escaped + "</h3>"));
  EXPECT_GE(count(html, escaped), 10u);

  // The data: no <, >, & or line separators in the raw text, and the same strings once parsed.
  const std::string raw = embedded_data(html);
  EXPECT_EQ(raw.find_first_of("<>&"), std::string::npos);
  EXPECT_FALSE(contains(raw, "\xE2\x80\xA8"));
  EXPECT_FALSE(contains(raw, "\xE2\x80\xA9"));
  EXPECT_TRUE(contains(raw, "\\u2028"));
  const json data = json::parse(raw);
  EXPECT_EQ(data["figures"][0]["x_label"], attack);
  EXPECT_EQ(data["figures"][0]["panels"][0]["traces"][0]["name"], attack + separators);
  EXPECT_EQ(data["figures"][0]["panels"][0]["traces"][0]["group"], attack);
}

TEST(HtmlReport, InvalidUtf8IsReplacedNotFatal) {
  json doc = sample::document();
  doc["sections"][0]["figures"][0]["panels"][0]["traces"][0]["name"] = std::string("APA \xFF\xFE 1");
  const json data = json::parse(embedded_data(render_html(doc)));
  EXPECT_EQ(data["figures"][0]["panels"][0]["traces"][0]["name"], "APA \xEF\xBF\xBD\xEF\xBF\xBD 1");
}

TEST(HtmlReport, EmptyBatchStillRenders) {
  const json doc = {
      {"title", "Nothing measured"}, {"results", {{"units", json::array()}}}, {"sections", json::array()}};
  const std::string html = render_html(doc);
  EXPECT_TRUE(contains(html, "The results list no unit."));
  EXPECT_TRUE(contains(html, "data-figures=\"0\""));
  EXPECT_EQ(json::parse(embedded_data(html))["figures"].size(), 0u);
}

// Issue 33: a unit that could not be analysed is neither accepted nor rejected: its row and the
// batch summary name it with its file and reason; accepted with not_analysed is a bad document.
TEST(HtmlReport, NotAnalysedUnitIsNamedWithItsFileAndReason) {
  json doc = sample::document();
  json& u2 = doc["results"]["units"][1];
  u2["name"] = "APA <2>";
  u2["accepted"] = false;
  u2["reasons"] = {"not analysed: the force sensor is dead"};
  u2["not_analysed"] = {{"file", "frf2.mat"}, {"key", "units[1].frf"}, {"reason", "Vs is constant"}};
  const std::string html = render_html(doc);
  const std::string row = row_of(html, "APA &lt;2&gt;");
  EXPECT_TRUE(contains(row, "<tr class=\"not-analysed\">")) << row;
  EXPECT_TRUE(contains(row, "<td class=\"status\">not analysed</td>")) << row;
  EXPECT_TRUE(contains(html, "<dt>Not analysed</dt><dd>1: APA &lt;2&gt;<ul><li>APA &lt;2&gt;: frf2.mat: Vs is constant</li></ul></dd>"));
  EXPECT_TRUE(contains(html, "<dt>Rejected</dt><dd>1: APA 3</dd>"));
  u2["accepted"] = true;
  (void)test::input_error([&] { (void)render_html(doc); }, "results.units[1].accepted");
}

TEST(HtmlReport, MarginalUnitHasItsStatusAndItsLineInTheSummary) {
  json doc = sample::document();
  json& u2 = doc["results"]["units"][1];
  u2["accepted"] = false;
  u2["marginal"] = true;
  u2["reasons"] = {"marginal: stroke 251 +- 4 um (k = 2) has a limit of the specification inside its interval"};
  const std::string html = render_html(doc);
  const std::string row = row_of(html, "APA 2");
  EXPECT_TRUE(contains(row, "<tr class=\"marginal\">")) << row;
  EXPECT_TRUE(contains(row, "<td class=\"status\">marginal</td>")) << row;
  EXPECT_TRUE(contains(row, "<li>marginal: stroke 251 +- 4 um"));
  EXPECT_TRUE(contains(html, "<dt>Marginal</dt><dd>1: APA 2 (a limit within the value's 95 % interval"));
  EXPECT_TRUE(contains(html, "<dt>Rejected</dt><dd>1: APA 3</dd>"));  // a marginal unit is not counted as rejected
  EXPECT_EQ(count(html, "<tr class=\"accepted\">"), 5u);
  u2["accepted"] = true;  // accepted and marginal at once is no verdict
  (void)test::input_error([&] { (void)render_html(doc); }, "results.units[1].marginal");
  u2["accepted"] = false;
  u2["marginal"] = "yes";
  (void)test::input_error([&] { (void)render_html(doc); }, "results.units[1].marginal");
}

TEST(HtmlReport, TextBecomesEscapedParagraphs) {
  json doc = sample::document();
  doc["sections"][1]["text"] = "First <paragraph>.\n\nSecond one,\non two lines.\n\n\n\n";
  doc["sections"][1]["figures"][0]["text"] = "A caption & more";
  const std::string html = render_html(doc);
  EXPECT_TRUE(contains(html,
                       "<h2>4. Integral force feedback</h2>\n<p>First &lt;paragraph&gt;.</p>\n"
                       "<p>Second one,\non two lines.</p>\n<p class=\"hint\">"));
  EXPECT_TRUE(contains(html, "<p class=\"caption\">A caption &amp; more</p>"));
  EXPECT_TRUE(contains(html, "<p>u -&gt; d_e for every unit &amp; the fitted model &lt;dashed&gt;.</p>"));
}

TEST(HtmlReport, TablesWarningsHoverLabelsAndACompactBatch) {
  json doc = sample::document();
  doc["sections"][1]["warnings"] = {"poles 12 % off the <model>"};
  doc["sections"][1]["tables"] = {{{"title", "Damped poles"},
                                   {"text", "per gain"},
                                   {"columns", {"gain", "f [Hz]", "ok", "note"}},
                                   {"rows", {{30000, 95.78576, true, nullptr}, {240000.0, 0.000123456, false, "a & b"}, {9.9996, -0.5, 1e7, "x"}}}}};
  doc["sections"][1]["figures"][0]["panels"][0]["traces"][0]["text"] = json::array();
  for (std::size_t i = 0; i < doc["sections"][1]["figures"][0]["panels"][0]["traces"][0]["x"].size(); ++i) {
    doc["sections"][1]["figures"][0]["panels"][0]["traces"][0]["text"].push_back(i == 0 ? json(nullptr) : json("g = <" + std::to_string(i) + ">"));
  }
  // results.batch as the pipeline writes it: flat objects per quantity, a list of flat objects.
  doc["results"]["batch"] = {{"outlier_rule", {{"robust_z_threshold", 3.5}, {"rejects", true}}},
                             {"spread", {{"resonance_Hz", {{"median", 95.31927}, {"min", 94.978}, {"units", 7}}},
                                         {"k1_N_per_um", {{"median", 1.697019948}, {"min", 1.6749}, {"units", 7}}}}},
                             {"outliers", {{{"unit", 3}, {"quantity", "stroke_um"}, {"value", 158.3063121909871}}}}};
  const std::string html = render_html(doc);
  EXPECT_TRUE(contains(html, "<p class=\"warning\" role=\"alert\">poles 12 % off the &lt;model&gt;</p>"));
  EXPECT_TRUE(contains(html, "<h3>Damped poles</h3>"));
  // Numbers to 3 significant digits, positional in [0.001, 1e6); booleans and null readable.
  EXPECT_TRUE(contains(html, "<tr><td class=\"num\">30000</td><td class=\"num\">95.8</td><td>yes</td><td class=\"nm\""));
  EXPECT_TRUE(contains(html, "<td class=\"num\">240000</td><td class=\"num\">0.000123</td><td>no</td><td>a &amp; b</td>"));
  EXPECT_TRUE(contains(html, "<td class=\"num\">10.0</td><td class=\"num\">-0.500</td><td class=\"num\">1e+07</td>"));
  // results.batch's raw keys never reach the page.
  EXPECT_FALSE(contains(html, "robust z threshold"));
  EXPECT_FALSE(contains(html, "stroke_um"));
  // Hover labels reach the data, escaped there like every string.
  const json data = json::parse(embedded_data(html));
  const json& t = data["figures"][2]["panels"][0]["traces"][0];
  EXPECT_TRUE(t["text"][0].is_null());
  EXPECT_EQ(t["text"][1], "g = <1>");
  // Bad tables and labels name their field.
  json bad = doc;
  bad["sections"][1]["tables"][0]["rows"][1].erase(0);
  (void)test::input_error([&] { (void)render_html(bad); }, "sections[1].tables[0].rows[1]");
  bad = doc;
  bad["sections"][1]["tables"][0]["rows"][0][1] = json::object();
  (void)test::input_error([&] { (void)render_html(bad); }, "sections[1].tables[0].rows[0][1]");
  bad["sections"][1]["tables"][0]["rows"][0][1] = json::array({1.0, json::array()});  // a list of lists
  (void)test::input_error([&] { (void)render_html(bad); }, "sections[1].tables[0].rows[0][1]");
  // A flat list of numbers is one cell, its items joined.
  bad = doc;
  bad["sections"][1]["tables"][0]["rows"][0][1] = json::array({1.0, 10.0});
  EXPECT_TRUE(test::contains(render_html(bad), "<td class=\"num\">1.00, 10.0</td>"));
  bad = doc;
  bad["sections"][1]["figures"][0]["panels"][0]["traces"][0]["text"].erase(0);
  (void)test::input_error([&] { (void)render_html(bad); }, "sections[1].figures[0].panels[0].traces[0].text");
  bad = doc;
  bad["sections"][1]["warnings"] = "one";
  (void)test::input_error([&] { (void)render_html(bad); }, "sections[1].warnings");
}

struct BadDocument {
  const char* what;
  std::function<void(json&)> edit;
  std::string field;
};

TEST(HtmlReport, BadDocumentsAreInputErrorsNamingTheField) {
  const std::string fig0 = "sections[0].figures[0]";
  const std::vector<BadDocument> cases = {
      {"no title", [](json& d) { d.erase("title"); }, "title"},
      {"empty title", [](json& d) { d["title"] = ""; }, "title"},
      {"title a number", [](json& d) { d["title"] = 3; }, "title"},
      {"unknown top-level key", [](json& d) { d["sectionz"] = json::array(); }, "sectionz"},
      {"subtitle a list", [](json& d) { d["subtitle"] = json::array(); }, "subtitle"},
      {"no results", [](json& d) { d.erase("results"); }, "results"},
      {"results a list", [](json& d) { d["results"] = json::array(); }, "results"},
      {"no units", [](json& d) { d["results"].erase("units"); }, "results.units"},
      {"unit not an object", [](json& d) { d["results"]["units"][1] = 5; }, "results.units[1]"},
      {"unit without id", [](json& d) { d["results"]["units"][1].erase("id"); }, "results.units[1].id"},
      {"unit id a float", [](json& d) { d["results"]["units"][1]["id"] = 1.5; }, "results.units[1].id"},
      {"unit listed twice", [](json& d) { d["results"]["units"][4]["id"] = "APA 2"; }, "results.units[4].id"},
      {"no accepted", [](json& d) { d["results"]["units"][2].erase("accepted"); }, "results.units[2].accepted"},
      {"accepted a string", [](json& d) { d["results"]["units"][2]["accepted"] = "no"; }, "results.units[2].accepted"},
      {"rejected without reason", [](json& d) { d["results"]["units"][2]["reasons"] = json::array(); },
       "results.units[2].reasons"},
      {"reason a number", [](json& d) { d["results"]["units"][2]["reasons"][1] = 7; }, "results.units[2].reasons[1]"},
      {"capacitance a number", [](json& d) { d["results"]["units"][0]["capacitance_uF"] = 4.4; },
       "results.units[0].capacitance_uF"},
      {"sensor capacitance an object",
       [](json& d) { d["results"]["units"][0]["capacitance_uF"]["sensor"] = json::object(); },
       "results.units[0].capacitance_uF.sensor"},
      {"batch a string", [](json& d) { d["results"]["batch"] = "spread"; }, "results.batch"},
      {"no sections", [](json& d) { d.erase("sections"); }, "sections"},
      {"section without title", [](json& d) { d["sections"][1].erase("title"); }, "sections[1].title"},
      {"section id with a space", [](json& d) { d["sections"][1]["id"] = "a b"; }, "sections[1].id"},
      {"section id twice", [](json& d) { d["sections"][1]["id"] = "frf"; }, "sections[1].id"},
      {"section without figures", [](json& d) { d["sections"][1].erase("figures"); }, "sections[1].figures"},
      {"figure id upper case", [&](json& d) { d["sections"][0]["figures"][0]["id"] = "FRF"; }, fig0 + ".id"},
      {"figure id twice", [](json& d) { d["sections"][2]["figures"][1]["id"] = "hysteresis"; },
       "sections[2].figures[1].id"},
      {"figure without title", [&](json& d) { d["sections"][0]["figures"][0].erase("title"); }, fig0 + ".title"},
      {"x_log a string", [&](json& d) { d["sections"][0]["figures"][0]["x_log"] = "yes"; }, fig0 + ".x_log"},
      {"no panels", [&](json& d) { d["sections"][0]["figures"][0]["panels"] = json::array(); }, fig0 + ".panels"},
      {"unknown panel key", [&](json& d) { d["sections"][0]["figures"][0]["panels"][0]["y_logg"] = true; },
       fig0 + ".panels[0].y_logg"},
      {"unknown trace key", [&](json& d) { d["sections"][0]["figures"][0]["panels"][1]["traces"][0]["color"] = "red"; },
       fig0 + ".panels[1].traces[0].color"},
      {"trace without name", [&](json& d) { d["sections"][0]["figures"][0]["panels"][1]["traces"][6].erase("name"); },
       fig0 + ".panels[1].traces[6].name"},
      {"y_upper on a line", [&](json& d) { d["sections"][0]["figures"][0]["panels"][1]["traces"][2]["y_upper"] = json::array(); },
       fig0 + ".panels[1].traces[2].y_upper"},
      {"band without y_upper", [&](json& d) { d["sections"][0]["figures"][0]["panels"][1]["traces"][2]["mode"] = "band"; },
       fig0 + ".panels[1].traces[2].y_upper"},
      {"band y_upper short", [&](json& d) {
         json& t = d["sections"][0]["figures"][0]["panels"][1]["traces"][2];
         t["mode"] = "band";
         t["y_upper"] = t["y"];
         t["y_upper"].erase(0);
       },
       fig0 + ".panels[1].traces[2].y_upper"},
      {"y shorter than x", [&](json& d) { d["sections"][0]["figures"][0]["panels"][1]["traces"][2]["y"].erase(0); },
       fig0 + ".panels[1].traces[2].y"},
      {"y an object", [&](json& d) { d["sections"][0]["figures"][0]["panels"][1]["traces"][2]["y"] = json::object(); },
       fig0 + ".panels[1].traces[2].y"},
      {"y entry a word", [&](json& d) { d["sections"][0]["figures"][0]["panels"][1]["traces"][2]["y"][5] = "high"; },
       fig0 + ".panels[1].traces[2].y[5]"},
      {"x entry a list",
       [&](json& d) { d["sections"][0]["figures"][0]["panels"][0]["traces"][0]["x"][7] = json::array(); },
       fig0 + ".panels[0].traces[0].x[7]"},
      {"mode unknown", [&](json& d) { d["sections"][0]["figures"][0]["panels"][0]["traces"][0]["mode"] = "dots"; },
       fig0 + ".panels[0].traces[0].mode"},
      {"dash a number", [&](json& d) { d["sections"][0]["figures"][0]["panels"][0]["traces"][0]["dash"] = 1; },
       fig0 + ".panels[0].traces[0].dash"},
      {"log category axis", [](json& d) { d["sections"][3]["figures"][0]["x_log"] = true; },
       "sections[3].figures[0].x_log"},
      {"numbers mixed with categories",
       [](json& d) { d["sections"][3]["figures"][0]["panels"][1]["traces"][1]["x"] = {1, 2, 3, 4, 5, 6, 7}; },
       "sections[3].figures[0].panels[1].traces[1].x"},
  };
  const json base = sample::document();
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    json doc = base;
    c.edit(doc);
    try {
      (void)render_html(doc);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), "report document") << e.what();
      EXPECT_EQ(e.field(), c.field) << e.what();
      EXPECT_TRUE(contains(e.what(), "expected")) << e.what();
    }
  }
  // The message says what was found.
  json doc = sample::document();
  doc["sections"][0]["figures"][0]["panels"][1]["traces"][2]["y"].erase(0);
  const std::string message = test::input_error([&] { (void)render_html(doc); });
  EXPECT_TRUE(contains(message, "400 values (as many as x)")) << message;
  EXPECT_TRUE(contains(message, "399 values")) << message;
  EXPECT_TRUE(contains(test::input_error([] { (void)render_html(json::array()); }, "document"), "a list of 0"));
}

TEST(HtmlReport, WriteHtmlIsAtomic) {
  test::TempDir dir;
  const auto file = dir.path() / "report.html";
  write_html(sample::document(), file);
  const std::string written = test::read_text(file);
  EXPECT_EQ(written, render_html(sample::document()));

  // A bad document leaves the previous report untouched and no temporary file behind.
  json bad = sample::document();
  bad["results"]["units"][2]["reasons"] = json::array();
  (void)test::input_error([&] { write_html(bad, file); }, "results.units[2].reasons");
  EXPECT_EQ(test::read_text(file), written);
  // And so does a directory that cannot hold it.
  (void)test::input_error([&] { write_html(sample::document(), dir.path() / "missing" / "report.html"); });
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) names.push_back(entry.path().filename());
  EXPECT_EQ(names, std::vector<std::string>{"report.html"});
}

}  // namespace
}  // namespace piezobench::report
