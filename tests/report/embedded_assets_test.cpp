#include "piezobench/report/embedded_assets.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>
#include <string>

#include "test_util.hpp"

namespace piezobench::report {
namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::tolower(c); });
  return out;
}

// What src/report/js/package-lock.json pins.
std::string locked_version() {
  const auto lock = nlohmann::json::parse(
      test::read_text(std::filesystem::path(PIEZOBENCH_SOURCE_DIR) / "src/report/js/package-lock.json"));
  return lock.at("packages").at("node_modules/plotly.js-dist-min").at("version").get<std::string>();
}

TEST(EmbeddedAssets, PlottingLibraryIsTheInstalledPlotlyBundle) {
  const std::string_view library = plotting_library();
  EXPECT_EQ(plotting_library_version(), locked_version());
  // The bundle, byte for byte: its banner names the version, and it is as long as the file.
  const std::string banner = "/**\n* plotly.js v" + std::string(plotting_library_version()) + "\n";
  EXPECT_EQ(library.substr(0, banner.size()), banner);
  const auto file =
      std::filesystem::path(PIEZOBENCH_SOURCE_DIR) / "src/report/js/node_modules/plotly.js-dist-min/plotly.min.js";
  EXPECT_EQ(library.size(), std::filesystem::file_size(file));
  EXPECT_EQ(library, test::read_text(file));
  EXPECT_TRUE(test::contains(std::string(library.substr(library.size() - 200)), "window.Plotly = Plotly;"));
}

TEST(EmbeddedAssets, ReportScriptAndStyle) {
  EXPECT_EQ(report_script(),
            test::read_text(std::filesystem::path(PIEZOBENCH_SOURCE_DIR) / "src/report/assets/report.js"));
  EXPECT_EQ(report_style(),
            test::read_text(std::filesystem::path(PIEZOBENCH_SOURCE_DIR) / "src/report/assets/report.css"));
  EXPECT_TRUE(test::contains(std::string(report_script()), "Plotly.newPlot"));
}

// Each asset goes verbatim inside a <script> or <style> element, which ends at the first
// "</script" or "</style"; "<!--" followed by "<script" would change how that end is found.
TEST(EmbeddedAssets, AssetsCanBeInlinedVerbatim) {
  for (const std::string_view asset : {plotting_library(), report_script(), report_style()}) {
    const std::string text = lower(asset);
    EXPECT_EQ(text.find("</script"), std::string::npos);
    EXPECT_EQ(text.find("<script"), std::string::npos);
    EXPECT_EQ(text.find("</style"), std::string::npos);
  }
}

}  // namespace
}  // namespace piezobench::report
