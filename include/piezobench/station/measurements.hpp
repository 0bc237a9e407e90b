#pragma once
// Measurements with validators (docs/station.md): every phase of a qualification produces named
// measurements, each a figure of the campaign's per-unit analysis (campaign/unit_analysis.hpp) in
// a fixed unit, checked against the station file's limits with a verdict.
//
// Verdicts are ordered pass < marginal < fail, and the verdict of a phase, a unit or a batch is the
// worst of its parts. Marginal: a limit lies within value +- U, U the measurement's uncertainty,
// decided by the campaign's rule (metrology::decide, ISO 14253-1). The station's measurements do not
// carry their budgets yet: U = margin_relative x |limit| (the station file's `margin_relative`,
// default 1 %), documented in docs/station.md.
#include <optional>
#include <string>
#include <vector>

#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/results.hpp"

namespace piezobench::station {

enum class Verdict { kPass = 0, kMarginal = 1, kFail = 2 };
std::string to_string(Verdict v);                  // "pass", "marginal", "fail"
Verdict verdict_from_string(const std::string& s); // InputError for anything else
Verdict worst(Verdict a, Verdict b);

struct Limit {
  std::optional<double> min, max;  // in the measurement's unit; absent: not checked
};

// One entry of the catalog: what a phase of an experiment can measure.
struct MeasurementKind {
  std::string name;         // "stroke_um"
  std::string unit;         // "um"
  campaign::Experiment experiment;
  std::string description;  // "stroke (max - min of d_e)"
};
// Every measurement the station knows, by experiment (docs/station.md lists them).
const std::vector<MeasurementKind>& measurement_catalog();
// nullptr when `name` is not in the catalog.
const MeasurementKind* find_measurement(const std::string& name);

struct MeasuredValue {
  std::string name, unit;
  // same unit as `unit` names.
  std::optional<double> value;  // nullopt: the analysis gave none (failed, or not observable)
  Limit limit;
  Verdict verdict = Verdict::kPass;
  std::string reason;           // the sentence behind a marginal or fail verdict, "" on pass
};

// The value of measurement `name` in a unit's analysis; `file` (as given in the campaign) picks
// the record of a multi-file experiment (a hysteresis amplitude, an IFF gain). nullopt when the
// analysis has none.
std::optional<double> measured_value(const campaign::UnitAnalysis& unit, const std::string& name, const std::string& file);

// The verdict of `value` against `limit` with the margin (U = margin_relative |limit|): fail when
// the value is outside a limit by more than U, marginal when a limit is within value +- U, pass
// otherwise; no value at all fails.
MeasuredValue judge(const MeasurementKind& kind, std::optional<double> value, const Limit& limit, double margin_relative);

}  // namespace piezobench::station
