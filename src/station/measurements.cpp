#include "piezobench/station/measurements.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <type_traits>

#include "piezobench/core/error.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/metrology/conformity.hpp"

namespace piezobench::station {

using campaign::Experiment;

std::string to_string(Verdict v) {
  switch (v) {
    case Verdict::kPass: return "pass";
    case Verdict::kMarginal: return "marginal";
    case Verdict::kFail: return "fail";
  }
  return "fail";
}

Verdict verdict_from_string(const std::string& s) {
  for (const Verdict v : {Verdict::kPass, Verdict::kMarginal, Verdict::kFail}) {
    if (to_string(v) == s) return v;
  }
  throw InputError("verdict", "verdict", "pass, marginal or fail", "'" + s + "'");
}

Verdict worst(Verdict a, Verdict b) { return static_cast<int>(a) >= static_cast<int>(b) ? a : b; }

namespace {

using campaign::UnitAnalysis;
using Si = std::optional<double>;
// A measurement's value in SI from a unit's analysis; `file` picks the record of a multi-file experiment.
using Reader = std::function<Si(const UnitAnalysis&, const std::string& file)>;

// The shown unit of a declared member (core/fields.hpp): the catalog's units and factors are the
// declaration's, not written again here.
template <class S, class M> core::Shown shown_of(M S::*member) { return core::declared<S>(member).shown; }

struct Entry {
  MeasurementKind kind;
  double per_si = 1.0;
  Reader read;
};

Entry entry(std::string name, Experiment experiment, std::string description, const core::Shown& shown, Reader read) {
  return {{std::move(name), shown.unit.empty() ? "1" : std::string(shown.unit), experiment, std::move(description)}, shown.per_si,
          std::move(read)};
}

// A number of UnitAnalysis's declaration (core/fields.hpp; a derived field, read from its analysis):
// the measurement's name, unit and description are the declaration's results key, shown unit and meaning.
Entry unit_entry(Experiment e, Si (*value)(const UnitAnalysis&)) {
  const core::Declared d = core::declared<UnitAnalysis>(value);
  return entry(core::results_key(d.name, d.shown), e, std::string(d.meaning), d.shown,
               [value](const UnitAnalysis& u, const std::string&) { return value(u); });
}

template <class Item, class Pick>
Si first_of(const std::vector<Item>& items, const std::string& file, const std::string Item::*file_of, Pick pick) {
  for (const Item& x : items) {
    if (!file.empty() && x.*file_of != file) continue;
    return pick(x);
  }
  return std::nullopt;
}

Si hysteresis_pick(const UnitAnalysis& u, const std::string& file, double metrology::HysteresisResult::*member) {
  for (const campaign::HysteresisLoop& h : u.hysteresis) {
    if (!file.empty() && h.provenance.file != file) continue;
    return h.result.*member;
  }
  return std::nullopt;
}

Si damped_pick(const UnitAnalysis& u, const std::string& file, double ident::DominantPole::*member) {
  return first_of(u.damped, file, &campaign::DampedPlant::file,
                  [&](const campaign::DampedPlant& d) { return d.identified ? Si((*d.identified).*member) : std::nullopt; });
}

const std::vector<Entry>& catalog() {
  static const std::vector<Entry> entries = {
      unit_entry(Experiment::kFlatness, &campaign::flatness_of),
      unit_entry(Experiment::kCapacitance, &campaign::capacitance_sensor_of),
      unit_entry(Experiment::kCapacitance, &campaign::capacitance_actuator_of),
      unit_entry(Experiment::kStroke, &campaign::stroke_of),
      unit_entry(Experiment::kStroke, &campaign::sensitivity_of),
      entry("hysteresis_relative_width", Experiment::kHysteresis, "loop width at the offset / loop stroke",
            shown_of(&metrology::HysteresisResult::relative_width),
            [](const UnitAnalysis& u, const std::string& f) { return hysteresis_pick(u, f, &metrology::HysteresisResult::relative_width); }),
      entry("hysteresis_width_um", Experiment::kHysteresis, "loop width at the offset", shown_of(&metrology::HysteresisResult::width),
            [](const UnitAnalysis& u, const std::string& f) { return hysteresis_pick(u, f, &metrology::HysteresisResult::width); }),
      unit_entry(Experiment::kStiffness, &campaign::k1_of),
      unit_entry(Experiment::kStiffness, &campaign::k2_of),
      unit_entry(Experiment::kStiffnessOpen, &campaign::k_oc_of),
      unit_entry(Experiment::kFrf, &campaign::resonance_Hz_of),
      unit_entry(Experiment::kFrf, &campaign::antiresonance_Hz_of),
      unit_entry(Experiment::kFrf, &campaign::resonance_damping_of),
      unit_entry(Experiment::kFrf, &campaign::k_resonance_of),
      unit_entry(Experiment::kFrf, &campaign::static_gain_of),
      unit_entry(Experiment::kFrf, &campaign::hpf_corner_Hz_of),
      unit_entry(Experiment::kFrfNoResistor, &campaign::hpf_corner_without_resistor_Hz_of),
      entry("damped_damping", Experiment::kIff, "damping ratio of the identified damped pole", shown_of(&ident::DominantPole::damping),
            [](const UnitAnalysis& u, const std::string& f) { return damped_pick(u, f, &ident::DominantPole::damping); }),
      entry("damped_frequency_Hz", Experiment::kIff, "frequency of the identified damped pole", shown_of(&ident::DominantPole::natural_frequency),
            [](const UnitAnalysis& u, const std::string& f) { return damped_pick(u, f, &ident::DominantPole::natural_frequency); }),
      unit_entry(Experiment::kHammer, &campaign::first_mode_Hz_of),
      unit_entry(Experiment::kTracking, &campaign::tracking_width_ff_of),
      unit_entry(Experiment::kTracking, &campaign::tracking_rms_reduction_of),
  };
  return entries;
}

const Entry* find_entry(const std::string& name) {
  const auto& c = catalog();
  const auto it = std::find_if(c.begin(), c.end(), [&](const Entry& e) { return e.kind.name == name; });
  return it == c.end() ? nullptr : &*it;
}

}  // namespace

const std::vector<MeasurementKind>& measurement_catalog() {
  static const std::vector<MeasurementKind> kinds = [] {
    std::vector<MeasurementKind> out;
    for (const Entry& e : catalog()) out.push_back(e.kind);
    return out;
  }();
  return kinds;
}

const MeasurementKind* find_measurement(const std::string& name) {
  const auto& c = measurement_catalog();
  const auto it = std::find_if(c.begin(), c.end(), [&](const MeasurementKind& k) { return k.name == name; });
  return it == c.end() ? nullptr : &*it;
}

std::optional<double> measured_value(const campaign::UnitAnalysis& u, const std::string& name, const std::string& file) {
  const Entry* e = find_entry(name);
  if (e == nullptr) return std::nullopt;
  const Si v = e->read(u, file);
  return v ? Si(*v * e->per_si) : std::nullopt;
}

MeasuredValue judge(const MeasurementKind& kind, std::optional<double> value, const Limit& limit, double margin_relative) {
  MeasuredValue m{kind.name, kind.unit, value, limit, Verdict::kPass, {}};
  if (!value) {
    m.verdict = Verdict::kFail;
    m.reason = fmt::format("{}: no value (the analysis gave none)", kind.name);
    return m;
  }
  const double v = *value;
  // Each limit with its own U = margin |limit| (until the measurement carries its budget), decided by
  // the campaign's rule (metrology/conformity.hpp, ISO 14253-1).
  const auto check = [&](double bound, bool is_min) {
    const double u = margin_relative * std::abs(bound);
    const auto lower = is_min ? std::optional<double>(bound) : std::nullopt, upper = is_min ? std::nullopt : std::optional<double>(bound);
    const metrology::Conformity c = metrology::decide(v, u, lower, upper).verdict;
    const Verdict here = c == metrology::Conformity::kPass ? Verdict::kPass : c == metrology::Conformity::kMarginal ? Verdict::kMarginal : Verdict::kFail;
    if (static_cast<int>(here) > static_cast<int>(m.verdict)) {
      m.verdict = here;
      m.reason =
          fmt::format("{} {} {} {} {} {} {}{}", kind.description, format_number(v, 4), kind.unit,
                      here == Verdict::kMarginal ? "within the margin of" : (is_min ? "below" : "above"),
                      is_min ? "the minimum" : "the maximum", format_number(bound, 4), kind.unit,
                      here == Verdict::kMarginal ? fmt::format(" (margin +-{} {})", format_number(u, 3), kind.unit)
                                                 : std::string());
    }
  };
  if (limit.min) check(*limit.min, true);
  if (limit.max) check(*limit.max, false);
  return m;
}

}  // namespace piezobench::station
