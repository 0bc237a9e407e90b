#include "toml_reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "piezobench/core/error.hpp"
#include "piezobench/io/toml_describe.hpp"
#include "piezobench/io/toml_table.hpp"

namespace piezobench::station::detail {

TableReader::TableReader(const toml::table& table, std::string file, std::string prefix)
    : table_(table), file_(std::move(file)), prefix_(std::move(prefix)) {}

std::string TableReader::key(const std::string& k) const { return prefix_.empty() ? k : prefix_ + "." + k; }

std::string TableReader::where(const toml::node* node) const {
  const toml::node& n = node ? *node : static_cast<const toml::node&>(table_);
  const auto line = n.source().begin.line;
  if (line == 0) return file_;
  return fmt::format("{}: line {}", file_, line);
}

void TableReader::fail(const std::string& k, const std::string& expected, const std::string& found, const toml::node* node) const {
  throw InputError(where(node ? node : table_.get(k)), key(k), expected, found);
}

void TableReader::only(const std::vector<std::string>& known) const {
  for (const auto& [k, node] : table_) {
    const std::string name(k.str());
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      std::string list;
      for (const auto& s : known) list += (list.empty() ? "" : ", ") + s;
      fail(name, "one of " + list, "an unknown key", &node);
    }
  }
}

std::optional<std::string> TableReader::text(const std::string& k) const {
  const toml::node* n = table_.get(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_string()) fail(k, "a string", io::describe_toml(*n));
  return std::string(*n->value<std::string>());
}

std::string TableReader::required_text(const std::string& k) const {
  auto v = text(k);
  if (!v) fail(k, "a string", "nothing (the key is required)");
  return *v;
}

std::optional<double> TableReader::number(const std::string& k) const {
  const toml::node* n = table_.get(k);
  if (n == nullptr) return std::nullopt;
  const auto v = io::toml_number(*n);
  if (!v) fail(k, "a number", io::describe_toml(*n));
  if (!std::isfinite(*v)) fail(k, "a finite number", fmt::format("{}", *v));
  return v;
}

std::optional<long> TableReader::integer(const std::string& k, long min) const {
  const toml::node* n = table_.get(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_integer()) fail(k, fmt::format("an integer >= {}", min), io::describe_toml(*n));
  const auto v = *n->value<std::int64_t>();
  if (v < min) fail(k, fmt::format("an integer >= {}", min), std::to_string(v));
  return static_cast<long>(v);
}

std::optional<bool> TableReader::flag(const std::string& k) const {
  const toml::node* n = table_.get(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_boolean()) fail(k, "true or false", io::describe_toml(*n));
  return *n->value<bool>();
}

std::vector<std::string> TableReader::texts(const std::string& k) const {
  const toml::node* n = table_.get(k);
  if (n == nullptr) return {};
  const toml::array* a = n->as_array();
  if (a == nullptr) fail(k, "an array of strings", io::describe_toml(*n));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::node& e = *a->get(i);
    if (!e.is_string()) fail(fmt::format("{}[{}]", k, i), "a string", io::describe_toml(e), &e);
    out.emplace_back(*e.value<std::string>());
  }
  return out;
}

const toml::node* TableReader::element(const std::string& k, std::size_t i) const {
  const toml::node* n = table_.get(k);
  const toml::array* a = n ? n->as_array() : nullptr;
  return a && i < a->size() ? a->get(i) : nullptr;
}

std::vector<TableReader> TableReader::tables(const std::string& k) const {
  const toml::node* n = table_.get(k);
  if (n == nullptr) return {};
  const toml::array* a = n->as_array();
  if (a == nullptr) fail(k, "an array of tables ([[" + key(k) + "]])", io::describe_toml(*n));
  std::vector<TableReader> out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::node& e = *a->get(i);
    if (!e.is_table()) fail(fmt::format("{}[{}]", k, i), "a table", io::describe_toml(e), &e);
    out.emplace_back(*e.as_table(), file_, fmt::format("{}[{}]", key(k), i));
  }
  return out;
}

std::optional<TableReader> TableReader::sub(const std::string& k) const {
  const toml::node* n = table_.get(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_table()) fail(k, "a table", io::describe_toml(*n));
  return TableReader(*n->as_table(), file_, key(k));
}

}  // namespace piezobench::station::detail
