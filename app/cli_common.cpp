#include "cli_common.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <cmath>
#include <iostream>

#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"

namespace piezobench::app {

void print_json(const nlohmann::json& document) {
  std::cout << document.dump(2) << '\n';
  std::cout.flush();
}

std::vector<std::string> split_list(const std::string& text, const std::string& option) {
  std::vector<std::string> items;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    std::string item = text.substr(start, end - start);
    const auto first = item.find_first_not_of(" \t");
    const auto last = item.find_last_not_of(" \t");
    item = first == std::string::npos ? std::string() : item.substr(first, last - first + 1);
    if (item.empty()) throw UsageError(option, "a comma-separated list with no empty item", "'" + text + "'");
    items.push_back(item);
    start = end + 1;
  }
  return items;
}

std::vector<double> parse_number_list(const std::string& text, const std::string& option) {
  std::vector<double> values;
  for (const std::string& item : split_list(text, option)) {
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (ec != std::errc() || ptr != item.data() + item.size() || !std::isfinite(value)) {
      throw UsageError(option, "a comma-separated list of finite numbers", "'" + item + "' in '" + text + "'");
    }
    values.push_back(value);
  }
  return values;
}

void log_line(const std::string& message) { std::cerr << "piezobench: " << message << '\n'; }

nlohmann::json quality_json(const core::FitQuality& quality) {
  return {{"quality", core::to_string(quality.verdict)},
          {"quality_problems", quality.problems},
          {"physically_possible", !quality.impossible},
          {"advice", quality.advice}};
}

int exit_code_for(const core::FitQuality& quality) {
  return quality.poor() ? core::kPoorFitExitCode : 0;
}

int report_quality(const core::FitQuality& quality) {
  if (quality.poor()) {
    log_line("warning: the fit is poor (exit code 6): " + quality.summary());
    if (quality.impossible) log_line("warning: a fitted parameter is not physical: the parameters are not shown as a result");
  }
  return exit_code_for(quality);
}

CLI::Validator parsed_by(const std::function<void(const std::string&)>& parse, const std::string& description) {
  return CLI::Validator(
      [parse](std::string& value) -> std::string {
        try {
          parse(value);
        } catch (const Error& e) {
          return e.what();
        }
        return {};
      },
      description);
}

CLI::Validator output_extension(const std::vector<std::string>& extensions) {
  std::string list;
  for (const auto& e : extensions) list += (list.empty() ? "" : ", ") + e;
  return CLI::Validator(
      [extensions, list](std::string& value) -> std::string {
        std::string ext = std::filesystem::path(value).extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (std::find(extensions.begin(), extensions.end(), ext) != extensions.end()) return {};
        return "expected a file name ending in one of " + list + ", found '" + value + "'";
      },
      "FILE (" + list + ")");
}

}  // namespace piezobench::app
