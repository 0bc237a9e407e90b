#pragma once
// The report's parameter tables (campaign-private): a result struct's columns and cells are the
// fields its declaration marks `.in_report()` (core/fields.hpp), headed by name and shown unit
// (core::report_heading) and converted once from SI to that unit (io::shown_json). report_document.cpp
// builds every parameter table with them; a test adds a test-only declared struct and finds its
// field in the table (tests/campaign).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"
#include "piezobench/io/fields_json.hpp"

namespace piezobench::campaign {

// Appends the headings of S's report fields, in declaration order.
template <class S> void report_columns(std::vector<std::string>& columns) {
  core::for_each_field<S>([&](const auto& f) {
    if (f.in(core::kReport)) columns.push_back(core::report_heading(f));
  });
}

// Appends s's report fields in their shown units (non-finite numbers as "nan", "inf", "-inf").
template <class S> void report_cells(nlohmann::json& row, const S& s) {
  core::for_each_field<S>([&](const auto& f) {
    if (f.in(core::kReport)) row.push_back(io::shown_json(f.of(s), f.shown.per_si));
  });
}

}  // namespace piezobench::campaign
