#pragma once
// part.json's codec (campaign-private): every struct is written and read through its field
// declaration (core/fields.hpp, beside the struct): one list serves both directions, so the reader is
// the writer's inverse by construction. part.cpp writes and reads units with it; a test adds a
// test-only declared struct and finds its fields here as part.json holds them (tests/campaign).
//
// encode(v): SI values as part.json holds them (a declared struct as an object of its member
// fields by name; derived fields left out; non-finite numbers as "nan", "inf", "-inf"; enums by
// their module's name; complex as [re, im]; an absent optional as null).
// decode(j, v, where): the inverse; a value of the wrong shape is an InputError naming the file and
// the dotted path of the field, what was expected and what was found.
#include <Eigen/Core>
#include <fmt/format.h>

#include <complex>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "piezobench/campaign/results.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/field_types.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/io/json.hpp"

namespace piezobench::campaign::part_codec {

using nlohmann::json;

// Where a value is read: the file and the dotted path of the field.
struct Where {
  std::string file, path;
  [[nodiscard]] Where key(const std::string& k) const { return {file, path.empty() ? k : path + "." + k}; }
  [[nodiscard]] Where index(std::size_t i) const { return {file, fmt::format("{}[{}]", path, i)}; }
};

[[noreturn]] inline void bad(const Where& w, const std::string& expected, const json& found) {
  std::string f = found.dump();
  if (f.size() > 80) f = f.substr(0, 77) + "...";
  throw InputError(w.file, w.path, expected, f);
}

using core::kIsComplex, core::kIsEigen, core::kIsOptional, core::kIsPair, core::kIsStdArray, core::kIsVector;

// The enums, by the names their modules give them.
#define PIEZOBENCH_PART_ENUM(Type, label, parse)                                   \
  inline std::string enum_name(Type v) { return to_string(v); }                   \
  inline void enum_parse(const std::string& s, Type& v) { v = parse(s); }         \
  inline const char* enum_label(Type) { return label; }
PIEZOBENCH_PART_ENUM(metrology::FlatnessMethod, "flatness method", [](const std::string& name) { return metrology::flatness_method_from_string(name); })
PIEZOBENCH_PART_ENUM(ident::PhaseVerdict, "phase verdict", ident::phase_verdict_from_string)
PIEZOBENCH_PART_ENUM(ident::Convergence, "vector fitting convergence", ident::convergence_from_string)
PIEZOBENCH_PART_ENUM(core::LmStatus, "Levenberg-Marquardt status", core::lm_status_from_string)
PIEZOBENCH_PART_ENUM(core::FitVerdict, "fit verdict", core::fit_verdict_from_string)
PIEZOBENCH_PART_ENUM(apa::TuningStatus, "tuning status", apa::tuning_status_from_string)
PIEZOBENCH_PART_ENUM(metrology::Conformity, "conformity verdict", metrology::conformity_from_string)
#undef PIEZOBENCH_PART_ENUM

template <class T> json encode(const T& v);
template <class T> void decode(const json& j, T& v, const Where& w);

struct PartReader {
  const json& in;
  Where where;
  template <class T> void operator()(const char* key, T& v) {
    const Where w = where.key(key);
    if (!in.contains(key)) throw InputError(w.file, w.path, "present", "missing");
    decode(in[key], v, w);
  }
};

template <class T> json encode(const T& v) {
  if constexpr (std::is_same_v<T, double>) {
    return io::to_json(v);
  } else if constexpr (std::is_same_v<T, bool> || std::is_integral_v<T> || std::is_same_v<T, std::string>) {
    return v;
  } else if constexpr (std::is_enum_v<T>) {
    return enum_name(v);
  } else if constexpr (kIsComplex<T>) {
    return json::array({encode(v.real()), encode(v.imag())});
  } else if constexpr (kIsOptional<T>) {
    return v ? encode(*v) : json(nullptr);
  } else if constexpr (kIsVector<T> || kIsStdArray<T>) {
    json a = json::array();
    for (const auto& x : v) a.push_back(encode(x));
    return a;
  } else if constexpr (kIsPair<T>) {
    return json::array({encode(v.first), encode(v.second)});
  } else if constexpr (kIsEigen<T>) {
    json a = json::array();
    if constexpr (T::ColsAtCompileTime == 1) {
      for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(encode(v(i)));
    } else {
      for (Eigen::Index r = 0; r < v.rows(); ++r) {
        json row = json::array();
        for (Eigen::Index c = 0; c < v.cols(); ++c) row.push_back(encode(v(r, c)));
        a.push_back(row);
      }
    }
    return a;
  } else {
    static_assert(core::Described<T>, "part.json writes the structs with a field declaration (core/fields.hpp)");
    json o = json::object();
    core::for_each_field<T>([&](const auto& f) {
      if constexpr (!std::remove_cvref_t<decltype(f)>::kDerived) o[std::string(f.name)] = encode(f.of(v));
    });
    return o;
  }
}

template <class T> void decode(const json& j, T& v, const Where& w) {
  if constexpr (std::is_same_v<T, double>) {
    if (j.is_number()) {
      v = j.get<double>();
    } else if (j == "nan") {
      v = std::numeric_limits<double>::quiet_NaN();
    } else if (j == "inf" || j == "-inf") {
      v = (j == "inf" ? 1.0 : -1.0) * std::numeric_limits<double>::infinity();
    } else {
      bad(w, "a number (or \"nan\", \"inf\", \"-inf\")", j);
    }
  } else if constexpr (std::is_same_v<T, bool>) {
    if (!j.is_boolean()) bad(w, "true or false", j);
    v = j.get<bool>();
  } else if constexpr (std::is_integral_v<T>) {
    if (!j.is_number_integer()) bad(w, "an integer", j);
    v = j.get<T>();
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!j.is_string()) bad(w, "a string", j);
    v = j.get<std::string>();
  } else if constexpr (std::is_enum_v<T>) {
    if (!j.is_string()) bad(w, std::string("a ") + enum_label(v) + " name", j);
    try {
      enum_parse(j.get<std::string>(), v);
    } catch (const InputError&) {
      bad(w, std::string("a ") + enum_label(v) + " name", j);
    }
  } else if constexpr (kIsComplex<T>) {
    if (!j.is_array() || j.size() != 2) bad(w, "a complex number [re, im]", j);
    double re = 0.0, im = 0.0;
    decode(j[0], re, w.index(0));
    decode(j[1], im, w.index(1));
    v = T(re, im);
  } else if constexpr (kIsOptional<T>) {
    if (j.is_null()) {
      v.reset();
    } else {
      v = typename T::value_type{};  // not emplace(): clang 14 takes NmpEvidence::Zero for not default-constructible
      decode(j, *v, w);
    }
  } else if constexpr (kIsVector<T>) {
    if (!j.is_array()) bad(w, "a list", j);
    v.clear();
    v.resize(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) decode(j[i], v[i], w.index(i));
  } else if constexpr (kIsStdArray<T>) {
    if (!j.is_array() || j.size() != v.size()) bad(w, fmt::format("a list of {}", v.size()), j);
    for (std::size_t i = 0; i < v.size(); ++i) decode(j[i], v[i], w.index(i));
  } else if constexpr (kIsPair<T>) {
    if (!j.is_array() || j.size() != 2) bad(w, "a pair [first, second]", j);
    decode(j[0], v.first, w.index(0));
    decode(j[1], v.second, w.index(1));
  } else if constexpr (kIsEigen<T>) {
    if (!j.is_array()) bad(w, "a list", j);
    const auto n = static_cast<Eigen::Index>(j.size());
    if constexpr (T::ColsAtCompileTime == 1) {
      v.resize(n);
      for (Eigen::Index i = 0; i < n; ++i) decode(j[i], v(i), w.index(i));
    } else {
      const Eigen::Index cols = n > 0 && j[0].is_array() ? static_cast<Eigen::Index>(j[0].size()) : 0;
      v.resize(n, cols);
      for (Eigen::Index r = 0; r < n; ++r) {
        const Where wr = w.index(r);
        if (!j[r].is_array() || static_cast<Eigen::Index>(j[r].size()) != cols) bad(wr, fmt::format("a row of {} values", cols), j[r]);
        for (Eigen::Index c = 0; c < cols; ++c) decode(j[r][c], v(r, c), wr.index(c));
      }
    }
  } else {
    static_assert(core::Described<T>, "part.json reads the structs with a field declaration (core/fields.hpp)");
    if (!j.is_object()) bad(w, "an object", j);
    PartReader r{j, w};
    core::for_each_field<T>([&](const auto& f) {
      if constexpr (!std::remove_cvref_t<decltype(f)>::kDerived) r(std::string(f.name).c_str(), f.of(v));
    });
  }
}

}  // namespace piezobench::campaign::part_codec
