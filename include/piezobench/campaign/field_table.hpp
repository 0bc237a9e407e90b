#pragma once
// docs/fields.md's tables: one markdown table per declared result struct, derived from its
// declaration (core/fields.hpp): each field's name, type, SI unit, shown unit with its factor,
// results.json key, meaning and where it appears. campaign::field_reference_markdown writes the
// document with them, and the program (app/field_reference.cpp, which sees every module) adds the
// tables of the modules campaign does not depend on (rt); a test adds a test-only declared struct
// and finds its field's row (tests/campaign).
#include <fmt/format.h>

#include <set>
#include <string>
#include <string_view>
#include <type_traits>

#include "piezobench/core/fields.hpp"

namespace piezobench::campaign {

namespace field_table_detail {
inline std::string shown_cell(const core::Shown& s) {
  if (s.unit.empty() || s.per_si == 1.0) return std::string(s.unit);
  return fmt::format("{} (SI x {:g})", s.unit, s.per_si);
}

// A table cell's text: "|" (as in "|H|") escaped, so that it does not end the cell.
inline std::string cell(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

template <class F> std::string results_cell(const F& f) {
  if (!f.in(core::kResults)) return F::kDerived ? "(not in results.json)" : "(part.json only)";
  const std::string key = core::results_key(f);
  return key == "." ? "(merged into its parent)" : "`" + key + "`";
}

}  // namespace field_table_detail

// Appends S's table to `out`, then one for each described struct its fields hold, each struct once
// (`done`: the names of the structs already documented).
template <class S> void field_table(std::string& out, std::set<std::string>& done) {
  constexpr auto& d = core::kFields<S>;
  if (!done.insert(std::string(d.name)).second) return;
  out += fmt::format("\n## {}\n\n{}.\n\n| field | type | SI | shown | results.json | meaning |\n|---|---|---|---|---|---|\n", d.name, d.meaning);
  core::for_each_field<S>([&](const auto& f) {
    using E = core::element_t<typename std::remove_cvref_t<decltype(f)>::Member>;
    std::string type;
    if constexpr (core::Described<E>) type = std::string(core::kFields<E>.name);
    out += fmt::format("| `{}` | {} | {} | {} | {} | {}{}{} |\n", f.name, type, f.shown.si, field_table_detail::shown_cell(f.shown), field_table_detail::results_cell(f), field_table_detail::cell(f.meaning),
                       f.in(core::kReport) ? " (report table)" : "",
                       std::remove_cvref_t<decltype(f)>::kDerived ? " (derived: read from its analysis, not in part.json)" : "");
  });
  core::for_each_field<S>([&](const auto& f) {
    using E = core::element_t<typename std::remove_cvref_t<decltype(f)>::Member>;
    if constexpr (core::Described<E>) field_table<E>(out, done);
  });
}

}  // namespace piezobench::campaign
