#include "piezobench/station/answers.hpp"

#include <fmt/format.h>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/io/toml_reader.hpp"

namespace piezobench::station {

namespace fs = std::filesystem;
using io::TomlReader;

namespace {

PhaseAnswers read_phase_answers(const TomlReader& r, const PhaseSpec& phase, const fs::path& folder) {
  r.only({"steps", "on_check_fail", "sensor_uF", "actuator_uF", "file"});
  PhaseAnswers a;
  const std::vector<std::string> steps = r.strings("steps");
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (steps[i] == "confirm") {
      a.steps.push_back(StepAnswer::kConfirm);
    } else if (steps[i] == "abort") {
      a.steps.push_back(StepAnswer::kAbort);
    } else {
      r.fail(fmt::format("steps[{}]", i), "confirm or abort", "'" + steps[i] + "'", r.element("steps", i));
    }
  }
  if (a.steps.size() != phase.steps.size()) {
    r.fail("steps", fmt::format("an answer to each of the {} operator steps of phase '{}' (station file line {})", phase.steps.size(),
                                phase.name, phase.line),
           fmt::format("{} answers", a.steps.size()));
  }
  const std::vector<std::string> checks = r.strings("on_check_fail");
  for (std::size_t i = 0; i < checks.size(); ++i) {
    if (checks[i] == "retry") {
      a.on_check_fail.push_back(CheckAnswer::kRetry);
    } else if (checks[i] == "continue") {
      a.on_check_fail.push_back(CheckAnswer::kContinue);
    } else if (checks[i] == "abort") {
      a.on_check_fail.push_back(CheckAnswer::kAbort);
    } else {
      r.fail(fmt::format("on_check_fail[{}]", i), "retry, continue or abort", "'" + checks[i] + "'", r.element("on_check_fail", i));
    }
  }
  a.sensor_uF = r.number("sensor_uF");
  a.actuator_uF = r.number("actuator_uF");
  const bool typed = phase.source == ValueSource::kTyped;
  if ((a.sensor_uF || a.actuator_uF) && !typed) r.fail("sensor_uF", "no typed values (phase '" + phase.name + "' is not source = \"typed\")", "a value");
  for (const auto& [key, v] : {std::pair{"sensor_uF", a.sensor_uF}, std::pair{"actuator_uF", a.actuator_uF}}) {
    if (typed && !v) r.fail(key, "the capacitance typed in for phase '" + phase.name + "', uF", "nothing");
    if (v && !(*v > 0.0)) r.fail(key, "a capacitance > 0 uF", format_number_exact(*v));
  }
  if (const auto f = r.string("file")) {
    if (phase.source != ValueSource::kFile) r.fail("file", "no file (phase '" + phase.name + "' is not source = \"file\")", "'" + *f + "'");
    const fs::path p(*f);
    a.file = p.is_absolute() ? p : folder / p;
    if (!fs::is_regular_file(*a.file)) r.fail("file", "an existing file", "'" + *f + "' (" + a.file->string() + ") does not exist");
  } else if (phase.source == ValueSource::kFile) {
    r.fail("file", "the file of phase '" + phase.name + "'", "nothing");
  }
  return a;
}

// The answers a phase needs: its operator steps, typed values, a file.
bool needs_answers(const PhaseSpec& p) { return !p.steps.empty() || p.source != ValueSource::kBench; }

}  // namespace

Answers parse_answers(const std::string& text, const fs::path& file, const StationFile& station) {
  const toml::table root = io::parse_toml(text, file.string());
  const TomlReader r(root, file.string(), "");
  r.only({"operator", "phases"});
  Answers a;
  a.file = file;
  a.operator_name = r.string("operator").value_or("");
  const fs::path folder = file.parent_path();
  if (const auto phases = r.table("phases")) {
    for (const auto& [k, node] : phases->table()) {
      const std::string name(k.str());
      const PhaseSpec* p = station.phase(name);
      if (p == nullptr) {
        std::string names;
        for (const PhaseSpec& s : station.phases) names += (names.empty() ? "" : ", ") + s.name;
        phases->fail(name, "a phase of " + station.file.string() + " (" + names + ")", "'" + name + "'", &node);
      }
      const auto sub = phases->table(name);
      a.phases[name] = read_phase_answers(*sub, *p, folder);
    }
  }
  for (const PhaseSpec& p : station.phases) {
    if (needs_answers(p) && a.phases.find(p.name) == a.phases.end()) {
      throw InputError(file.string(), "phases." + p.name,
                       fmt::format("the answers of phase '{}' (station file line {}: {} operator steps{})", p.name, p.line, p.steps.size(),
                                   p.source == ValueSource::kBench ? "" : ", values"),
                       "no [phases." + p.name + "] table");
    }
  }
  return a;
}

Answers read_answers(const fs::path& file, const StationFile& station) { return parse_answers(io::read_toml_text(file), file, station); }

}  // namespace piezobench::station
