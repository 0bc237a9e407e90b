#include "cli_common.hpp"

#include "piezobench/io/fields_json.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>

#include <fmt/format.h>

#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/units.hpp"

namespace piezobench::app {

void print_json(const nlohmann::json& document) {
  // Invalid UTF-8 (a hostile file's channel names quoted in a message) becomes U+FFFD, never a throw.
  std::cout << document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << '\n';
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

nlohmann::json quality_json(const core::FitQuality& quality) { return io::results_object(quality); }

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
          // CLI11 puts the option's name before this message: a UsageError's own "--units: "
          // prefix would repeat it.
          const std::string message = e.what();
          const std::size_t colon = message.find(": ");
          if (message.rfind("--", 0) == 0 && colon != std::string::npos) return message.substr(colon + 2);
          return message;
        }
        return {};
      },
      description);
}

std::map<std::string, std::string> parse_units(const std::string& text) {
  std::map<std::string, std::string> out;
  if (text.empty()) return out;
  for (const std::string& item : split_list(text, "--units")) {
    const std::size_t eq = item.find('=');
    const auto trim = [](std::string s) {
      const auto first = s.find_first_not_of(" \t"), last = s.find_last_not_of(" \t");
      return first == std::string::npos ? std::string() : s.substr(first, last - first + 1);
    };
    const std::string name = eq == std::string::npos ? std::string() : trim(item.substr(0, eq));
    const std::string unit = eq == std::string::npos ? std::string() : trim(item.substr(eq + 1));
    if (name.empty() || unit.empty()) throw UsageError("--units", "CHANNEL=UNIT items (de=um,Vs=mV)", "'" + item + "'");
    if (!io::find_unit(unit)) {
      throw UsageError("--units", "a unit of the table (" + io::known_units() + ", or products and quotients of them) for " + name,
                       "'" + unit + "'");
    }
    if (!out.emplace(name, unit).second) throw UsageError("--units", "each channel once", "'" + name + "' twice");
  }
  return out;
}

void add_units_option(CLI::App* command, std::string& text) {
  command->add_option("--units", text,
                      "units of the input file's channels, replacing or completing the file's: CHANNEL=UNIT,... (de=um,Vs=mV; "
                      "for an FRF file also H_NAME=um/V or the input's name); every name must be a channel of the file")
      ->check(parsed_by([](const std::string& v) { (void)parse_units(v); }, "CHANNEL=UNIT,..."));
}

void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) log_line("warning: " + w);
}

io::FrfFile read_frf_with_units(const std::string& file, const std::string& units) {
  io::FrfReadOptions options;
  options.unit_overrides = parse_units(units);
  io::FrfFile frf = io::read_frf_file(file, options);
  print_warnings(frf.warnings);
  return frf;
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

CLI::Validator input_file() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        std::error_code ec;
        const auto status = std::filesystem::status(value, ec);
        if (!std::filesystem::exists(status)) throw InputError(value, "file", "an existing, readable file", "no such file");
        if (std::filesystem::is_directory(status)) throw InputError(value, "file", "an existing, readable file", "a folder");
        std::ifstream in(value, std::ios::binary);
        if (!in) throw InputError(value, "file", "an existing, readable file", std::string("not readable (") + std::strerror(errno) + ")");
        return {};
      },
      "FILE");
}

CLI::Validator number_in(double lo, double hi) {
  const std::string what = std::isinf(hi) ? fmt::format("a number >= {:g}", lo) : fmt::format("a number in [{:g}, {:g}]", lo, hi);
  return CLI::Validator(
      [lo, hi, what](std::string& value) -> std::string {
        double v = 0.0;
        const char* end = value.data() + value.size();
        const auto [ptr, ec] = std::from_chars(value.data(), end, v);
        if (ec != std::errc() || ptr != end || !(v >= lo && v <= hi)) return "expected " + what + ", found '" + value + "'";
        return {};
      },
      std::isinf(hi) ? fmt::format("NUMBER >= {:g}", lo) : fmt::format("NUMBER in [{:g}, {:g}]", lo, hi));
}

CLI::Validator non_negative() { return number_in(0.0, std::numeric_limits<double>::infinity()); }

CLI::Validator positive() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        double v = 0.0;
        const char* end = value.data() + value.size();
        const auto [ptr, ec] = std::from_chars(value.data(), end, v);
        if (ec != std::errc() || ptr != end || !(v > 0.0) || std::isinf(v)) return "expected a number > 0, found '" + value + "'";
        return {};
      },
      "NUMBER > 0");
}

namespace {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string nearest_option(const CLI::App& app, const std::string& unknown) {
  std::string word = unknown.substr(0, unknown.find('='));
  while (!word.empty() && word.front() == '-') word.erase(0, 1);
  if (word.empty()) return {};
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const CLI::App* a = &app; a != nullptr; a = a->get_parent()) {
    for (const CLI::Option* o : a->get_options()) {
      for (const std::string& name : o->get_lnames()) {
        const std::size_t d = edit_distance(word, name);
        if (d < best_distance) {
          best_distance = d;
          best = "--" + name;
        }
      }
    }
  }
  return best;
}

}  // namespace piezobench::app
