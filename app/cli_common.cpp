#include "cli_common.hpp"

#include <charconv>
#include <cmath>
#include <iostream>

#include "piezobench/core/error.hpp"

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
    if (item.empty()) throw InputError("", option, "a comma-separated list with no empty item", "'" + text + "'");
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
      throw InputError("", option, "a comma-separated list of finite numbers", "'" + item + "' in '" + text + "'");
    }
    values.push_back(value);
  }
  return values;
}

void log_line(const std::string& message) { std::cerr << "piezobench: " << message << '\n'; }

}  // namespace piezobench::app
