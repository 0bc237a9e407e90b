#pragma once
// The documents' JSON of a declared struct (core/fields.hpp): results.json's view of it.
//
// results_object(s) holds every field of s's declaration that appears in results.json, under its
// results key (core::results_key: `name_UNIT` unless the entry names another key; a dotted key such
// as "readings_um.before" nests; the key "." merges a nested struct into its parent), each number
// converted once from SI to the shown unit. The one encoding of values: non-finite numbers as the
// strings "nan", "inf", "-inf" (to_json below), complex numbers as [re, im], an absent optional as
// null (a derived field's nullptr too), enums by their module's to_string, a list of (text, value) pairs as an object.
#include <Eigen/Core>
#include <array>
#include <complex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "piezobench/core/field_types.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/io/json.hpp"

namespace piezobench::io {

namespace fields_detail {
// Puts `value` at the dotted `key` of `object` ("." merges an object into it; null merges nothing).
void put(nlohmann::json& object, std::string_view key, nlohmann::json value);
}  // namespace fields_detail

template <class T> nlohmann::json results_object(const T& s);

// Rewrites every non-finite number of `document` (raw NaN would be dumped as null) as the string
// "nan", "inf" or "-inf": the one encoding, applied to a whole document before it is written.
void name_non_finite(nlohmann::json& document);

// One value in the shown unit: its numbers times per_si, the dimensionless factor from SI to the
// shown unit (core::Shown::per_si; 1 keeps SI).
template <class T> nlohmann::json shown_json(const T& v, double per_si = 1.0) {
  if constexpr (std::is_same_v<T, double> || std::is_same_v<T, float>) {
    return to_json(static_cast<double>(v) * per_si);
  } else if constexpr (std::is_same_v<T, bool> || std::is_integral_v<T> || std::is_same_v<T, std::string>) {
    return v;
  } else if constexpr (std::is_enum_v<T>) {
    return to_string(v);
  } else if constexpr (std::is_same_v<T, std::complex<double>>) {
    return to_json(v * per_si);
  } else if constexpr (std::is_same_v<T, core::ParameterUncertainty>) {
    return to_json(v);
  } else if constexpr (core::kIsOptional<T> || std::is_pointer_v<T>) {
    return v ? shown_json(*v, per_si) : nlohmann::json(nullptr);
  } else if constexpr (core::kIsPairList<T>) {
    nlohmann::json o = nlohmann::json::object();
    for (const auto& [k, x] : v) o[k] = shown_json(x, per_si);
    return o;
  } else if constexpr (core::kIsVector<T> || core::kIsStdArray<T>) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& x : v) a.push_back(shown_json(x, per_si));
    return a;
  } else if constexpr (core::kIsEigen<T>) {
    nlohmann::json a = nlohmann::json::array();
    for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(shown_json(v(i), per_si));
    return a;
  } else {
    return results_object(v);
  }
}

template <class T> nlohmann::json results_object(const T& s) {
  static_assert(core::Described<T>, "results.json writes the structs with a field declaration (core/fields.hpp)");
  nlohmann::json o = nlohmann::json::object();
  core::for_each_field<T>([&](const auto& f) {
    if (f.in(core::kResults)) fields_detail::put(o, core::results_key(f), shown_json(f.of(s), f.shown.per_si));
  });
  return o;
}

}  // namespace piezobench::io
