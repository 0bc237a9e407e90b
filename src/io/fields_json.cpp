#include "piezobench/io/fields_json.hpp"

#include <cmath>

namespace piezobench::io {

void name_non_finite(nlohmann::json& document) {
  if (document.is_number_float()) {
    const double v = document.get<double>();
    if (!std::isfinite(v)) document = to_json(v);
  } else if (document.is_structured()) {
    for (auto& x : document) name_non_finite(x);
  }
}

}  // namespace piezobench::io

namespace piezobench::io::fields_detail {

void put(nlohmann::json& object, std::string_view key, nlohmann::json value) {
  if (key == ".") {
    if (value.is_object()) object.update(value);
    return;
  }
  const std::size_t dot = key.find('.');
  if (dot == std::string_view::npos) {
    object[std::string(key)] = std::move(value);
    return;
  }
  nlohmann::json& inner = object[std::string(key.substr(0, dot))];
  if (!inner.is_object()) inner = nlohmann::json::object();
  put(inner, key.substr(dot + 1), std::move(value));
}

}  // namespace piezobench::io::fields_detail
