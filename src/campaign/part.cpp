#include "piezobench/campaign/part.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <type_traits>
#include <utility>

#include "piezobench/core/error.hpp"
#include "piezobench/core/field_types.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/version.hpp"

namespace piezobench::campaign {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kFormat = "piezobench campaign part";

// ------------------------------------------------------------------------------------ encoding
// Every struct is written and read through its field declaration (core/fields.hpp, beside the
// struct): one list serves both directions, so the reader is the writer's inverse by construction.

// Where a value is read: the file and the dotted path of the field.
struct Where {
  std::string file, path;
  [[nodiscard]] Where key(const std::string& k) const { return {file, path.empty() ? k : path + "." + k}; }
  [[nodiscard]] Where index(std::size_t i) const { return {file, fmt::format("{}[{}]", path, i)}; }
};

[[noreturn]] void bad(const Where& w, const std::string& expected, const json& found) {
  std::string f = found.dump();
  if (f.size() > 80) f = f.substr(0, 77) + "...";
  throw InputError(w.file, w.path, expected, f);
}

using core::kIsComplex, core::kIsEigen, core::kIsOptional, core::kIsPair, core::kIsStdArray, core::kIsVector;

// The enums, by the names their modules give them.
#define PIEZOBENCH_PART_ENUM(Type, label, parse)                                   \
  std::string enum_name(Type v) { return to_string(v); }                          \
  void enum_parse(const std::string& s, Type& v) { v = parse(s); }                \
  const char* enum_label(Type) { return label; }
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

std::string generator() { return std::string("piezobench ") + kVersion; }

std::string units_text(const std::vector<int>& ids) {
  std::string s;
  for (const int id : ids) s += (s.empty() ? "" : ", ") + std::to_string(id);
  return s;
}

}  // namespace

// ------------------------------------------------------------------------------------ public

std::string campaign_hash(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "campaign", "a readable campaign file", "cannot be opened");
  std::uint64_t h = 14695981039346656037ULL;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 1099511628211ULL;
    }
  }
  return fmt::format("fnv1a64:{:016x}", h);
}

std::vector<std::size_t> part_indices(const Campaign& c, int k, int n) {
  if (n < 1 || k < 1 || k > n) throw InputError("", "--part", "K/N with 1 <= K <= N", fmt::format("{}/{}", k, n));
  std::vector<std::size_t> out;
  for (std::size_t i = static_cast<std::size_t>(k - 1); i < c.units.size(); i += static_cast<std::size_t>(n)) out.push_back(i);
  return out;
}

std::vector<std::size_t> unit_indices(const Campaign& c, const std::vector<int>& ids, const std::string& option) {
  std::vector<int> all;
  for (const auto& u : c.units) all.push_back(u.id);
  for (const int id : ids) {
    if (std::find(all.begin(), all.end(), id) == all.end()) {
      throw InputError(c.file.string(), option, "unit ids of the campaign (" + units_text(all) + ")", std::to_string(id));
    }
  }
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < c.units.size(); ++i) {
    if (std::find(ids.begin(), ids.end(), c.units[i].id) != ids.end()) out.push_back(i);
  }
  return out;
}

json typed_unit_json(const UnitAnalysis& unit) { return encode(unit); }

UnitAnalysis typed_unit_from_json(const json& j, const std::string& source, const std::string& path) {
  UnitAnalysis u;
  decode(j, u, Where{source, path});
  return u;
}

json part_json(const Campaign& c, const std::vector<UnitAnalysis>& units) {
  json ids = json::array();
  for (const auto& u : c.units) ids.push_back(u.id);
  json list = json::array();
  for (const auto& u : units) list.push_back(typed_unit_json(u));
  return {{"format", kFormat},
          {"format_version", kPartFormatVersion},
          {"generator", generator()},
          {"campaign", c.file.string()},
          {"campaign_path", fs::absolute(c.file).lexically_normal().string()},
          {"campaign_hash", campaign_hash(c.file)},
          {"campaign_units", ids},
          {"units", list}};
}

fs::path write_part(const Campaign& c, const std::vector<UnitAnalysis>& units, const fs::path& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir)) {
    throw InputError(out_dir.string(), "--out", "a folder that can be created", ec ? ec.message() : "not a folder");
  }
  const fs::path file = out_dir / "part.json";
  io::write_text_atomically(file, part_json(c, units).dump() + "\n");
  return file;
}

CampaignPart read_part(const fs::path& path) {
  const fs::path file = fs::is_directory(path) ? path / "part.json" : path;
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    throw InputError(path.string(), "part.json", "a partial result of `piezobench run --part K/N` or `--units LIST`",
                     fs::exists(path) ? "no part.json in it" : "no such file or folder");
  }
  std::ostringstream text;
  text << in.rdbuf();
  json doc;
  try {
    doc = json::parse(text.str());
  } catch (const json::exception& e) {
    throw InputError(name, "", "a JSON document (part.json)", e.what());
  }
  const Where top{name, ""};
  if (!doc.is_object() || !doc.contains("format") || doc["format"] != kFormat) {
    throw InputError(name, "format", fmt::format("\"{}\" (a part.json of `piezobench run --part/--units`)", kFormat),
                     doc.is_object() && doc.contains("format") ? doc["format"].dump() : "no format key");
  }
  int version = 0;
  PartReader r{doc, top};
  r("format_version", version);
  if (version != kPartFormatVersion) throw InputError(name, "format_version", std::to_string(kPartFormatVersion), std::to_string(version));
  CampaignPart p;
  p.file = file;
  r("generator", p.generator);
  if (p.generator != generator()) {
    throw InputError(name, "generator", generator() + " (parts are merged by the program that wrote them)", p.generator);
  }
  std::string campaign_path;
  r("campaign", p.campaign);
  r("campaign_path", campaign_path);
  p.campaign_path = campaign_path;
  r("campaign_hash", p.campaign_hash);
  r("campaign_units", p.campaign_units);
  r("units", p.units);
  return p;
}

std::vector<UnitAnalysis> merge_parts(const Campaign& c, const std::vector<CampaignPart>& parts) {
  const std::string campaign_file = c.file.string();
  const std::string hash = campaign_hash(c.file);
  std::map<int, std::pair<const UnitAnalysis*, const CampaignPart*>> found;
  for (const CampaignPart& p : parts) {
    const std::string name = p.file.string();
    if (p.campaign_hash != hash) {
      throw InputError(name, "campaign_hash",
                       fmt::format("{} (campaign {} as it is now)", hash, campaign_file),
                       fmt::format("{} (campaign {}): a part of another campaign, or of this file before it changed", p.campaign_hash, p.campaign));
    }
    for (std::size_t i = 0; i < p.units.size(); ++i) {
      const UnitAnalysis& u = p.units[i];
      const bool known = std::any_of(c.units.begin(), c.units.end(), [&](const UnitSpec& s) { return s.id == u.id; });
      if (!known) throw InputError(name, fmt::format("units[{}].id", i), "a unit of campaign " + campaign_file, std::to_string(u.id));
      const auto [it, inserted] = found.emplace(u.id, std::pair{&u, &p});
      if (!inserted) {
        throw InputError(name, fmt::format("units[{}].id", i), "a unit no other part holds",
                         fmt::format("unit {} ({}), also in {}", u.id, u.name, it->second.second->file.string()));
      }
    }
  }
  std::vector<UnitAnalysis> out;
  std::vector<int> missing;
  for (const UnitSpec& s : c.units) {
    const auto it = found.find(s.id);
    if (it == found.end()) {
      missing.push_back(s.id);
    } else {
      out.push_back(*it->second.first);
    }
  }
  if (!missing.empty()) {
    throw InputError(campaign_file, "units", fmt::format("every unit of the campaign in one of the {} parts", parts.size()),
                     fmt::format("unit{} {} in none of them", missing.size() > 1 ? "s" : "", units_text(missing)));
  }
  return out;
}

}  // namespace piezobench::campaign
