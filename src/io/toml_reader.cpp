#include "piezobench/io/toml_reader.hpp"

#include <algorithm>
#include <cmath>

#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/io/toml_describe.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/io/units.hpp"

namespace piezobench::io {

namespace {

constexpr const char* kRequired = "nothing (the key is required)";

std::string joined_keys(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

// "\"a\", \"b\" or \"c\"".
std::string quoted_choices(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += i + 1 == items.size() ? " or " : ", ";
    out += "\"" + items[i] + "\"";
  }
  return out;
}

std::string indexed(std::string_view k, std::size_t i) { return std::string(k) + "[" + std::to_string(i) + "]"; }

}  // namespace

bool NumberBounds::contains(double v) const {
  const bool above = min_open ? v > min : v >= min;
  const bool below = max_open ? v < max : v <= max;
  return above && below;
}

std::string NumberBounds::describe(const std::string& unit) const {
  const bool has_min = std::isfinite(min), has_max = std::isfinite(max);
  std::string out = "a number";
  if (has_min && has_max) {
    out += " in " + std::string(min_open ? "(" : "[") + format_number(min) + ", " + format_number(max) + (max_open ? ")" : "]");
  } else if (has_min) {
    out += std::string(min_open ? " > " : " >= ") + format_number(min);
  } else if (has_max) {
    out += std::string(max_open ? " < " : " <= ") + format_number(max);
  }
  return unit.empty() ? out : out + " " + unit;
}

std::string key_unit(std::string_view key) {
  // Try the suffixes after each '_', longest first: "stiffness_N_per_um" -> "N_per_um" -> "N/um".
  for (std::size_t at = key.find('_'); at != std::string_view::npos; at = key.find('_', at + 1)) {
    std::string candidate(key.substr(at + 1));
    for (std::size_t p = candidate.find("_per_"); p != std::string::npos; p = candidate.find("_per_")) candidate.replace(p, 5, "/");
    if (candidate.empty() || candidate.find('_') != std::string::npos) continue;
    if (find_unit(candidate)) return candidate;
  }
  return "";
}

TomlReader::TomlReader(const toml::table& table, std::string file, std::string path)
    : table_(&table), file_(std::move(file)), path_(std::move(path)) {}

std::string TomlReader::key(std::string_view k) const {
  if (path_.empty()) return std::string(k);
  return path_ + (k.empty() || k.front() == '[' ? "" : ".") + std::string(k);
}

std::string TomlReader::where(const toml::node* node) const {
  auto line = node != nullptr ? node->source().begin.line : 0;
  if (line == 0 && !path_.empty()) line = table_->source().begin.line;  // the root's line 1 would say nothing
  if (line == 0) return file_;
  const std::string at = "line " + std::to_string(line);
  return file_.empty() ? at : file_ + ": " + at;
}

void TomlReader::fail(std::string_view k, const std::string& expected, const std::string& found, const toml::node* at) const {
  throw InputError(where(at != nullptr ? at : table_->get(k)), key(k), expected, found);
}

void TomlReader::only(const std::vector<std::string>& known) const {
  for (const auto& [k, node] : *table_) {
    const std::string name(k.str());
    if (std::find(known.begin(), known.end(), name) == known.end()) fail(name, "one of " + joined_keys(known), "an unknown key", &node);
  }
}

double TomlReader::number_at(const toml::node& node, std::string_view k, const NumberBounds& bounds) const {
  const auto v = toml_number(node);
  const std::string unit = key_unit(k.substr(0, k.find('[')));
  if (!v) fail(k, bounds.describe(unit), describe_toml(node), &node);
  if (!std::isfinite(*v) || !bounds.contains(*v)) {
    const bool plain = !std::isfinite(bounds.min) && !std::isfinite(bounds.max);
    fail(k, plain ? "a finite number" : bounds.describe(unit), format_number_exact(*v), &node);
  }
  return *v;
}

std::optional<double> TomlReader::number(std::string_view k, const NumberBounds& bounds) const {
  const toml::node* n = get(k);
  if (n == nullptr) return std::nullopt;
  return number_at(*n, k, bounds);
}

double TomlReader::required_number(std::string_view k, const NumberBounds& bounds, const std::string& what) const {
  const auto v = number(k, bounds);
  if (!v) fail(k, what.empty() ? bounds.describe(key_unit(k)) : what, kRequired);
  return *v;
}

std::optional<std::int64_t> TomlReader::integer(std::string_view k, std::int64_t lo, std::int64_t hi) const {
  const toml::node* n = get(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_integer()) fail(k, "an integer", describe_toml(*n));
  return checked_integer(n->as_integer()->get(), lo, hi, NumberOrigin::file(where(n), key(k)));
}

std::optional<bool> TomlReader::boolean(std::string_view k) const {
  const toml::node* n = get(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_boolean()) fail(k, "true or false", describe_toml(*n));
  return n->as_boolean()->get();
}

std::optional<std::string> TomlReader::string(std::string_view k) const {
  const toml::node* n = get(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_string()) fail(k, "a string", describe_toml(*n));
  return n->as_string()->get();
}

std::string TomlReader::required_string(std::string_view k, const std::string& what) const {
  auto v = string(k);
  if (!v) fail(k, what, kRequired);
  return std::move(*v);
}

std::optional<std::string> TomlReader::choice(std::string_view k, const std::vector<std::string>& allowed) const {
  const toml::node* n = get(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_string()) fail(k, quoted_choices(allowed), describe_toml(*n));
  std::string v = n->as_string()->get();
  if (std::find(allowed.begin(), allowed.end(), v) == allowed.end()) fail(k, quoted_choices(allowed), "'" + v + "'");
  return v;
}

const toml::array* TomlReader::array(std::string_view k, const std::string& what) const {
  const toml::node* n = get(k);
  if (n == nullptr) return nullptr;
  if (!n->is_array()) fail(k, what, describe_toml(*n));
  return n->as_array();
}

const toml::node* TomlReader::element(std::string_view k, std::size_t i) const {
  const toml::node* n = get(k);
  const toml::array* a = n != nullptr ? n->as_array() : nullptr;
  return a != nullptr && i < a->size() ? a->get(i) : nullptr;
}

std::optional<std::vector<double>> TomlReader::numbers(std::string_view k, const NumberBounds& bounds) const {
  const toml::array* a = array(k, "an array of numbers");
  if (a == nullptr) return std::nullopt;
  std::vector<double> out;
  out.reserve(a->size());
  for (std::size_t i = 0; i < a->size(); ++i) out.push_back(number_at(*a->get(i), indexed(k, i), bounds));
  return out;
}

std::vector<double> TomlReader::required_numbers(std::string_view k, const NumberBounds& bounds) const {
  auto v = numbers(k, bounds);
  if (!v) fail(k, "an array of numbers", kRequired);
  return std::move(*v);
}

std::optional<std::vector<std::int64_t>> TomlReader::integers(std::string_view k, std::int64_t lo, std::int64_t hi) const {
  const toml::array* a = array(k, "an array of integers");
  if (a == nullptr) return std::nullopt;
  std::vector<std::int64_t> out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::node& e = *a->get(i);
    if (!e.is_integer()) fail(indexed(k, i), "an integer", describe_toml(e), &e);
    out.push_back(checked_integer(e.as_integer()->get(), lo, hi, NumberOrigin::file(where(&e), key(indexed(k, i)))));
  }
  return out;
}

std::vector<std::string> TomlReader::strings(std::string_view k) const {
  const toml::array* a = array(k, "an array of strings");
  std::vector<std::string> out;
  if (a == nullptr) return out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::node& e = *a->get(i);
    if (!e.is_string()) fail(indexed(k, i), "a string", describe_toml(e), &e);
    out.push_back(e.as_string()->get());
  }
  return out;
}

std::optional<std::pair<double, double>> TomlReader::pair(std::string_view k, const std::string& what) const {
  const toml::array* a = array(k, what);
  if (a == nullptr) return std::nullopt;
  if (a->size() != 2) fail(k, what, describe_toml(*get(k)));
  return std::pair{number_at(*a->get(0), indexed(k, 0)), number_at(*a->get(1), indexed(k, 1))};
}

std::optional<TomlReader> TomlReader::table(std::string_view k) const {
  const toml::node* n = get(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_table()) fail(k, "a table", describe_toml(*n));
  return TomlReader(*n->as_table(), file_, key(k));
}

TomlReader TomlReader::required_table(std::string_view k, const std::string& what) const {
  auto t = table(k);
  if (!t) fail(k, what.empty() ? "a table [" + key(k) + "]" : what, "nothing (the table is required)");
  return std::move(*t);
}

TomlReader TomlReader::table_or_empty(std::string_view k) const {
  static const toml::table empty;
  auto t = table(k);
  return t ? std::move(*t) : TomlReader(empty, file_, key(k));
}

std::vector<TomlReader> TomlReader::tables(std::string_view k) const {
  const toml::array* a = array(k, "an array of tables ([[" + key(k) + "]])");
  std::vector<TomlReader> out;
  if (a == nullptr) return out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::node& e = *a->get(i);
    if (!e.is_table()) fail(indexed(k, i), "a table", describe_toml(e), &e);
    out.emplace_back(*e.as_table(), file_, key(indexed(k, i)));
  }
  return out;
}

}  // namespace piezobench::io
