#include "piezobench/io/mat_struct.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "mat_file.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::io {

using detail::make_logical;
using detail::make_matrix;
using detail::MatValue;
using json = nlohmann::json;

void MatStructOptions::validate() const {
  if (!variable.empty() && !detail::is_matlab_identifier(variable)) {
    throw InputError("mat options", "variable", "a MATLAB identifier (letter, then letters, digits, '_')",
                     "'" + variable + "'");
  }
}

std::string matlab_field_name(const std::string& key) {
  std::string name;
  for (const char c : key) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    name += ok ? c : '_';
  }
  if (name.empty() || !((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= 'A' && name[0] <= 'Z'))) name = "x" + name;
  if (name.size() > 63) name.resize(63);
  return name;
}

namespace {

// The MATLAB names of an object's keys, unique, in key order.
std::vector<std::string> field_names(const json& object) {
  std::vector<std::string> names;
  std::set<std::string> used;
  for (const auto& item : object.items()) {
    const std::string base = matlab_field_name(item.key());
    std::string name = base;
    for (int k = 2; used.count(name) > 0; ++k) {
      std::string suffix(1, '_');
      suffix += std::to_string(k);
      name.assign(base, 0, std::min(base.size(), 63 - suffix.size()));
      name.append(suffix);
    }
    used.insert(name);
    names.push_back(name);
  }
  return names;
}

// A number, or null / "nan" / "inf" / "-inf" as non-finite values; nullopt for anything else.
std::optional<double> as_number(const json& v) {
  if (v.is_number()) return v.get<double>();
  if (v.is_null()) return std::numeric_limits<double>::quiet_NaN();
  if (v.is_string()) {
    const auto& s = v.get_ref<const std::string&>();
    if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
  }
  return std::nullopt;
}

MatValue build(const json& v, const std::string& name);

MatValue build_struct_array(const std::vector<const json*>& objects, const std::string& name) {
  // The union of the keys (a JSON object keeps its keys sorted).
  json ordered = json::object();
  for (const json* o : objects) {
    for (const auto& item : o->items()) ordered[item.key()] = nullptr;
  }
  const std::vector<std::string> names = field_names(ordered);
  std::map<std::string, std::string> field_of;
  {
    std::size_t i = 0;
    for (const auto& item : ordered.items()) field_of[item.key()] = names[i++];
  }
  MatValue var(name, MAT_C_STRUCT, {1, objects.size()});
  var.field_names = names;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    for (const auto& item : ordered.items()) {
      const std::string& field = field_of[item.key()];
      const json* value = objects[i]->contains(item.key()) ? &(*objects[i])[item.key()] : &item.value();  // null -> []
      var.items.push_back(build(*value, field));
    }
  }
  return var;
}

MatValue build_cell(const json& array, const std::string& name) {
  MatValue var(name, MAT_C_CELL, {1, array.size()});
  for (const json& item : array) var.items.push_back(build(item, name));
  return var;
}

MatValue build_array(const json& a, const std::string& name) {
  if (a.empty()) return make_matrix(name, 0, 0, {});
  // Numbers (with non-finite stand-ins), not all of them stand-ins.
  {
    std::vector<double> values;
    bool real_number = false;
    for (const auto& x : a) {
      const auto d = as_number(x);
      if (!d) break;
      real_number = real_number || x.is_number();
      values.push_back(*d);
    }
    if (values.size() == a.size() && real_number) {
      const std::size_t n = values.size();
      return make_matrix(name, 1, n, std::move(values));
    }
  }
  if (std::all_of(a.begin(), a.end(), [](const json& x) { return x.is_boolean(); })) {
    std::vector<unsigned char> values;
    for (const auto& x : a) values.push_back(x.get<bool>() ? 1 : 0);
    return make_logical(name, values);
  }
  // Rows of numbers of equal length: a matrix.
  if (std::all_of(a.begin(), a.end(), [&](const json& x) { return x.is_array() && !x.empty() && x.size() == a.front().size(); })) {
    const std::size_t rows = a.size();
    const std::size_t cols = a.front().size();
    std::vector<double> data(rows * cols);
    bool ok = true;
    for (std::size_t i = 0; i < rows && ok; ++i) {
      for (std::size_t j = 0; j < cols && ok; ++j) {
        const auto d = as_number(a[i][j]);
        ok = d.has_value();
        if (ok) data[j * rows + i] = *d;  // column-major
      }
    }
    if (ok) return make_matrix(name, rows, cols, std::move(data));
  }
  // Objects: a struct array with the union of their keys (a key an element lacks is [] there).
  if (std::all_of(a.begin(), a.end(), [](const json& x) { return x.is_object(); }) &&
      std::any_of(a.begin(), a.end(), [](const json& x) { return !x.empty(); })) {
    std::vector<const json*> objects;
    for (const auto& o : a) objects.push_back(&o);
    return build_struct_array(objects, name);
  }
  return build_cell(a, name);
}

MatValue build(const json& v, const std::string& name) {
  switch (v.type()) {
    case json::value_t::object: {
      if (v.empty()) return MatValue(name, MAT_C_STRUCT, {1, 1});
      return build_struct_array({&v}, name);
    }
    case json::value_t::array: return build_array(v, name);
    case json::value_t::boolean: return make_logical(name, {static_cast<unsigned char>(v.get<bool>() ? 1 : 0)});
    case json::value_t::null: return make_matrix(name, 0, 0, {});
    case json::value_t::string: {
      if (const auto d = as_number(v)) return make_matrix(name, 1, 1, {*d});
      return detail::make_text(name, v.get<std::string>());
    }
    default: return make_matrix(name, 1, 1, {v.get<double>()});  // numbers
  }
}

}  // namespace

void write_json_as_mat(const json& document, const std::filesystem::path& file, const MatStructOptions& options) {
  options.validate();
  if (!document.is_object()) {
    throw InputError(file.string(), "document", "a JSON object", std::string("a JSON ") + document.type_name());
  }
  std::vector<MatValue> vars;
  try {
    if (!options.variable.empty()) {
      vars.push_back(build(document, options.variable));
    } else {
      const std::vector<std::string> names = field_names(document);
      std::size_t i = 0;
      for (const auto& item : document.items()) vars.push_back(build(item.value(), names[i++]));
    }
  } catch (const InputError& e) {
    throw e.with_source(file.string());
  }
  detail::write_mat_atomically(file, options.version == MatVersion::kV73, options.compress && options.version == MatVersion::kV5,
                               [&](detail::MatWriter& w) {
                                 for (const auto& v : vars) w.write(v);
                               });
}

}  // namespace piezobench::io
