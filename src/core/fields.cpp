#include "piezobench/core/fields.hpp"

namespace piezobench::core {

std::string unit_key_suffix(std::string_view unit) {
  std::string out;
  for (const char c : unit) {
    if (c == '/') {
      out += "_per_";
    } else if (c == ' ') {
      out += '_';
    } else if (c != '^') {
      out += c;
    }
  }
  return out;
}

std::string results_key(std::string_view name, const Shown& shown, std::string_view own_key) {
  if (!own_key.empty()) return std::string(own_key);
  const std::string suffix = unit_key_suffix(shown.unit);
  std::string key(name);
  if (suffix.empty()) return key;
  std::string tail = "_";
  tail += suffix;
  if (key.size() >= tail.size() && key.compare(key.size() - tail.size(), tail.size(), tail) == 0) return key;
  key += tail;
  return key;
}

std::string unit_heading(const Shown& shown) {
  std::string out;
  if (shown.unit.empty()) return out;
  out += '[';
  out.append(shown.unit);
  out += ']';
  return out;
}

std::string report_heading(std::string_view name, const Shown& shown) {
  std::string words(name);
  std::string tail = "_";
  tail += unit_key_suffix(shown.unit);
  if (!shown.unit.empty() && words.size() > tail.size() && words.compare(words.size() - tail.size(), tail.size(), tail) == 0) {
    words.resize(words.size() - tail.size());
  }
  for (char& c : words) {
    if (c == '_') c = ' ';
  }
  const std::string unit = unit_heading(shown);
  if (!unit.empty()) {
    words += ' ';
    words += unit;
  }
  return words;
}

}  // namespace piezobench::core
